"""What a vision-then-touch trial gives (thesis §4.3, Pub. VI): its rounds, each an executed top
grasp with the belief it was planned from. JSON comes from :mod:`bayesgrasp.io.results`."""
from __future__ import annotations

from dataclasses import dataclass
from typing import List, Optional

import numpy as np

from ..io.results import fusion_dict, fusion_round_dict
from ..planners.fusion import FusionPlan


@dataclass
class TopGraspExecution:
    """A world top grasp executed on the object at its true pose, lift-tested.

    action : np.ndarray — (x, y, yaw), world
    lifted : bool; epsilon : float
    joint_angles : np.ndarray — every joint of the closed hand
    hand_pose : np.ndarray — (4, 4) world pose of the hand where it closed
    """

    action: np.ndarray
    lifted: bool
    epsilon: float
    joint_angles: np.ndarray
    hand_pose: np.ndarray


@dataclass
class FusionRound:
    """One round: G(0) (``plan`` None) or a tactile round's grasp planned by Eq. 4.6.

    number : int — 0 for G(0)
    execution : TopGraspExecution
    measurement : np.ndarray — the modelled joint angles read
    weights, poses : list — the belief the grasp was planned from (w_i, p_i per model)
    underflow : bool — the update before the plan underflowed
    plan : FusionPlan or None
    """

    number: int
    execution: TopGraspExecution
    measurement: np.ndarray
    weights: list
    poses: list
    underflow: bool = False
    plan: Optional[FusionPlan] = None

    @property
    def lifted(self) -> bool:
        return self.execution.lifted

    def to_dict(self) -> dict:
        return fusion_round_dict(self)


@dataclass
class FusionResult:
    """A trial: its mode (G(0) ``random`` or ``vision``), rounds, and the models with their
    vision weights w_i(0)."""

    mode: str
    rounds: List[FusionRound]
    names: List[str]
    vision_weights: np.ndarray

    @property
    def success(self) -> bool:
        """The last grasp lifted (the trial stops at the first lift after round 1)."""
        return bool(self.rounds[-1].lifted)

    def to_dict(self) -> dict:
        return fusion_dict(self)
