"""What the planners for known objects under pose uncertainty return: a :class:`Plan` from
``plan()`` and a :class:`PoseUpdate` from ``observe()`` (see :mod:`.protocol`)."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

import numpy as np


@dataclass
class Plan:
    """A planned grasp. ``kind`` is "stability" or "explore"; ``predicted_stability`` the
    belief-weighted P(S) of the action (Eq. 3.1's integral), ``objective`` what the planner's
    own search maximised (equal for the stability planner), ``expected_entropy`` Eq. 3.2's value
    for exploration plans (else None), ``seconds`` the wall time of the decision, ``family``
    the grasp family of the action."""

    action: np.ndarray
    kind: str
    predicted_stability: float
    objective: float
    expected_entropy: Optional[float] = None
    seconds: float = 0.0
    evaluations: int = 0
    family: str = "top"

    def to_dict(self) -> dict:
        return {"kind": self.kind, "family": self.family, "action": np.asarray(self.action).tolist(),
                "predicted_stability": float(self.predicted_stability), "objective": float(self.objective),
                "expected_entropy": self.expected_entropy, "plan_seconds": self.seconds,
                "evaluations": self.evaluations}


@dataclass
class Observation:
    """One executed grasp (x, y, yaw, world) of ``family``, the joint angles read and whether it
    held (None: not known)."""

    action: np.ndarray
    measurement: np.ndarray
    stable: Optional[bool]
    family: str = "top"


@dataclass
class PoseUpdate:
    """What one Bayes update did: the observation it absorbed and the belief's weighted mean
    (x, y, yaw) and effective sample size after it."""

    observation: Observation
    mean: np.ndarray
    ess: float

    def to_dict(self) -> dict:
        o = self.observation
        return {"family": o.family, "action": o.action.tolist(), "measurement": o.measurement.tolist(),
                "stable": o.stable, "mean": self.mean.tolist(), "ess": float(self.ess)}
