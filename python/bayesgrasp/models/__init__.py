"""GP models of the measurements P(M|A,O) and the stability P(S|A,O), learnt from simulation:
:mod:`.settings` (how they are built), :mod:`.training` (simulated data, spread pilot,
calibration), :mod:`.families` (top and side grasps), :mod:`.grasp_models` (the fitted models and their queries), :mod:`.table` (the
models on a grid, for the planners) and :mod:`.build` (build, cache, per-process memo)."""
from .build import build_models, cache_key, default_cache_dir, get_models, models_cached
from .families import FAMILIES, Variant, parse_families
from .grasp_models import GraspModels, features, relative_top_grasps
from .settings import AUTO_SPREADS, CACHE_VERSION, ModelSettings
from .table import ModelTable
from .training import choose_spread, fit_calibration, simulate_training_data

__all__ = ["AUTO_SPREADS", "CACHE_VERSION", "FAMILIES", "GraspModels", "Variant", "parse_families", "ModelSettings", "ModelTable", "build_models",
           "cache_key", "choose_spread", "default_cache_dir", "features", "fit_calibration", "get_models", "models_cached",
           "relative_top_grasps", "simulate_training_data"]
