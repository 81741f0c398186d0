"""Measurement and stability models for top grasps, learnt from simulated grasps (thesis §3.2).

The models take the grasp relative to the object: a top grasp at (x, y, yaw) in the object's
frame (see :func:`relative_top_grasps`). Inputs to the GPs are (x, y, cos yaw, sin yaw), so that
yaw wraps. Two sparse (FITC) GPs are fitted on simulated grasps of the object with the hand:

* measurement model P(M|A,O): the hand's phalanx joint angles after closing (one output per
  phalanx joint, shared hyper-parameters), Gaussian with the GP's predictive variance plus noise;
* stability model P(S|A,O): the GP regression of the grasp's epsilon quality (0 without force
  closure), mapped to a probability with a probit of the latent epsilon,
  P(S) = Phi((mu - eps_stable) / sd).

Models are cached on disk under a key made of the object's mesh, the hand file and the settings;
they are rebuilt only when one of those changes.
"""
from __future__ import annotations

import hashlib
import json
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Optional, Union

import numpy as np
from scipy.special import log_ndtr, ndtr

from .. import gp as _gp
from ..objects import ObjectModel, load_object
from ..world import World

CACHE_VERSION = 1


@dataclass(frozen=True)
class ModelSettings:
    """How the models are built (every field is part of the cache key)."""

    n_samples: int = 2000         # simulated grasps
    n_inducing: int = 200         # FITC inducing inputs
    xy_range: float = 0.06        # relative x, y sampled uniformly in +-xy_range (m)
    spread: float = 0.0           # finger spread of the grasps (rad)
    eps_stable: float = 0.05      # epsilon above which a grasp counts as stable
    max_iter: int = 150           # hyper-parameter optimisation iterations
    seed: int = 0

    def __post_init__(self):
        if self.n_samples < 10:
            raise ValueError(f"n_samples: need at least 10, got {self.n_samples}")
        if self.n_inducing < 1:
            raise ValueError(f"n_inducing: must be >= 1, got {self.n_inducing}")
        if not (self.xy_range > 0 and np.isfinite(self.xy_range)):
            raise ValueError(f"xy_range: must be positive, got {self.xy_range}")


def relative_top_grasps(grasps, object_poses) -> np.ndarray:
    """Top grasps (A, 3) in the world and planar object poses (N, 3) -> (A, N, 3) grasps in each
    object's frame: R(-oyaw) (a_xy - o_xy), wrap(a_yaw - o_yaw) into [-pi, pi)."""
    a = np.atleast_2d(np.asarray(grasps, dtype=float))[:, None, :]
    o = np.atleast_2d(np.asarray(object_poses, dtype=float))[None, :, :]
    dx, dy = a[..., 0] - o[..., 0], a[..., 1] - o[..., 1]
    c, s = np.cos(o[..., 2]), np.sin(o[..., 2])
    yaw = np.mod(a[..., 2] - o[..., 2] + np.pi, 2 * np.pi) - np.pi
    return np.stack([c * dx + s * dy, -s * dx + c * dy, yaw], axis=-1)


def _mean_var(model: _gp.SparseGP, X: np.ndarray, include_noise: bool):
    """Predictive mean and variance (N, P) in the outputs' units, with or without the noise."""
    mv = [m.predict(np.ascontiguousarray(X), include_noise) for m in model.models_]
    return np.concatenate([a for a, _ in mv], axis=1), np.concatenate([b for _, b in mv], axis=1)


def features(rel) -> np.ndarray:
    """(..., 3) relative grasps -> (..., 4) GP inputs (x, y, cos yaw, sin yaw)."""
    rel = np.asarray(rel, dtype=float)
    return np.concatenate([rel[..., :2], np.cos(rel[..., 2:3]), np.sin(rel[..., 2:3])], axis=-1)


class GraspModels:
    """The two fitted GPs of one object and hand, with the planners' queries."""

    def __init__(self, measurement: _gp.SparseGP, stability: _gp.SparseGP, settings: ModelSettings,
                 joint_index: np.ndarray, info: dict):
        self.measurement, self.stability, self.settings = measurement, stability, settings
        self.joint_index = np.asarray(joint_index, dtype=int)  # which hand joints are measured
        self.info = info

    def predict_measurement(self, rel):
        """Mean and variance (incl. noise) of the joint angles at relative grasps (..., 3)."""
        rel = np.asarray(rel, dtype=float)
        mean, var = _mean_var(self.measurement, features(rel).reshape(-1, 4), include_noise=True)
        shape = rel.shape[:-1] + (len(self.joint_index),)
        return mean.reshape(shape), var.reshape(shape)

    def log_likelihood(self, rel, measurement) -> np.ndarray:
        """log P(M = measurement | A, O) at relative grasps (..., 3): a sum over joints."""
        rel = np.asarray(rel, dtype=float)
        m = np.asarray(measurement, dtype=float)
        X = features(rel).reshape(-1, 4)
        Y = np.broadcast_to(m, (len(X), m.shape[-1]))
        return self.measurement.log_predictive_density(X, Y).reshape(rel.shape[:-1])

    def _stability_z(self, rel) -> np.ndarray:
        # The latent epsilon's predictive distribution (without the observation noise, which
        # in epsilon is mostly the simulator's discontinuity, not uncertainty about the grasp).
        rel = np.asarray(rel, dtype=float)
        mean, var = _mean_var(self.stability, features(rel).reshape(-1, 4), include_noise=False)
        z = (mean[:, 0] - self.settings.eps_stable) / np.sqrt(np.maximum(var[:, 0], 1e-12))
        return z.reshape(rel.shape[:-1])

    def stability_probability(self, rel) -> np.ndarray:
        """P(S | A, O) at relative grasps (..., 3): Phi((mu - eps_stable) / sd) of the latent epsilon."""
        return ndtr(self._stability_z(rel))

    def log_stability_probability(self, rel) -> np.ndarray:
        return log_ndtr(self._stability_z(rel))


def _cache_key(obj: ObjectModel, hand_text: str, settings: ModelSettings) -> str:
    h = hashlib.sha256()
    h.update(f"v{CACHE_VERSION}".encode())
    h.update(np.ascontiguousarray(obj.vertices, dtype=np.float64).tobytes())
    h.update(np.ascontiguousarray(obj.faces, dtype=np.int64).tobytes())
    h.update(hand_text.encode())
    h.update(json.dumps(asdict(settings), sort_keys=True).encode())
    return h.hexdigest()[:20]


def simulate_training_data(world: World, settings: ModelSettings):
    """Relative grasps (n, 3), joint angles (n, J) and epsilon (n,) from the simulator; grasps
    whose open hand started in collision are dropped."""
    rng = np.random.default_rng(settings.seed)
    n = settings.n_samples
    rel = np.column_stack([rng.uniform(-settings.xy_range, settings.xy_range, n),
                           rng.uniform(-settings.xy_range, settings.xy_range, n),
                           rng.uniform(-np.pi, np.pi, n)])
    b = world.grasp_batch(rel, spread=settings.spread, threads=0)
    ok = ~np.asarray(b["collision_at_start"], dtype=bool)
    return rel[ok], np.asarray(b["joint_angles"])[ok], np.asarray(b["epsilon"])[ok]


def build_models(obj: Union[str, ObjectModel], hand="barrett_bh8", settings: Optional[ModelSettings] = None,
                 cache_dir: Union[str, Path, None] = None, progress=None) -> GraspModels:
    """Fits (or loads from ``cache_dir``) the measurement and stability models of ``obj``.

    ``progress`` is an optional callable taking a message string.
    """
    settings = settings or ModelSettings()
    obj = load_object(obj) if isinstance(obj, str) else obj
    world = World.single(obj, pose=(0.0, 0.0, 0.0), hand=hand)
    hand_text = Path(world.hand.path).read_text() if getattr(world.hand, "path", None) else world.hand.name
    key = _cache_key(world.object, hand_text, settings)
    say = progress or (lambda msg: None)
    files = None
    if cache_dir is not None:
        d = Path(cache_dir)
        files = (d / f"{key}_measurement.npz", d / f"{key}_stability.npz", d / f"{key}.json")
        if all(f.exists() for f in files):
            info = json.loads(files[2].read_text())
            say(f"models for {obj.name}: loaded from cache ({key})")
            return GraspModels(_gp.load(files[0]), _gp.load(files[1]), settings, info["joint_index"], info)
    say(f"models for {obj.name}: simulating {settings.n_samples} grasps")
    rel, q, eps = simulate_training_data(world, settings)
    if len(rel) < 10:
        raise ValueError(f"{obj.name}: only {len(rel)} collision-free grasps in the sampled range")
    joint_index = np.arange(1, q.shape[1])     # every phalanx joint (the spread is fixed)
    X = features(rel)
    say(f"models for {obj.name}: fitting FITC GPs on {len(rel)} grasps")
    kw = dict(n_inducing=min(settings.n_inducing, len(rel)), max_iter=settings.max_iter, seed=settings.seed,
              noise=1e-2)
    measurement = _gp.SparseGP(**kw).fit(X, q[:, joint_index])
    stability = _gp.SparseGP(**kw).fit(X, np.maximum(eps, 0.0))
    info = {"key": key, "object": obj.name, "hand": world.hand.name, "settings": asdict(settings),
            "samples": int(len(rel)), "force_closure_fraction": float(np.mean(eps > 0)),
            "stable_fraction": float(np.mean(eps > settings.eps_stable)), "joint_index": joint_index.tolist()}
    if files is not None:
        try:
            files[0].parent.mkdir(parents=True, exist_ok=True)
            measurement.save(files[0])
            stability.save(files[1])
            files[2].write_text(json.dumps(info, indent=1))
        except OSError as e:
            raise ValueError(f"cache_dir: cannot write models to {files[0].parent}: {e}") from e
    return GraspModels(measurement, stability, settings, joint_index, info)
