"""Building the grasp models of an object: simulate, fit, calibrate, cache.

Models are cached on disk under a key made of the object's mesh, the hand file and the settings
(:func:`cache_key`); they are rebuilt only when one of those changes. :func:`get_models` adds a
per-process memo, so a worker builds or loads each object's models once.
"""
from __future__ import annotations

import hashlib
import json
from dataclasses import asdict
from pathlib import Path
from typing import Callable, Optional, Union

import numpy as np

from .. import DEFAULT_HAND
from .. import gp as _gp
from ..cache import atomic_write, atomic_write_text, cache_root, cached, load_cached
from ..objects import ObjectModel, load_object
from ..world import World
from .families import Variant
from .grasp_models import DEFAULT_CALIBRATION, GraspModels
from ..objects.mass import cache_salt
from .settings import CACHE_VERSION, ModelSettings
from .training import choose_spread, choose_variant, fit_calibration, side_variants, simulate_training_data, success_labels

Say = Callable[[str], None]


def default_cache_dir() -> Path:
    """Where models are cached: $BAYESGRASP_CACHE/models, else ~/.cache/bayesgrasp/models."""
    return cache_root() / "models"


def cache_key(obj: ObjectModel, hand_text: str, settings: ModelSettings) -> str:
    """The models' identity: cache version, the object's mesh (and its mass properties where the lift test
    does not weigh its closed mesh), the hand file and the settings."""
    h = hashlib.sha256()
    h.update(f"v{CACHE_VERSION}".encode())
    h.update(np.ascontiguousarray(obj.vertices, dtype=np.float64).tobytes())
    h.update(np.ascontiguousarray(obj.faces, dtype=np.int64).tobytes())
    h.update(hand_text.encode())
    h.update(cache_salt(obj))      # the lift test's mass, where it is not the closed mesh's
    fields = settings.as_stored()
    if fields["family"] == "top":  # top models keep the keys they had before there were families
        del fields["family"]
    h.update(json.dumps(fields, sort_keys=True).encode())
    return h.hexdigest()[:20]


class _CacheFiles:
    """The three files of one cache entry: the two GPs and the info JSON."""

    def __init__(self, cache_dir, key: str):
        d = Path(cache_dir)
        self.measurement, self.stability, self.info = (d / f"{key}_measurement.npz", d / f"{key}_stability.npz",
                                                       d / f"{key}.json")

    def load(self, settings: ModelSettings) -> Optional[GraspModels]:
        """The cached models, or None (a damaged or unreadable file warns) to rebuild them."""
        info = load_cached(self.info, "model cache file", lambda p: json.loads(p.read_text()))
        gps = [load_cached(f, "model cache file", _gp.load) for f in (self.measurement, self.stability)]
        if info is None or None in gps:
            return None
        models = GraspModels(gps[0], gps[1], settings, info["joint_index"], info)
        models.loaded_from_cache = True
        return models

    def save(self, models: GraspModels) -> None:
        try:
            atomic_write(self.measurement, models.measurement.save)
            atomic_write(self.stability, models.stability.save)
            atomic_write_text(self.info, json.dumps(models.info, indent=1))
        except OSError as e:
            raise ValueError(f"cache_dir: cannot write models to {self.info.parent}: {e}") from e


def _fit(X, Y, settings: ModelSettings, n: int) -> _gp.SparseGP:
    return _gp.SparseGP(n_inducing=min(settings.n_inducing, n), max_iter=settings.max_iter, seed=settings.seed,
                        noise=1e-2).fit(X, Y)


def _calibrate(models: GraspModels, world: World, settings: ModelSettings, spread: Variant, say: Say,
               labelled: tuple) -> tuple:
    """The logistic calibration of P(S) on the outcomes of held-out simulated grasps, or (calibration
    "cross_fit") of the labelled training grasps ``labelled`` = (rel, outcomes) scored across folds;
    the probit-like default when there are too few."""
    if settings.calibration == "cross_fit":
        return _cross_fit_calibration(models, settings, spread, say, world.object.name, *labelled)
    if settings.n_calibration <= 0:
        return DEFAULT_CALIBRATION
    say(f"models for {world.object.name}: calibrating P(S) on {settings.n_calibration} held-out grasps "
        f"({settings.success} outcomes)")
    rel_c, _, eps_c = simulate_training_data(world, settings, seed_offset=1, n=settings.n_calibration, spread=spread)
    if len(rel_c) < 10:
        return DEFAULT_CALIBRATION
    return fit_calibration(models.stability_z(rel_c), success_labels(world, settings, rel_c, eps_c, spread, say))


def _cross_fit_calibration(models: GraspModels, settings: ModelSettings, variant: Variant, say: Say, name: str,
                           rel, outcomes) -> tuple:
    """Two-fold cross-fitting: a stability GP fitted on each half of the labelled grasps scores the
    other half (z, as GraspModels.stability_z); the logistic calibration of the outcomes on those
    out-of-fold scores. No grasp is simulated or lift-tested again."""
    n = len(rel)
    if n < 20 or np.all(outcomes) or not np.any(outcomes):
        return DEFAULT_CALIBRATION
    say(f"models for {name}: calibrating P(S) on the {n} lift-tested training grasps, each scored by a GP "
        f"fitted on the other half")
    fold = np.random.default_rng([settings.seed, 11]).permutation(n) % 2
    z = np.empty(n)
    for k in (0, 1):
        train, test = fold != k, fold == k
        gp = _fit(variant.features(rel[train]), outcomes[train].astype(float), settings, int(train.sum()))
        z[test] = GraspModels(models.measurement, gp, settings, models.joint_index, models.info).stability_z(rel[test])
    return fit_calibration(z, outcomes)


def _fit_stability(world: World, settings: ModelSettings, rel, eps, variant: Variant, say: Say):
    """The stability GP and the outcomes it was fitted on: lift outcomes (0/1) of the first
    n_lift_samples training grasps, or the epsilon of all of them."""
    if settings.success == "lift":
        n = min(settings.scaled(settings.n_lift_samples, settings.grasp_box(world.object)), len(rel))
        say(f"models for {world.object.name}: lift tests of {n} training grasps")
        lifted = success_labels(world, settings, rel[:n], eps[:n], variant, say)
        return _fit(variant.features(rel[:n]), lifted.astype(float), settings, n), (rel[:n], lifted)
    return _fit(variant.features(rel), np.maximum(eps, 0.0), settings, len(rel)), (rel, eps > settings.eps_stable)


def _choose_variant(world: World, settings: ModelSettings, say: Say):
    """The family's hand settings: (Variant, pilot table or None). Top grasps: the given spread,
    else the spread pilot; side grasps: the pilot over spread, height and roll."""
    name = world.object.name
    if settings.family == "top":
        if settings.spread is not None:
            return Variant("top", float(settings.spread)), None
        say(f"models for {name}: choosing the finger spread (pilot of {settings.n_pilot} grasps per spread)")
        spread, pilot = choose_spread(world, settings, say)
        return Variant("top", float(spread)), pilot
    candidates = side_variants(world, settings)
    say(f"models for {name}: choosing the side grasps' spread, height and roll (pilot of {settings.n_pilot} "
        f"grasps for each of {len(candidates)})")
    best, table = choose_variant(world, settings, candidates, say)
    return best, [dict(v.as_dict(), fraction=f, lifted=l, tested=t) for v, (f, l, t) in zip(candidates, table)]


def _train(world: World, settings: ModelSettings, key: str, say: Say) -> GraspModels:
    """Pilot (spread; for side grasps also height and roll), training grasps, the two FITC fits,
    calibration."""
    name = world.object.name
    variant, pilot = _choose_variant(world, settings, say)
    spread = variant.spread
    where = "" if variant.family == "top" else \
        f" from the side at {100 * variant.height:.1f} cm, roll {np.degrees(variant.roll):.0f} deg,"
    say(f"models for {name}: simulating {settings.n_samples} {variant.family} grasps{where} at spread "
        f"{np.degrees(spread):.0f} deg")
    rel, q, eps = simulate_training_data(world, settings, spread=variant)
    if len(rel) < 10:
        raise ValueError(f"{name}: only {len(rel)} collision-free {variant.family} grasps in the sampled range")
    joint_index = world.hand.measured_joints   # the hand file's measured_joints (the spread is fixed)
    X = variant.features(rel)
    say(f"models for {name}: fitting FITC GPs on {len(rel)} grasps")
    measurement = _fit(X, q[:, joint_index], settings, len(rel))
    stability, labelled = _fit_stability(world, settings, rel, eps, variant, say)
    outcomes = labelled[1]
    models = GraspModels(measurement, stability, settings, joint_index,
                         {"spread": float(spread), "grasp_box": settings.grasp_box(world.object).tolist(),
                          "variant": variant.as_dict()})
    calibration = _calibrate(models, world, settings, variant, say, labelled)
    models.info = {"key": key, "object": name, "calibration": list(calibration), "hand": world.hand.name,
                   "settings": asdict(settings), "samples": int(len(rel)),
                   "force_closure_fraction": float(np.mean(eps > 0)),
                   "stable_fraction": float(np.mean(eps > settings.eps_stable)),
                   "success_fraction": float(np.mean(outcomes)),
                   "joint_index": joint_index.tolist(), "measurement_scale": world.hand.measurement_scale.tolist(), "spread": float(spread), "spread_pilot": pilot,
                   "grasp_box": settings.grasp_box(world.object).tolist(), "variant": variant.as_dict()}
    return models


def build_models(obj: Union[str, ObjectModel], hand=DEFAULT_HAND, settings: Optional[ModelSettings] = None,
                 cache_dir: Union[str, Path, None] = None, progress: Optional[Say] = None) -> GraspModels:
    """Fits (or loads from ``cache_dir``) the measurement and stability models of ``obj``.

    ``progress`` is an optional callable taking a message string. The result's
    ``loaded_from_cache`` says whether it came from the cache.
    """
    settings = settings or ModelSettings()
    obj = load_object(obj) if isinstance(obj, str) else obj
    world, key = _world_and_key(obj, hand, settings)
    say = progress or (lambda msg: None)
    files = None if cache_dir is None else _CacheFiles(cache_dir, key)
    models = None if files is None else files.load(settings)
    if models is not None:
        say(f"models for {obj.name}: loaded from cache ({key})")
        return models
    return _as_reloaded(_train(world, settings, key, say), files, settings, key)


def _world_and_key(obj: ObjectModel, hand, settings: ModelSettings) -> tuple:
    """The object's world at the origin with ``hand``, and its models' cache key."""
    world = World.single(obj, pose=(0.0, 0.0, 0.0), hand=hand)
    return world, cache_key(world.object, world.hand.text or world.hand.name, settings)


def _memo_key(obj, hand, settings: ModelSettings, cache_dir) -> tuple:
    """get_models' per-process memo key (a name, or the object model's identity)."""
    return obj if isinstance(obj, str) else id(obj), hand, settings, str(cache_dir)


def _as_reloaded(models: GraspModels, files: Optional[_CacheFiles], settings: ModelSettings, key: str) -> GraspModels:
    """The freshly fitted models as a later run will load them: saved (to the cache, or to a
    temporary directory without one) and read back. A reloaded GP re-factors from its stored
    hyper-parameters and predicts ~1e-14 away from the fitted one, so returning the fitted one
    would make a cold-cache run differ in its last digits from a warm one."""
    import tempfile

    with tempfile.TemporaryDirectory(prefix="bayesgrasp-models-") as tmp:
        target = files if files is not None else _CacheFiles(tmp, key)
        target.save(models)
        reloaded = target.load(settings)
    if reloaded is None:  # the cache could not be read back: keep what was fitted
        return models
    reloaded.loaded_from_cache = False
    return reloaded


_MODELS: dict = {}


def models_cached(obj: Union[str, ObjectModel], hand=DEFAULT_HAND, settings: Optional[ModelSettings] = None,
                  cache_dir=None) -> bool:
    """Whether ``obj``'s models are in this process's memo or in ``cache_dir`` (default
    :func:`default_cache_dir`), i.e. whether :func:`get_models` will not build them. Reads no GP."""
    settings = settings or ModelSettings()
    cache_dir = default_cache_dir() if cache_dir is None else cache_dir
    if _memo_key(obj, hand, settings, cache_dir) in _MODELS:
        return True
    _, key = _world_and_key(load_object(obj) if isinstance(obj, str) else obj, hand, settings)
    files = _CacheFiles(cache_dir, key)
    return all(cached(f) for f in (files.measurement, files.stability, files.info))


def get_models(obj: Union[str, ObjectModel], hand: str = DEFAULT_HAND, settings: Optional[ModelSettings] = None,
               cache_dir=None, progress: Optional[Say] = None) -> GraspModels:
    """build_models with a per-process memo (a worker builds or loads each object's models once);
    ``cache_dir`` None means :func:`default_cache_dir`."""
    settings = settings or ModelSettings()
    cache_dir = default_cache_dir() if cache_dir is None else cache_dir
    key = _memo_key(obj, hand, settings, cache_dir)
    if key not in _MODELS:
        _MODELS[key] = build_models(obj, hand, settings, cache_dir=cache_dir, progress=progress)
    return _MODELS[key]
