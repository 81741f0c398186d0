"""Planners for known objects under pose uncertainty (thesis §3.2-3.3), one module per method:
:mod:`.stability` (Eq. 3.1), :mod:`.exploration` (Eq. 3.2), :mod:`.baselines`; :mod:`.registry`
makes one by name; :mod:`.protocol` is the interface every planner of the package has (these,
:mod:`.category`, :mod:`.fusion`, :mod:`.touch`). The closed loop that runs them against the
simulator is :mod:`bayesgrasp.loop.episode`."""
from ..models import get_models
from .base import Planner, PlannerSettings
from .pose_results import Plan, PoseUpdate
from .protocol import GraspPlanner, Reading
from .baselines import MLPosePlanner, OpenLoopPlanner
from .exploration import ExplorationPlanner
from .registry import PLANNERS, make_planner
from .stability import StabilityPlanner

__all__ = ["GraspPlanner", "Reading", "Plan", "PoseUpdate", "Planner", "PlannerSettings", "StabilityPlanner",
           "ExplorationPlanner", "MLPosePlanner", "OpenLoopPlanner", "PLANNERS", "make_planner", "get_models"]
