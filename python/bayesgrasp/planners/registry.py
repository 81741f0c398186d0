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

#: What each method does, in one line (the command line's help reads it). Every method needs the
#: object's grasp models and an initial estimate; none needs more.
METHOD_HELP = {"stability": "the most stable grasp (Eq. 3.1)",
               "explore": "informative grasps while none is likely to hold (Eq. 3.2)",
               "ml_pose": "the most stable grasp at the most likely pose",
               "open_loop": "the most stable grasp at the estimate, no update"}

#: The pose methods an episode with the robot outside offers (``bayesgrasp episode``, the outside
#: loop): the thesis's two, Eq. 3.1 and Eq. 3.2; the others are the experiments' baselines.
EPISODE_METHODS = ("stability", "explore")


def methods_help(methods=None, help_of=None) -> str:
    """"name: what it does; ..." for ``methods`` (default: every pose method) from ``help_of``
    (default: :data:`METHOD_HELP`)."""
    help_of = METHOD_HELP if help_of is None else help_of
    return "; ".join(f"{m}: {help_of[m]}" for m in (help_of if methods is None else methods))


def make_planner(method: str, models: GraspModels, estimate, settings: Optional[PlannerSettings] = None,
                 seed: int = 0) -> Planner:
    """A planner of ``method`` (a key of :data:`PLANNERS`) on the initial belief around ``estimate``."""
    if method not in PLANNERS:
        raise ValueError(f"method: one of {', '.join(PLANNERS)}; got {method!r}")
    return PLANNERS[method](models, estimate, settings, seed=seed)
