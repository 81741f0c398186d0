"""What the category planner (:mod:`.category`, Eq. 4.1) returns: a :class:`CategoryPlan` from
``plan()`` and a :class:`CategoryUpdate` from ``observe()`` (see :mod:`.protocol`)."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Optional

import numpy as np


@dataclass
class CategoryPlan:
    """The chosen grasp: hand pose (4x4, scene frame) and spread; J there (with the clearance
    factor: ``objective``; without: ``mixture``); the per-model weights phi (normalised) and
    contributions to J; the component that dominates J and its model; the search start."""

    pose: np.ndarray
    spread: float
    method: str
    objective: float
    mixture: float
    weights: dict
    contributions: dict
    dominant_model: Optional[str]
    dominant_grasp: int
    start_model: Optional[str]
    evaluations: int = 0
    intrusion: float = 0.0
    reason: str = ""
    extra: dict = field(default_factory=dict)

    @property
    def ok(self) -> bool:
        return not self.reason

    @property
    def action(self) -> np.ndarray:
        """The hand pose to execute (4x4, scene frame)."""
        return self.pose

    def to_dict(self) -> dict:
        return {"method": self.method, "plan_ok": self.ok, "objective": self.objective, "mixture": self.mixture,
                "pose": None if not self.ok else self.pose.tolist(), "weights": self.weights,
                "contributions": self.contributions, "dominant_model": self.dominant_model,
                "start_model": self.start_model, "evaluations": self.evaluations, "intrusion": self.intrusion,
                **({"part_check": self.extra} if self.extra else {})}


@dataclass
class CategoryUpdate:
    """What one observed grasp did: whether it held (None: not known) and the mixture's total
    component weight before and after (a failed grasp lowers the weight of the components near it)."""

    held: Optional[bool]
    weight_before: float
    weight_after: float

    def to_dict(self) -> dict:
        return {"held": self.held, "weight_before": self.weight_before, "weight_after": self.weight_after}
