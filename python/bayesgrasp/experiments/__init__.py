"""Experiments that reproduce the thesis's results: each writes tables, plots and per-run results."""
from .runner import ResultStore, RunKey, run_experiment, run_seed

__all__ = ["ResultStore", "RunKey", "run_experiment", "run_seed"]
