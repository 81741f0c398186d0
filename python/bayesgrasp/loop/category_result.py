"""What a category plan gives (thesis §4.2): the plan of Eq. 4.1 and its grasp on the stand-in
object, one :class:`TaskGraspResult`. JSON comes from :mod:`bayesgrasp.io.results` (``to_dict``)."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import List, Optional

from ..hand import Hand
from ..io.grasp_schema import hand_grasp_record
from ..io.results import task_grasp_dict, task_grasp_outcome_dict
from ..planners.category import CategoryPlan


@dataclass
class TaskGraspOutcome:
    """A category plan's grasp on the stand-in object: executed (approach, close, lift test) or
    not (no stand-in: a camera's view; or no plan, ``reason``). One key set either way: what was
    not measured is None. success = lifted and task_ok (the contacts obey the task's rule)."""

    executed: bool
    reason: str = ""
    hand_pose: Optional[list] = None
    spread: Optional[float] = None
    epsilon: Optional[float] = None
    force_closure: Optional[bool] = None
    lifted: Optional[bool] = None
    task_ok: Optional[bool] = None
    success: Optional[bool] = None
    failure: Optional[str] = None
    contact_parts: List[str] = field(default_factory=list)
    collision_at_start: Optional[bool] = None
    stopped_by_table: Optional[bool] = None
    joint_angles: Optional[list] = None
    joint_names: Optional[list] = None

    def to_dict(self) -> dict:
        return task_grasp_outcome_dict(self)


@dataclass
class TaskGraspResult:
    """One task and method on a category episode's registrations.

    plan : CategoryPlan — Eq. 4.1's grasp: pose, spread, objective, per-model weights and contributions
    outcome : TaskGraspOutcome — that grasp on the stand-in object (or why it was not executed)
    method : str — the method asked for; task : str
    task_grasps : int — the demonstrated grasps of the task the plan drew on
    """

    plan: CategoryPlan
    outcome: TaskGraspOutcome
    method: str
    task: str
    task_grasps: int

    @property
    def planned_pose(self) -> Optional[list]:
        """The planned hand pose (4x4, scene frame) as a list; None when the plan failed."""
        return self.plan.pose.tolist() if self.plan.ok else None

    def planned_grasp(self, hand: Hand) -> dict:
        """The planned pose in the grasp schema, with the open preshape (the plan must be ok)."""
        s = self.outcome.spread
        return hand_grasp_record(hand, self.planned_pose, hand.open_joints(s), s)

    def grasp(self, hand: Hand) -> Optional[dict]:
        """The plan in the grasp schema (world = the table frame): executed, where the hand closed
        and its closed fingers; planned only, :meth:`planned_grasp`; None without a plan."""
        if not self.plan.ok:
            return None
        o = self.outcome
        if o.executed:
            return hand_grasp_record(hand, o.hand_pose, o.joint_angles, o.spread)
        return self.planned_grasp(hand)

    def to_dict(self) -> dict:
        return task_grasp_dict(self)
