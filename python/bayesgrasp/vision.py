"""Seeing the object: a simulated RGB-D (depth) camera, table-top segmentation and registration of
a partial cloud against object models (thesis §4.2, Publication V).

The heavy lifting is in C++ (:mod:`bayesgrasp._core.vision`): a BVH ray caster with a
structured-light noise model, PCL's plane RANSAC and Euclidean clustering, and a registration
pipeline of voxel downsampling (PCL), normals and FPFH features, a seeded RANSAC over feature
correspondences, point-to-plane ICP, and a hypothesis choice that penalises upside-down fits.
To register many clouds against the same models, prepare the models once in a :class:`Registrar`.
The registration's settings are a :class:`RegistrationOptions` (one option class per step:
``features``, ``correspondences``, ``ransac``, ``icp``, ``up_prior``); :func:`register` and
:class:`Registrar` take one, and its fields by keyword (see :func:`registration_options`).

>>> from bayesgrasp.vision import Camera, segment_table, register
>>> cam = Camera.looking_at(eye=(0.5, -0.5, 0.5), target=(0, 0, 0.05))
>>> cloud = cam.capture([(V, F)], table=True, seed=1)          # (N, 3) world frame, noisy
>>> seg = segment_table(cloud)                                 # clusters, largest first
>>> results = register(seg.cluster_points[0], [model_a, model_b], viewpoint=cam.eye)
>>> results[0].transform, results[0].fitness, results[0].weight
>>> opts = RegistrationOptions(voxel=0.004)
>>> opts.ransac.restarts = 6
>>> reg = Registrar([model_a, model_b], opts)                  # models prepared once
>>> results = reg.register(seg.cluster_points[0], viewpoint=cam.eye)
>>> [r.status for r in results]                                # RegistrationStatus.Ok, ...

Conventions: metres; world frame z up with the table top at z = 0; camera frame x right, y down,
z forward; depth images hold the camera-frame z (NaN where nothing is measured).

Fitting error and weight (Eq. 4.1's phi(delta)): ``delta = sqrt(mean_i min(d_i, tau)^2)`` over
the downsampled scene points, ``d_i`` the distance to the registered model surface and
``tau = 1.5 voxel``; ``phi = exp(-delta^2 / (2 sigma^2))`` with ``sigma = 0.5 voxel`` (unnormalised);
``weight = phi / sum(phi)`` over the models of one call that registered successfully
(:func:`bayesgrasp.belief.shape_weights`).

By default registration assumes the cloud is in the world frame (z up) and the models rest upright
on the table in their own frame (+z up, as the built-in objects do): hypotheses are searched over
yaw and translation, refined in 6 DOF by ICP, and upside-down fits are penalised. Pass
``up_prior=False`` (``options.up_prior.enabled = False``) for arbitrary orientations (6-DOF
search, no penalty), or ``up=`` the table normal in the cloud's frame.

A model that cannot be registered gives a result with ``success=False``, a
:class:`RegistrationStatus` (``NoSurface``, ``TooFewScenePoints``, ``NoHypothesis``, ...) and a
human-readable ``reason``; bad input (an empty cloud, no models, bad options) is a ``ValueError``.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, List, Optional, Sequence, Tuple, Union

from bayesgrasp._args import c_int, c_seed, with_fields
import numpy as np

from bayesgrasp import _core as _bgcore
from bayesgrasp.belief import shape_weights

__all__ = [
    "Camera", "SegmentationResult", "RegistrationResult", "Registrar", "segment_table", "register",
    "model_samples", "rotation_error", "as_cloud", "as_mesh", "registration_options",
    "RegistrationOptions", "FeatureOptions", "CorrespondenceOptions", "RansacOptions", "IcpOptions", "UpPrior",
    "FeatureEstimator", "RegistrationStatus", "Intrinsics", "Table", "NoiseModel", "SegmentationOptions",
]

_v = _bgcore.vision

RegistrationOptions = _v.RegistrationOptions
FeatureOptions = _v.FeatureOptions
CorrespondenceOptions = _v.CorrespondenceOptions
RansacOptions = _v.RansacOptions
IcpOptions = _v.IcpOptions
UpPrior = _v.UpPrior
FeatureEstimator = _v.FeatureEstimator
RegistrationStatus = _v.RegistrationStatus
Intrinsics = _v.Intrinsics
Table = _v.Table
NoiseModel = _v.NoiseModel
SegmentationOptions = _v.SegmentationOptions
SegmentationResult = _v.SegmentationResult


# ---------------------------------------------------------------------------------------------
# input conversion
def as_mesh(obj, name: str = "mesh") -> Tuple[np.ndarray, np.ndarray]:
    """(vertices float64 (N, 3), faces int32 (M, 3)) from a (V, F) tuple or an object with
    ``.vertices`` and ``.faces`` (ObjectModel, trimesh.Trimesh)."""
    if hasattr(obj, "vertices") and hasattr(obj, "faces"):
        V, F = obj.vertices, obj.faces
    elif isinstance(obj, (tuple, list)) and len(obj) == 2:
        V, F = obj
    else:
        raise ValueError(f"{name}: expected a (vertices, faces) tuple or an object with .vertices and .faces")
    V = np.ascontiguousarray(np.asarray(V, dtype=np.float64))
    F = np.asarray(F)
    if V.ndim != 2 or V.shape[1] != 3:
        raise ValueError(f"{name}: vertices must have shape (N, 3), got {V.shape}")
    if F.ndim != 2 or F.shape[1] != 3 or (F.size and not np.issubdtype(F.dtype, np.integer)):
        raise ValueError(f"{name}: faces must be integer with shape (M, 3), got {F.shape} {F.dtype}")
    return V, np.ascontiguousarray(F, dtype=np.int32)


def as_cloud(cloud, name: str = "cloud") -> np.ndarray:
    """(N, 3) float64 from a numpy array (N, 3) or (H, W, 3) (organised), or an Open3D point cloud
    (anything with ``.points``). NaN rows are kept (the functions below drop them)."""
    if hasattr(cloud, "points") and not isinstance(cloud, np.ndarray):
        cloud = np.asarray(cloud.points)
    a = np.asarray(cloud, dtype=np.float64)
    if a.ndim == 3 and a.shape[2] == 3:
        a = a.reshape(-1, 3)
    if a.ndim != 2 or a.shape[1] != 3:
        raise ValueError(f"{name}: expected shape (N, 3) or (H, W, 3), got {a.shape}")
    if np.isinf(a).any():
        raise ValueError(f"{name}: contains infinity")
    return np.ascontiguousarray(a)


# ---------------------------------------------------------------------------------------------
@dataclass
class Camera:
    """A pinhole depth camera (default: Kinect v1-like, 640 x 480, f = 525 px, principal point at
    the image centre) with a camera-to-world ``pose`` (4x4)."""

    pose: np.ndarray = field(default_factory=lambda: np.eye(4))
    width: int = 640
    height: int = 480
    fx: float = 525.0
    fy: float = 525.0
    cx: Optional[float] = None
    cy: Optional[float] = None

    def __post_init__(self):
        self.pose = np.asarray(self.pose, dtype=np.float64)
        if self.pose.shape != (4, 4) or not np.all(np.isfinite(self.pose)):
            raise ValueError(f"pose: expected a finite (4, 4) matrix, got shape {self.pose.shape}")
        if self.cx is None:
            self.cx = (self.width - 1) / 2.0
        if self.cy is None:
            self.cy = (self.height - 1) / 2.0

    @classmethod
    def looking_at(cls, eye, target, up=(0.0, 0.0, 1.0), **intrinsics) -> "Camera":
        """A camera at ``eye`` looking at ``target`` (world frame), image up towards ``up``."""
        pose = _v.look_at(np.asarray(eye, float), np.asarray(target, float), np.asarray(up, float))
        return cls(pose=np.asarray(pose), **intrinsics)

    @property
    def eye(self) -> np.ndarray:
        return self.pose[:3, 3].copy()

    @property
    def K(self) -> np.ndarray:
        return np.array([[self.fx, 0, self.cx], [0, self.fy, self.cy], [0, 0, 1.0]])

    @property
    def intrinsics(self) -> "Intrinsics":
        """The core's :class:`Intrinsics` of this camera."""
        return Intrinsics(width=c_int(self.width, "width"), height=c_int(self.height, "height"), fx=float(self.fx),
                          fy=float(self.fy), cx=float(self.cx), cy=float(self.cy))

    def render(self, meshes: Sequence, table: Union[bool, dict, "Table"] = False, noise: Union[bool, "NoiseModel"] = True,
               seed: int = 0, **noise_fields) -> Tuple[np.ndarray, np.ndarray]:
        """Ray-casts ``meshes`` (world frame; (V, F) tuples or mesh objects) and optionally the table
        (True: 1 x 1 m at z = 0 centred at the origin; a dict with ``z``, ``center`` (x, y),
        ``half_extents`` (hx, hy), inf allowed; or a :class:`Table`). Returns (depth (H, W) in metres
        with NaN where nothing is measured, label (H, W): index of the mesh seen, -2 table, -1 nothing).
        ``noise``: on/off or a :class:`NoiseModel`; ``noise_fields`` set its fields (sigma_a, sigma_b,
        baseline, disparity_step, max_incidence (rad), edge_jump, edge_drop_prob, min_depth, max_depth)."""
        ms = [as_mesh(m, f"meshes[{i}]") for i, m in enumerate(meshes)]
        nm = noise.__copy__() if isinstance(noise, NoiseModel) else NoiseModel(enabled=bool(noise))
        nm.seed = c_seed(seed, "seed")
        for key, value in noise_fields.items():
            if key not in NoiseModel.fields:
                raise ValueError(f"{key}: not a field of NoiseModel")
            setattr(nm, key, value)
        depth, label = _v.render(ms, self.pose, self.intrinsics, _table(table), nm)
        return np.asarray(depth), np.asarray(label)

    def points(self, depth: np.ndarray, world: bool = True, organised: bool = False) -> np.ndarray:
        """Back-projects a depth image: organised -> (H, W, 3) with NaN for missing pixels, else
        (N, 3) valid points; world or camera frame."""
        depth = np.asarray(depth, dtype=np.float64)
        if depth.shape != (self.height, self.width):
            raise ValueError(f"depth: expected shape ({self.height}, {self.width}), got {depth.shape}")
        P = np.asarray(_v.depth_to_points(depth, self.pose, self.intrinsics, world=world, organised=organised))
        return P.reshape(self.height, self.width, 3) if organised else P

    def capture(self, meshes: Sequence, table: Union[bool, dict] = False, noise: bool = True, seed: int = 0,
                world: bool = True, organised: bool = False, **noise_params) -> np.ndarray:
        """render() then points(): the cloud the camera sees."""
        depth, _ = self.render(meshes, table=table, noise=noise, seed=seed, **noise_params)
        return self.points(depth, world=world, organised=organised)


def _table(table) -> "Table":
    """A :class:`Table` from False / True / a dict (z, center, half_extents) / a Table."""
    if isinstance(table, Table):
        return table
    if table is True or table is False:
        return Table(enabled=bool(table))
    tb = dict(table)
    unknown = set(tb) - {"z", "center", "half_extents"}
    if unknown:
        raise ValueError(f"table: unknown keys {sorted(unknown)} (known: z, center, half_extents)")
    cx, cy = (float(v) for v in tb.get("center", (0.0, 0.0)))
    hx, hy = (float(v) for v in tb.get("half_extents", (0.5, 0.5)))
    return Table(enabled=True, z=float(tb.get("z", 0.0)), center_x=cx, center_y=cy, half_x=hx, half_y=hy)


# ---------------------------------------------------------------------------------------------
def segment_table(cloud, options: Optional[SegmentationOptions] = None, **fields) -> SegmentationResult:
    """Table plane by RANSAC, the points ``min_height``..``max_height`` above it, Euclidean
    clusters of those (largest first). ``cloud``: (N, 3), organised (H, W, 3) or an Open3D cloud;
    NaN rows are ignored. ``options``: a :class:`SegmentationOptions`, its fields also given by
    keyword (plane_threshold, plane_iterations, min_height, max_height, cluster_tolerance,
    min_cluster_size, max_cluster_size, up). Returns a :class:`SegmentationResult` (plane,
    plane_inliers, clusters, cluster_points). ValueError for a bad field (naming it), fewer than 3
    finite points or no plane."""
    return _v.segment_table(as_cloud(cloud), with_fields(SegmentationOptions, options, fields))


# ---------------------------------------------------------------------------------------------
# registration options
def _steps(options: RegistrationOptions) -> List[str]:
    """The fields of RegistrationOptions that are option classes themselves (its steps)."""
    return [f for f in RegistrationOptions.fields if hasattr(type(getattr(options, f)), "fields")]


def registration_options(options: Optional[RegistrationOptions] = None, **keywords) -> RegistrationOptions:
    """A validated copy of ``options`` (default: ``RegistrationOptions()``) with ``keywords`` set.
    A keyword names a field of :class:`RegistrationOptions` (``voxel=0.004``, ``ransac=RansacOptions(...)``)
    or a field of exactly one of its steps (``restarts=6`` sets ``ransac.restarts``, ``upright=False``
    sets ``up_prior.upright``, ``estimator=FeatureEstimator.Pcl``); a field two steps share
    (``iterations``, of ``ransac`` and ``icp``) is given through its step. A step given True or False
    sets its ``enabled`` field (``up_prior=False``: 6-DOF, no tilt limit). The names are the bound
    classes' own (``RegistrationOptions.fields``, ``RansacOptions.fields``, ...); angles are radians.
    ValueError naming an unknown or shared keyword or a bad value; ``options`` is never changed."""
    out = with_fields(RegistrationOptions, options)
    steps = _steps(out)
    for key, value in keywords.items():
        if key in steps and isinstance(value, (bool, np.bool_)):
            key, value = f"{key}.enabled", bool(value)
        elif key not in RegistrationOptions.fields:
            owners = [s for s in steps if key in type(getattr(out, s)).fields]
            if len(owners) != 1:
                known = sorted(set(RegistrationOptions.fields) | {f for s in steps for f in type(getattr(out, s)).fields})
                why = f"a field of {' and '.join(owners)}: give it through its step" if owners else \
                    f"unknown registration option (known: {', '.join(known)})"
                raise ValueError(f"{key}: {why}")
            key = f"{owners[0]}.{key}"
        step, _, name = key.rpartition(".")
        if step:
            sub = getattr(out, step)
            try:
                setattr(out, step, with_fields(type(sub), sub, {name: value}))
            except ValueError as e:
                raise ValueError(f"{step}.{e}") from None
        else:
            out = with_fields(RegistrationOptions, out, {name: value})
    out.validate()
    return out


# ---------------------------------------------------------------------------------------------
# registration
@dataclass
class RegistrationResult:
    """One model's registration. ``transform`` maps model coordinates to the cloud's frame."""

    success: bool
    reason: str
    transform: np.ndarray
    fitness: float      # fraction of downsampled scene points within the inlier distance of the model
    rmse: float         # RMS distance of those inliers (m)
    delta: float        # fitting error (m), see the module docstring
    phi: float          # exp(-delta^2 / (2 sigma^2)), unnormalised
    weight: float       # phi normalised over the successful models of the call (belief.shape_weights)
    up_cos: float       # cos of the angle between the model's +z in the scene and `up`
    scene_points: int
    model_points: int
    time_features: float
    time_global: float
    time_icp: float
    model: Any = None   # the name or index of the model
    status: Any = None  # RegistrationStatus: Ok, or why not
    ransac_iterations: int = 0  # total over the RANSAC restarts
    cost: float = 0.0   # selection cost of the chosen hypothesis (delta / tau + up penalty)

    @classmethod
    def known(cls, model, transform, phi: float = 1.0, success: bool = True) -> "RegistrationResult":
        """A registration given rather than computed (a model placed by hand, a known pose):
        ``transform`` model -> scene (4x4), ``phi`` its fit weight phi(delta); the fit measures
        are zero and ``status`` is None."""
        T = np.asarray(transform, dtype=float)
        if T.shape != (4, 4) or not np.all(np.isfinite(T)):
            raise ValueError(f"transform: expected a finite 4x4 matrix, got shape {T.shape}")
        return cls(success=bool(success), reason="" if success else "given as failed", transform=T, fitness=0.0,
                   rmse=0.0, delta=0.0, phi=float(phi), weight=0.0, up_cos=1.0, scene_points=0, model_points=0,
                   time_features=0.0, time_global=0.0, time_icp=0.0, model=model)

    def as_dict(self) -> dict:
        return {"model": self.model, "success": self.success, "reason": self.reason,
                "transform": np.asarray(self.transform).tolist(), "fitness": self.fitness, "rmse": self.rmse,
                "delta": self.delta, "phi": self.phi, "weight": self.weight}


def _results(raw: Sequence, names: Sequence) -> List[RegistrationResult]:
    """Python results from the core's, with the shape weights over the models of the call."""
    weights = shape_weights([r.phi for r in raw], [r.success for r in raw])
    return [RegistrationResult(
        success=bool(r.success), reason=r.reason, transform=np.array(r.transform), fitness=float(r.fitness),
        rmse=float(r.rmse), delta=float(r.delta), phi=float(r.phi), weight=float(w), up_cos=float(r.up_cos),
        scene_points=int(r.scene_points), model_points=int(r.model_points), time_features=float(r.time_features),
        time_global=float(r.time_global), time_icp=float(r.time_icp), model=name, status=r.status,
        ransac_iterations=int(r.ransac_iterations), cost=float(r.cost))
        for r, w, name in zip(raw, weights, names)]


def _mesh_samples(V: np.ndarray, F: np.ndarray, options: RegistrationOptions, seed: int) -> Tuple[np.ndarray, np.ndarray]:
    s = _v.model_from_mesh(V, F, options, seed=c_seed(seed, "seed"))
    return np.asarray(s.points), np.asarray(s.normals)


def _samples_of(model) -> Optional[Tuple[np.ndarray, np.ndarray]]:
    """(points, normals) if ``model`` is given as samples (Open3D cloud with normals, (N, 6) array,
    (points, normals) tuple), else None (a mesh)."""
    if hasattr(model, "points") and hasattr(model, "normals") and not isinstance(model, np.ndarray):
        P, N = np.asarray(model.points, float), np.asarray(model.normals, float)
        if len(N) != len(P):
            raise ValueError("model: an Open3D cloud needs normals (estimate and orient them outwards)")
        return np.ascontiguousarray(P), np.ascontiguousarray(N)
    if isinstance(model, np.ndarray):
        a = np.asarray(model, float)
        if a.ndim != 2 or a.shape[1] != 6:
            raise ValueError(f"model: a point array must be (N, 6) points + normals, got {a.shape}")
        return np.ascontiguousarray(a[:, :3]), np.ascontiguousarray(a[:, 3:])
    if isinstance(model, (tuple, list)) and len(model) == 2:
        A, B = np.asarray(model[0]), np.asarray(model[1])
        if A.ndim == 2 and B.ndim == 2 and A.shape[1] == 3 and B.shape[1] == 3 and np.issubdtype(B.dtype, np.floating) \
                and len(A) == len(B):
            return np.ascontiguousarray(A, float), np.ascontiguousarray(B, float)
    return None


def model_samples(model, voxel: float = 0.005, seed: int = 0, samples: int = 0) -> Tuple[np.ndarray, np.ndarray]:
    """(points, outward normals) on a model's surface, for :func:`register`. ``model``: a mesh
    ((V, F) or an object with .vertices/.faces): sampled uniformly, area-weighted, seeded
    (``samples`` points; 0: area / (voxel/3)^2, clamped to [2000, 200000]); an (N, 6) array of
    points and normals; a (points, normals) tuple of two (N, 3) arrays; or an Open3D cloud with
    normals. ValueError if it has no surface."""
    given = _samples_of(model)
    if given is not None:
        return given
    V, F = as_mesh(model, "model")
    return _mesh_samples(V, F, RegistrationOptions(voxel=float(voxel), model_samples=c_int(samples, "samples")), seed)


def _model_clouds(models: Sequence, options: RegistrationOptions, model_seed: int) -> List[Tuple[np.ndarray, np.ndarray]]:
    """Surface samples of each model (mesh i seeded with model_seed + i, options.model_samples
    points). A mesh without area gives no samples: the core reports it as NoSurface."""
    out = []
    for i, m in enumerate(models):
        try:
            given = _samples_of(m)
            if given is None:
                V, F = as_mesh(m, "model")
                has_area = _bgcore.geometry.surface_area(V, F) > 0
                given = _mesh_samples(V, F, options, model_seed + i) if has_area else (np.zeros((0, 3)),) * 2
        except ValueError as e:
            raise ValueError(f"models[{i}]: {e}") from None
        out.append(given)
    return out


def _model_names(names: Optional[Sequence], n: int) -> list:
    if names is None:
        return list(range(n))
    names = list(names)
    if len(names) != n:
        raise ValueError(f"names: expected {n} names, got {len(names)}")
    return names


def _viewpoint(viewpoint) -> Optional[np.ndarray]:
    return None if viewpoint is None else np.asarray(viewpoint, float)


class Registrar:
    """Object models prepared once, partial clouds registered against them many times.

    Preparing a model (a radius grid over its dense surface samples, downsampling, normals, FPFH
    features) does not depend on the cloud, so it is done here once per model; :meth:`register`
    does only the per-cloud work. With the same options, seed and viewpoint,
    ``Registrar(models).register(cloud)`` gives exactly the transforms, fits and weights of
    ``register(cloud, models)``.

    >>> reg = Registrar([mug_a, mug_b, mug_c], names=["a", "b", "c"], restarts=6)
    >>> for cloud, eye in views:
    ...     results = reg.register(cloud, viewpoint=eye)        # all models
    ...     best = reg.register(cloud, viewpoint=eye, models=["b"])[0]

    Args:
        models: meshes or surface samples (see :func:`model_samples`).
        options: a :class:`RegistrationOptions` (fixed for the registrar's life).
        names: a name per model (else the index), used in the results and by ``models=`` of
            :meth:`register`.
        model_seed: seeds the surface sampling of the meshes (model i: model_seed + i).
        keywords: option fields by keyword (see :func:`registration_options`), applied over ``options``;
            ``seed`` and ``viewpoint`` are given per call, to :meth:`register`.
    """

    def __init__(self, models: Sequence, options: Optional[RegistrationOptions] = None, *,
                 names: Optional[Sequence] = None, model_seed: int = 0, **keywords):
        for k in ("seed", "viewpoint"):
            if k in keywords:
                raise ValueError(f"{k}: is given per call, to Registrar.register")
        options = registration_options(options, **keywords)
        models = list(models)
        if not models:
            raise ValueError("models: is empty")
        self.names = _model_names(names, len(models))
        self._core = _v.Registrar(options)
        self._core.add_models(_model_clouds(models, options, model_seed))

    def __len__(self) -> int:
        return len(self._core)

    @property
    def options(self) -> RegistrationOptions:
        """A copy of the registrar's options."""
        return self._core.options

    @property
    def voxel(self) -> float:
        return self._core.options.voxel

    def preparation_time(self, i: int) -> float:
        """Seconds spent preparing model ``i`` (radius grid, downsampling, normals, FPFH)."""
        return float(self._core.model_info(c_int(i, "i")).time)

    def _indices(self, models) -> Optional[List[int]]:
        if models is None:
            return None
        if isinstance(models, (str, int, np.integer)):
            models = [models]
        out = []
        for m in models:
            if m in self.names:  # a name (the first model of that name)
                out.append(self.names.index(m))
            elif isinstance(m, (int, np.integer)) and not isinstance(m, bool) and 0 <= int(m) < len(self.names):
                out.append(int(m))
            else:
                raise ValueError(f"models: unknown model {m!r} (names: {self.names})")
        if not out:
            raise ValueError("models: is empty")
        return out

    def register(self, cloud, seed: int = 0, viewpoint=None, models=None) -> List[RegistrationResult]:
        """Registers a partial cloud against the prepared models (``models``: names or indices,
        None for all), in parallel. ``seed``: RANSAC seed; ``viewpoint``: the camera centre in the
        cloud's frame. Returns one :class:`RegistrationResult` per model asked for, with weights
        normalised over those; ``time_features`` is the cloud's feature time only."""
        P = as_cloud(cloud)
        idx = self._indices(models)
        raw = self._core.register(P, seed=c_seed(seed, "seed"), viewpoint=_viewpoint(viewpoint), models=idx)
        return _results(raw, self.names if idx is None else [self.names[i] for i in idx])


def register(cloud, models: Sequence, options: Optional[RegistrationOptions] = None, *, seed: int = 0,
             viewpoint=None, model_seed: int = 0, names: Optional[Sequence] = None,
             **keywords) -> List[RegistrationResult]:
    """Registers a partial cloud against every model in one parallel call (one shot; to register
    many clouds against the same models, make one :class:`Registrar`).

    Args:
        cloud: (N, 3) / organised (H, W, 3) array or Open3D cloud; NaN rows are dropped.
        models: meshes or surface samples (see :func:`model_samples`).
        options: a :class:`RegistrationOptions`; every radius and threshold scales from its voxel (m).
        seed: RANSAC seed (same seed, same result); ``model_seed`` seeds the surface sampling.
        viewpoint: the camera centre in the cloud's frame (scene normals point towards it); without
            it they point away from the cloud's centroid.
        names: a name per model (else the index), in the results.
        keywords: fields of the options or of one of its steps, applied over ``options`` (see
            :func:`registration_options`): voxel, restarts, upright, up_prior=False, estimator (PCL's
            normal and FPFH estimators, FeatureEstimator.Pcl: same definitions, slower), ...

    Returns one :class:`RegistrationResult` per model, in order (``time_features`` includes the
    model's preparation). A model with no surface, or a cloud with too few points for the features,
    gives ``success=False`` with a ``status`` and a ``reason`` (the transform is then the identity).
    ValueError for an empty or all-NaN cloud, no models, or bad options.
    """
    options = registration_options(options, **keywords)
    models = list(models)
    names = _model_names(names, len(models))
    P = as_cloud(cloud)
    raw = _v.register_models(P, _model_clouds(models, options, model_seed), options, seed=c_seed(seed, "seed"),
                             viewpoint=_viewpoint(viewpoint))
    return _results(raw, names)


def rotation_error(Ra, Rb, axis=None) -> float:
    """Angle (rad) between two rotations; with ``axis`` (model frame), rotation about it is ignored."""
    ax = None if axis is None else np.asarray(axis, float)
    return float(_v.rotation_error(np.asarray(Ra, float), np.asarray(Rb, float), ax))
