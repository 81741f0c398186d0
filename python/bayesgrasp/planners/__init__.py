"""Planners for known objects under pose uncertainty (thesis §3.2-3.3), one module per method:
:mod:`.stability` (Eq. 3.1), :mod:`.exploration` (Eq. 3.2), :mod:`.baselines`; the loop that
runs them against the simulator is :mod:`.loop`."""
from .base import Plan, Planner, PlannerSettings
from .baselines import MLPosePlanner, OpenLoopPlanner
from .exploration import ExplorationPlanner
from .loop import PLANNERS, default_cache_dir, get_models, make_planner, run_episode
from .stability import StabilityPlanner

__all__ = ["Plan", "Planner", "PlannerSettings", "StabilityPlanner", "ExplorationPlanner", "MLPosePlanner",
           "OpenLoopPlanner", "PLANNERS", "make_planner", "run_episode", "get_models", "default_cache_dir"]
