"""Measurement and stability models for top grasps, learnt from simulated grasps (thesis §3.2).

The models take the grasp relative to the object: a top grasp at (x, y, yaw) in the object's
frame (see :func:`relative_top_grasps`). Inputs to the GPs are (x, y, cos yaw, sin yaw), so that
yaw wraps. Two sparse (FITC) GPs are fitted on simulated grasps of the object with the hand:

* measurement model P(M|A,O): the hand's phalanx joint angles after closing (one output per
  phalanx joint, shared hyper-parameters), Gaussian with the GP's predictive variance plus noise;
* stability model P(S|A,O): the GP regression of the grasp's epsilon quality (0 without force
  closure), mapped to a probability through z = (mu - eps_stable) / sd of the latent epsilon and
  a logistic calibration P(S) = 1 / (1 + exp(-(a z + b))) fitted on held-out simulated grasps
  (the plain probit Phi(z) is overconfident: grasps it gave P(S) > 0.9 were stable 56-61% of the
  time on the mugs).

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
from scipy.optimize import minimize
from scipy.special import expit

from .. import _core
from .. import gp as _gp
from ..objects import ObjectModel, load_object
from ..world import World

CACHE_VERSION = 6  # bump when the simulator or the models change what a key means

#: Grid nodes of highest P(S) a ModelTable keeps (the planners' PSO seeds).
N_BEST = 64

#: Candidate finger spreads (rad) when ModelSettings.spread is None.
AUTO_SPREADS = tuple(float(np.radians(d)) for d in (0.0, 30.0, 45.0, 60.0, 90.0))


@dataclass(frozen=True)
class ModelSettings:
    """How the models are built (every field is part of the cache key)."""

    n_samples: int = 2000         # simulated grasps
    n_inducing: int = 200         # FITC inducing inputs
    xy_range: float = 0.06        # relative x, y sampled uniformly in +-xy_range (m)
    # Finger spread of the grasps (rad), or None (the default): chosen per object from
    # AUTO_SPREADS by a pilot sample, as the spread with the most grasps that are both stable
    # (epsilon) and held in the physical lift test (see choose_spread). The two criteria pull
    # apart: on the built-in mug2 a 90-degree spread (fingers 1 and 2 facing each other, the thumb
    # pushing between them) gives stable epsilon 3x as often as 30 degrees, but those grasps are
    # never held when lifted (0/25), while 17/25 of the stable 30-degree ones are.
    spread: Optional[float] = None
    n_pilot: int = 300            # pilot grasps per candidate spread (spread=None)
    n_pilot_lifts: int = 16       # lift tests per candidate spread (on its stable pilot grasps)
    # Epsilon above which a grasp counts as stable: force closure with a margin (about the
    # 10th percentile of positive epsilons on the built-in objects).
    eps_stable: float = 0.01
    max_iter: int = 150           # hyper-parameter optimisation iterations
    n_calibration: int = 1000     # held-out simulated grasps for the P(S) calibration
    seed: int = 0

    def __post_init__(self):
        if self.n_samples < 10:
            raise ValueError(f"n_samples: need at least 10, got {self.n_samples}")
        if self.n_inducing < 1:
            raise ValueError(f"n_inducing: must be >= 1, got {self.n_inducing}")
        if not (self.xy_range > 0 and np.isfinite(self.xy_range)):
            raise ValueError(f"xy_range: must be positive, got {self.xy_range}")
        if self.spread is not None and not (np.isfinite(self.spread) and 0.0 <= self.spread <= np.pi):
            raise ValueError(f"spread: must be None (choose per object) or in [0, pi], got {self.spread}")
        if self.n_pilot < 10 or self.n_pilot_lifts < 1:
            raise ValueError("n_pilot: need at least 10 grasps and n_pilot_lifts at least 1")


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
        """P(S | A, O) at relative grasps (..., 3): the calibrated logistic of z = (mu - eps_stable) / sd."""
        a, b = self.info.get("calibration", (1.702, 0.0))  # default: the logistic close to Phi(z)
        return expit(a * self._stability_z(rel) + b)

    def log_stability_probability(self, rel) -> np.ndarray:
        a, b = self.info.get("calibration", (1.702, 0.0))
        return -np.logaddexp(0.0, -(a * self._stability_z(rel) + b))

    @property
    def spread(self) -> float:
        """The finger spread (rad) of every grasp these models describe."""
        return float(self.info.get("spread", self.settings.spread if self.settings.spread is not None else np.pi / 2))

    @property
    def n_joints(self) -> int:
        return len(self.joint_index)

    def table(self, xy_step: float = 0.002, yaw_step: float = np.radians(5.0)) -> "ModelTable":
        """The models tabulated over relative grasps for the planners (built on first use, kept).

        Channel 0 is P(S | A, O), channels 1..K the measurement mean of the K joints and K+1..2K its
        variance (with noise). The grid spans the training box (+-``settings.xy_range``) and all
        yaws; outside the box P(S) is 0 (the models know nothing there, and a GP's prior would
        claim stability) and the measurement channels take the nearest edge value.
        """
        key = (float(xy_step), float(yaw_step))
        cached = getattr(self, "_tables", {}).get(key)
        if cached is None:
            cached = ModelTable.build(self, xy_step, yaw_step)
            self._tables = {**getattr(self, "_tables", {}), key: cached}
        return cached


class ModelTable:
    """:class:`GraspModels` on a grid (C++ ``RelativePoseGrid``): trilinear lookups at every
    (candidate grasp, particle) pair instead of GP predictions, for planning."""

    def __init__(self, grid, n_joints: int, xy_range: float, best: np.ndarray):
        self.grid, self.n_joints, self.xy_range, self.best = grid, int(n_joints), float(xy_range), best

    @classmethod
    def build(cls, models: "GraspModels", xy_step: float, yaw_step: float) -> "ModelTable":
        if not (xy_step > 0 and yaw_step > 0):
            raise ValueError("table: steps must be positive")
        r = models.settings.xy_range
        nx = max(2, int(np.ceil(2 * r / xy_step)) + 1)
        nyaw = max(4, int(np.ceil(2 * np.pi / yaw_step)))
        xs = np.linspace(-r, r, nx)
        yaws = -np.pi + 2 * np.pi * np.arange(nyaw) / nyaw
        X, Y, T = np.meshgrid(xs, xs, yaws, indexing="ij")
        rel = np.column_stack([X.ravel(), Y.ravel(), T.ravel()])
        k = models.n_joints
        values = np.empty((len(rel), 1 + 2 * k))
        for s in range(0, len(rel), 65536):  # bounded memory
            part = rel[s:s + 65536]
            values[s:s + 65536, 0] = models.stability_probability(part)
            mean, var = models.predict_measurement(part)
            values[s:s + 65536, 1:1 + k], values[s:s + 65536, 1 + k:] = mean, var
        outside = np.full(1 + 2 * k, np.nan)
        outside[0] = 0.0
        grid = _core.belief.RelativePoseGrid(np.array([-r, -r]), np.array([r, r]), nx, nx, nyaw, values, outside)
        # the planners' PSO seeds: the nodes of highest P(S), best first
        top = np.argpartition(-values[:, 0], N_BEST - 1)[:N_BEST]
        return cls(grid, k, r, rel[top[np.argsort(-values[top, 0])]])

    def best_relative_grasps(self, k: int = 64) -> np.ndarray:
        """The k grid nodes with the highest P(S) (k, 3), best first (found when the table is built)."""
        if not 1 <= k <= len(self.best):
            raise ValueError(f"k: between 1 and {len(self.best)}, got {k}")
        return self.best[:k]

    def stability(self, rel) -> np.ndarray:
        """P(S) at relative grasps (P, 3)."""
        return self.grid.interpolate(np.atleast_2d(np.asarray(rel, dtype=float)))[:, 0]

    def expected_stability(self, actions, poses, weights, threads: int = 1) -> np.ndarray:
        """Eq. 3.1's integral over a particle belief: sum_j w_j P(S | a relative to pose_j), (A,)."""
        return self.grid.expected(np.atleast_2d(np.asarray(actions, float)), np.asarray(poses, float),
                                  np.asarray(weights, float), 0, int(threads))

    def measurement_pairs(self, actions, poses, threads: int = 1):
        """Measurement mean and variance at every (action, pose) pair: two (A, N, K) arrays."""
        A = np.atleast_2d(np.asarray(actions, float))
        P = np.asarray(poses, float)
        k = self.n_joints
        out = self.grid.interpolate_pairs(A, P, 1, 2 * k, int(threads)).reshape(len(A), len(P), 2 * k)
        return out[..., :k], np.maximum(out[..., k:], 1e-12)

    def expected_posterior_entropy(self, actions, poses, log_weights, n_samples: int = 100, seed: int = 0,
                                   threads: int = 1):
        """Eq. 3.2 (weight-based) for every action: (entropy (A,), standard error (A,))."""
        k = self.n_joints
        return self.grid.expected_posterior_entropy(np.atleast_2d(np.asarray(actions, float)),
                                                    np.asarray(poses, float), np.asarray(log_weights, float),
                                                    1, 1 + k, k, int(n_samples), int(seed), int(threads))


def _cache_key(obj: ObjectModel, hand_text: str, settings: ModelSettings) -> str:
    h = hashlib.sha256()
    h.update(f"v{CACHE_VERSION}".encode())
    h.update(np.ascontiguousarray(obj.vertices, dtype=np.float64).tobytes())
    h.update(np.ascontiguousarray(obj.faces, dtype=np.int64).tobytes())
    h.update(hand_text.encode())
    h.update(json.dumps(asdict(settings), sort_keys=True).encode())
    return h.hexdigest()[:20]


def fit_calibration(z, stable) -> tuple:
    """Logistic regression P = 1 / (1 + exp(-(a z + b))) of outcomes on scores (maximum likelihood,
    a tiny ridge keeps it finite when the classes separate)."""
    z = np.asarray(z, dtype=float)
    y = np.asarray(stable, dtype=float)

    def nll(p):
        t = p[0] * z + p[1]
        return np.sum(np.logaddexp(0.0, t) - y * t) + 1e-3 * (p[0] ** 2 + p[1] ** 2)

    def grad(p):
        t = p[0] * z + p[1]
        r = expit(t) - y
        return np.array([r @ z, r.sum()]) + 2e-3 * p

    res = minimize(nll, np.array([1.0, 0.0]), jac=grad, method="BFGS")
    return float(res.x[0]), float(res.x[1])


def choose_spread(world: World, settings: ModelSettings, say=lambda m: None) -> tuple:
    """The pilot behind ModelSettings.spread = None: for each spread in AUTO_SPREADS, simulate
    n_pilot random relative top grasps, lift-test up to n_pilot_lifts of the stable ones, and score
    stable fraction x lifted fraction. Returns (best spread, {degrees: (stable, lifted, tested)});
    with no grasp lifted at any spread, the spread with the most stable grasps."""
    rng = np.random.default_rng([settings.seed, 7])
    r = settings.xy_range
    rel = np.column_stack([rng.uniform(-r, r, settings.n_pilot), rng.uniform(-r, r, settings.n_pilot),
                           rng.uniform(-np.pi, np.pi, settings.n_pilot)])
    table, scores = {}, []
    for sp in AUTO_SPREADS:
        b = world.grasp_batch(rel, spread=sp, threads=0)
        ok = (np.asarray(b.epsilon) > settings.eps_stable) & ~np.asarray(b.collision_at_start, dtype=bool)
        idx = np.flatnonzero(ok)[:settings.n_pilot_lifts]
        lifted = int(np.sum(world.grasp_batch(rel[idx], spread=sp, lift=True, threads=0).lifted)) if len(idx) else 0
        frac = float(np.mean(ok))
        table[round(float(np.degrees(sp)))] = (frac, lifted, int(len(idx)))
        scores.append((frac * (lifted / len(idx) if len(idx) else 0.0), frac))
        say(f"  spread {np.degrees(sp):3.0f} deg: {100 * frac:.0f}% stable, {lifted}/{len(idx)} of those lifted")
    best = max(range(len(scores)), key=lambda i: scores[i])
    return AUTO_SPREADS[best], table


def simulate_training_data(world: World, settings: ModelSettings, seed_offset: int = 0, n: Optional[int] = None,
                           spread: Optional[float] = None):
    """Relative grasps (n, 3), joint angles (n, J) and epsilon (n,) from the simulator; grasps
    whose open hand started in collision are dropped."""
    rng = np.random.default_rng([settings.seed, seed_offset])
    n = settings.n_samples if n is None else int(n)
    rel = np.column_stack([rng.uniform(-settings.xy_range, settings.xy_range, n),
                           rng.uniform(-settings.xy_range, settings.xy_range, n),
                           rng.uniform(-np.pi, np.pi, n)])
    spread = settings.spread if spread is None else spread
    b = world.grasp_batch(rel, spread=spread, threads=0)
    ok = ~np.asarray(b.collision_at_start, dtype=bool)
    return rel[ok], np.asarray(b.joint_angles)[ok], np.asarray(b.epsilon)[ok]


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
    spread, pilot = settings.spread, None
    if spread is None:
        say(f"models for {obj.name}: choosing the finger spread (pilot of {settings.n_pilot} grasps per spread)")
        spread, pilot = choose_spread(world, settings, say)
    say(f"models for {obj.name}: simulating {settings.n_samples} grasps at spread {np.degrees(spread):.0f} deg")
    rel, q, eps = simulate_training_data(world, settings, spread=spread)
    if len(rel) < 10:
        raise ValueError(f"{obj.name}: only {len(rel)} collision-free grasps in the sampled range")
    joint_index = np.arange(1, q.shape[1])     # every phalanx joint (the spread is fixed)
    X = features(rel)
    say(f"models for {obj.name}: fitting FITC GPs on {len(rel)} grasps")
    kw = dict(n_inducing=min(settings.n_inducing, len(rel)), max_iter=settings.max_iter, seed=settings.seed,
              noise=1e-2)
    measurement = _gp.SparseGP(**kw).fit(X, q[:, joint_index])
    stability = _gp.SparseGP(**kw).fit(X, np.maximum(eps, 0.0))
    models = GraspModels(measurement, stability, settings, joint_index, {"spread": float(spread)})
    calibration = (1.702, 0.0)
    if settings.n_calibration > 0:
        say(f"models for {obj.name}: calibrating P(S) on {settings.n_calibration} held-out grasps")
        rel_c, _, eps_c = simulate_training_data(world, settings, seed_offset=1, n=settings.n_calibration,
                                                 spread=spread)
        if len(rel_c) >= 10:
            calibration = fit_calibration(models._stability_z(rel_c), eps_c > settings.eps_stable)
    info = {"key": key, "object": obj.name, "calibration": list(calibration), "hand": world.hand.name, "settings": asdict(settings),
            "samples": int(len(rel)), "force_closure_fraction": float(np.mean(eps > 0)),
            "stable_fraction": float(np.mean(eps > settings.eps_stable)), "joint_index": joint_index.tolist(),
            "spread": float(spread), "spread_pilot": pilot}
    if files is not None:
        try:
            files[0].parent.mkdir(parents=True, exist_ok=True)
            measurement.save(files[0])
            stability.save(files[1])
            files[2].write_text(json.dumps(info, indent=1))
        except OSError as e:
            raise ValueError(f"cache_dir: cannot write models to {files[0].parent}: {e}") from e
    models.info = info
    return models
