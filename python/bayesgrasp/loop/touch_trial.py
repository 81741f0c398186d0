"""One touch (thesis ch. 2, Pub. I): the object at its true state, the robot's guess, a top grasp
at the guessed centre along the guessed yaw, the readings, and the model fitted to them.

:func:`touch_once` runs it and returns a :class:`TouchTrial`; :func:`pose_errors` measures a
state against the truth (orientation modulo the object's symmetry)."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

import numpy as np

from ..io.results import pose_errors_dict
from ..planners.touch import TouchPlanner, orientation_error, read, symmetry_order, touch_world


@dataclass(frozen=True)
class PoseErrors:
    """A state (x, y, yaw, scale) against the truth.

    position_error : float — m in the plane
    orientation_error : float or None — rad, modulo the object's symmetry (None: a body of revolution)
    size_error : float — |scale - true scale| / true scale
    """

    position_error: float
    orientation_error: Optional[float]
    size_error: float

    def to_dict(self) -> dict:
        return pose_errors_dict(self)


def pose_errors(obj, state, truth) -> PoseErrors:
    """``state`` against ``truth`` on ``obj`` (a name or an ObjectModel: its symmetry)."""
    state, truth = np.asarray(state, dtype=float), np.asarray(truth, dtype=float)
    yaw = orientation_error(state[2], truth[2], symmetry_order(obj))
    return PoseErrors(float(np.hypot(*(state[:2] - truth[:2]))), yaw, float(abs(state[3] - truth[3]) / truth[3]))


@dataclass
class TouchTrial:
    """One touch and its fit.

    planner : TouchPlanner — its model, settings, initial guess and (after the fit) estimate
    truth, initial : np.ndarray — the true state and the guess (x, y, yaw, scale)
    touch : TouchGrasp — the executed top grasp (x, y, yaw, spread)
    readings : TouchReadings — what the hand read (joints, contacts per link, hand pose)
    fit : EstimateResult — the optimiser's result (status, fitness, evaluations, trace)
    """

    planner: TouchPlanner
    truth: np.ndarray
    initial: np.ndarray
    touch: object
    readings: object
    fit: object

    @property
    def estimate(self) -> np.ndarray:
        return np.asarray(self.planner.estimate, dtype=float)

    @property
    def errors_before(self) -> PoseErrors:
        return pose_errors(self.planner.model.object, self.initial, self.truth)

    @property
    def errors_after(self) -> PoseErrors:
        return pose_errors(self.planner.model.object, self.estimate, self.truth)

    @property
    def contact_links(self) -> list:
        """The names of the hand's links that touched."""
        names = list(self.planner.model.hand.core.link_names)
        return [n for n, c in zip(names, self.readings.contact) if c]


def touch_once(planner: TouchPlanner, obj, truth) -> TouchTrial:
    """``planner``'s touch executed on ``obj`` (the planner's object: a name or an ObjectModel)
    at ``truth`` (x, y, yaw, scale) and fitted."""
    truth = np.asarray(truth, dtype=float)
    initial = np.asarray(planner.initial, dtype=float).copy()
    touch = planner.plan().touch
    readings = read(touch_world(obj, truth[:3], truth[3], planner.model.hand), touch)
    fit = planner.observe(touch, readings)
    return TouchTrial(planner, truth, initial, touch, readings, fit)
