"""What an episode returns: its attempts, each with the plan and what the simulator computed, and
the beliefs around them. JSON comes from :mod:`bayesgrasp.io.results` (``to_dict``)."""
from __future__ import annotations

from dataclasses import dataclass
from typing import List, Optional, Tuple

import numpy as np

from ..hand import Hand
from ..io.results import episode_attempt_dict, episode_dict
from ..models.families import Variant
from ..planners import Plan, Planner
from ..world import ContactRecord


@dataclass
class Execution:
    """One executed grasp: where it was relative to the object, how it scored, what the fingers
    read. ``success`` is the context's criterion (lifted, or ``stable``: epsilon above the models'
    eps_stable); ``lifted`` is None when no lift test ran."""

    relative_grasp: np.ndarray
    epsilon: float
    stable: bool
    lifted: Optional[bool]
    success: bool
    collision_at_start: bool
    joint_angles: np.ndarray
    hand_pose: Optional[np.ndarray] = None   # (4, 4) world pose of the hand where it closed
    contacts: Tuple[ContactRecord, ...] = ()  # where the hand touched (object and table), with parts


@dataclass
class Attempt:
    """One attempt of an episode.

    number : int — 1 for the first attempt
    plan : Plan — what the planner chose (kind, family, action, predicted P(S), its timing)
    variant : Variant — the executed family's variant (spread, height, roll)
    execution : Execution — the grasp at the true pose: epsilon, stability, lift verdict, the
        simulator's joint angles, hand pose and contacts (with parts)
    measured : np.ndarray — the joint angles the planner read (the modelled ones, with noise)
    hand : Hand — the hand that grasped (its grasp record: :func:`bayesgrasp.io.results.attempt_grasp`)
    belief_before : dict — the planner's belief summary the plan was made from
    belief_after : dict or None — the summary after the planner observed the attempt (None when
        the episode stopped at it)
    """

    number: int
    plan: Plan
    variant: Variant
    execution: Execution
    measured: np.ndarray
    hand: Hand
    belief_before: dict
    belief_after: Optional[dict] = None

    @property
    def success(self) -> bool:
        return self.execution.success

    @property
    def lifted(self) -> Optional[bool]:
        return self.execution.lifted

    def to_dict(self) -> dict:
        return episode_attempt_dict(self)


@dataclass
class EpisodeResult:
    """One run of the loop.

    object : str — the object's name; method : str — the planner's
    true_pose, estimate : np.ndarray — the hidden pose and the initial estimate (x, y, yaw)
    seed : int
    attempts : list of Attempt
    initial_belief, final_belief : dict — the planner's belief summaries (errors to the true pose)
    planner : Planner or None — the planner at the end (kept on request)
    snapshots : list of (particles, weights) or None — the belief before each attempt and at the
        end (kept on request)
    """

    object: str
    method: str
    true_pose: np.ndarray
    estimate: np.ndarray
    seed: int
    attempts: List[Attempt]
    initial_belief: dict
    final_belief: dict
    planner: Optional[Planner] = None
    snapshots: Optional[List[Tuple[np.ndarray, np.ndarray]]] = None

    @property
    def success(self) -> bool:
        return any(a.success for a in self.attempts)

    @property
    def first_success(self) -> Optional[int]:
        return next((a.number for a in self.attempts if a.success), None)

    @property
    def lifted(self) -> bool:
        return any(a.lifted for a in self.attempts if a.lifted is not None)

    def to_dict(self) -> dict:
        return episode_dict(self)
