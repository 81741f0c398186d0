"""The planners by method name, and the one way to make one."""
from __future__ import annotations

from typing import Optional

from ..models import GraspModels
from .base import Planner, PlannerSettings
from .baselines import MLPosePlanner, OpenLoopPlanner
from .exploration import ExplorationPlanner
from .stability import StabilityPlanner

#: Planner classes by method name.
PLANNERS = {"stability": StabilityPlanner, "explore": ExplorationPlanner, "ml_pose": MLPosePlanner,
            "open_loop": OpenLoopPlanner}


def make_planner(method: str, models: GraspModels, estimate, settings: Optional[PlannerSettings] = None,
                 seed: int = 0) -> Planner:
    """A planner of ``method`` (a key of :data:`PLANNERS`) on the initial belief around ``estimate``."""
    if method not in PLANNERS:
        raise ValueError(f"method: one of {', '.join(PLANNERS)}; got {method!r}")
    return PLANNERS[method](models, estimate, settings, seed=seed)
