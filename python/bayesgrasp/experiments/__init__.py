"""Experiments that reproduce the thesis's results: each writes tables, plots and per-run results.

:mod:`.runner` (run by run into SQLite, with resume and workers), :mod:`.registry` (experiments by
name), :mod:`.driver` (runs one), :mod:`.pose_uncertainty` and :mod:`.report` (the thesis's
chapter-3 experiments and their tables and plots). The run context and the closed loop they run
are a layer below, in :mod:`bayesgrasp.loop`; ``RunContext``, ``EpisodeSettings`` and
``run_episode`` are re-exported here."""
from ..loop.context import RunContext
from ..loop.episode import EpisodeSettings, run_episode
from .driver import run
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
