"""The one interface of every planner: stability, exploration and the baselines (§3.2-3.3),
category (§4.2), fusion (§4.3) and touch (ch. 2)::

    plan = planner.plan()                          # .action: what the robot executes; .to_dict()
    update = planner.observe(plan, measurement)    # the belief after what the hand read; .to_dict()
    planner.belief                                 # what the planner believes now

``observe`` takes the plan that was executed (or the executed grasp itself: an (x, y, yaw) top
grasp, a 4x4 hand pose, a touch grasp, as the planner's plans carry it) and what the hand read:
a :class:`Reading` (joint angles and whether the grasp held) for every planner but the touch
planner, which reads contacts and the closing height as well
(:class:`bayesgrasp.planners.touch.TouchReadings`).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Optional, Protocol, runtime_checkable

import numpy as np

__all__ = ["GraspPlanner", "Reading", "as_reading", "grasp_outcome"]


@runtime_checkable
class GraspPlanner(Protocol):
    """plan() -> a plan with ``action`` and ``to_dict()``; observe(grasp, measurement) -> an
    update with ``to_dict()``; ``belief``."""

    belief: Any

    def plan(self) -> Any: ...

    def observe(self, grasp, measurement) -> Any: ...


def grasp_outcome(value, name: str = "held") -> bool:
    """A grasp outcome as a bool: True/False, numpy bools or the ints 0/1; anything else (a string
    such as "no" would be truthy) is a TypeError naming the argument."""
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    if isinstance(value, (int, np.integer)) and value in (0, 1):
        return bool(value)
    raise TypeError(f"{name}: expected a bool (or 0/1), got {value!r}")


@dataclass(frozen=True)
class Reading:
    """What the hand read after a grasp: ``joints``, the angles (rad) of the joints the planner's
    models predict, and ``held``, whether the grasp held the object: the lift test's outcome (with
    a run context's success rule "epsilon", that rule's); None: not known, the planners then use
    the joint angles alone."""

    joints: np.ndarray
    held: Optional[bool] = None

    def __post_init__(self):
        q = np.asarray(self.joints, dtype=float).ravel()
        if q.size == 0 or not np.all(np.isfinite(q)):
            raise ValueError(f"joints: expected finite joint angles (rad), got {self.joints!r}")
        q.setflags(write=False)
        object.__setattr__(self, "joints", q)
        if self.held is not None:
            object.__setattr__(self, "held", grasp_outcome(self.held))

    def to_dict(self) -> dict:
        return {"joints": self.joints.tolist(), "held": self.held}


def as_reading(measurement) -> Reading:
    """A :class:`Reading`, or joint angles alone (an array: whether the grasp held not known)."""
    return measurement if isinstance(measurement, Reading) else Reading(measurement)
