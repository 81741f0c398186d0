"""Experiments that reproduce the thesis's results: each writes tables, plots and per-run results.

:mod:`.context` (what a run needs from its caller), :mod:`.episode` (the closed loop),
:mod:`.runner` (run by run into SQLite, with resume and workers), :mod:`.registry` (experiments by
name), :mod:`.driver` (runs one), :mod:`.pose_uncertainty` and :mod:`.report` (the thesis's
chapter-3 experiments and their tables and plots)."""
from .context import RunContext
from .driver import run
from .episode import EpisodeSettings, run_episode
from .registry import EXPERIMENTS, Experiment, experiment_names, get_experiment
from .runner import ResultStore, RunKey, run_experiment, run_seed

# the modules that register experiments
from . import pose_uncertainty  # noqa: E402,F401  (isort: skip)
from . import category_grasping  # noqa: E402,F401  (isort: skip)
from . import category_scales  # noqa: E402,F401  (isort: skip)
from . import tactile_fusion  # noqa: E402,F401  (isort: skip)
from . import single_touch  # noqa: E402,F401  (isort: skip)

__all__ = ["EXPERIMENTS", "EpisodeSettings", "Experiment", "ResultStore", "RunContext", "RunKey", "experiment_names",
           "get_experiment", "run", "run_episode", "run_experiment", "run_seed"]
