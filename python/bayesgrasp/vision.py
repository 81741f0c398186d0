"""Seeing the object: a simulated RGB-D (depth) camera, table-top segmentation and registration of
a partial cloud against object models (thesis §4.2, Publication V).

The heavy lifting is in C++ (:mod:`bayesgrasp._core.vision`): a BVH ray caster with a
structured-light noise model, PCL's plane RANSAC and Euclidean clustering, and a registration
pipeline of voxel downsampling (PCL), normals and FPFH features, a seeded RANSAC over feature
correspondences, point-to-plane ICP, and a hypothesis choice that penalises upside-down fits.
To register many clouds against the same models, prepare the models once in a :class:`Registrar`.

>>> from bayesgrasp.vision import Camera, segment_table, register
>>> cam = Camera.looking_at(eye=(0.5, -0.5, 0.5), target=(0, 0, 0.05))
>>> cloud = cam.capture([(V, F)], table=True, seed=1)          # (N, 3) world frame, noisy
>>> seg = segment_table(cloud)                                 # clusters, largest first
>>> results = register(seg.cluster_points[0], [model_a, model_b], viewpoint=cam.eye)
>>> results[0].transform, results[0].fitness, results[0].weight
>>> reg = Registrar([model_a, model_b])                        # models prepared once
>>> results = reg.register(seg.cluster_points[0], viewpoint=cam.eye)

Conventions: metres; world frame z up with the table top at z = 0; camera frame x right, y down,
z forward; depth images hold the camera-frame z (NaN where nothing is measured).

Fitting error and weight (Eq. 4.1's phi(delta)): ``delta = sqrt(mean_i min(d_i, tau)^2)`` over
the downsampled scene points, ``d_i`` the distance to the registered model surface and
``tau = 1.5 voxel``; ``phi = exp(-delta^2 / (2 sigma^2))`` with ``sigma = 0.5 voxel`` (unnormalised);
``weight = phi / sum(phi)`` over the models of one call that registered successfully.

By default registration assumes the cloud is in the world frame (z up) and the models rest upright
on the table in their own frame (+z up, as the built-in objects do): hypotheses are searched over
yaw and translation, refined in 6 DOF by ICP, and upside-down fits are penalised. Pass
``up_prior=False`` for arbitrary orientations (6-DOF search, no penalty), or ``up=`` the table
normal in the cloud's frame.
"""
from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from typing import Any, List, Optional, Sequence, Tuple, Union

import numpy as np

__all__ = [
    "Camera", "SegmentationResult", "RegistrationResult", "Registrar", "segment_table", "register",
    "model_samples", "rotation_error", "register_command", "as_cloud", "as_mesh",
]


def _core():
    from bayesgrasp import _core

    return _core.vision


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
        pose = _core().look_at(np.asarray(eye, float), np.asarray(target, float), np.asarray(up, float))
        return cls(pose=np.asarray(pose), **intrinsics)

    @property
    def eye(self) -> np.ndarray:
        return self.pose[:3, 3].copy()

    @property
    def K(self) -> np.ndarray:
        return np.array([[self.fx, 0, self.cx], [0, self.fy, self.cy], [0, 0, 1.0]])

    def _intr(self) -> dict:
        return dict(fx=float(self.fx), fy=float(self.fy), cx=float(self.cx), cy=float(self.cy))

    def render(self, meshes: Sequence, table: Union[bool, dict] = False, noise: bool = True, seed: int = 0,
               **noise_params) -> Tuple[np.ndarray, np.ndarray]:
        """Ray-casts ``meshes`` (world frame; (V, F) tuples or mesh objects) and optionally the table
        (True: 1 x 1 m at z = 0 centred at the origin; or a dict with ``z``, ``center`` (x, y),
        ``half_extents`` (hx, hy), inf allowed). Returns (depth (H, W) in metres with NaN where
        nothing is measured, label (H, W): index of the mesh seen, -2 table, -1 nothing).
        ``noise_params``: sigma_a, sigma_b, baseline, disparity_step, max_incidence_deg, edge_jump,
        edge_drop_prob, min_depth, max_depth (see ``_core.vision.render``)."""
        ms = [as_mesh(m, f"meshes[{i}]") for i, m in enumerate(meshes)]
        tb = {} if table is True or table is False else dict(table)
        kw = dict(table=bool(table), table_z=float(tb.get("z", 0.0)),
                  table_center=np.asarray(tb.get("center", (0.0, 0.0)), float),
                  table_half_extents=np.asarray(tb.get("half_extents", (0.5, 0.5)), float))
        depth, label = _core().render(ms, self.pose, width=int(self.width), height=int(self.height), **self._intr(),
                                      noise=bool(noise), seed=int(seed), **kw, **noise_params)
        return np.asarray(depth), np.asarray(label)

    def points(self, depth: np.ndarray, world: bool = True, organised: bool = False) -> np.ndarray:
        """Back-projects a depth image: organised -> (H, W, 3) with NaN for missing pixels, else
        (N, 3) valid points; world or camera frame."""
        depth = np.asarray(depth, dtype=np.float64)
        if depth.shape != (self.height, self.width):
            raise ValueError(f"depth: expected shape ({self.height}, {self.width}), got {depth.shape}")
        P = np.asarray(_core().depth_to_points(depth, self.pose, **self._intr(), world=world, organised=organised))
        return P.reshape(self.height, self.width, 3) if organised else P

    def capture(self, meshes: Sequence, table: Union[bool, dict] = False, noise: bool = True, seed: int = 0,
                world: bool = True, organised: bool = False, **noise_params) -> np.ndarray:
        """render() then points(): the cloud the camera sees."""
        depth, _ = self.render(meshes, table=table, noise=noise, seed=seed, **noise_params)
        return self.points(depth, world=world, organised=organised)


# ---------------------------------------------------------------------------------------------
@dataclass
class SegmentationResult:
    plane: np.ndarray                 # (a, b, c, d): a x + b y + c z + d = 0, unit normal along `up`
    plane_inliers: np.ndarray         # row indices into the (flattened) input cloud
    clusters: List[np.ndarray]        # row indices per object, largest first
    cluster_points: List[np.ndarray]  # (n_i, 3) points per object


def segment_table(cloud, plane_threshold: float = 0.006, min_height: float = 0.008, max_height: float = 1.0,
                  cluster_tolerance: float = 0.01, min_cluster_size: int = 50, up=(0.0, 0.0, 1.0),
                  plane_iterations: int = 1000) -> SegmentationResult:
    """Table plane by RANSAC, the points ``min_height``..``max_height`` above it, Euclidean
    clusters of those (largest first). ``cloud``: (N, 3), organised (H, W, 3) or an Open3D cloud;
    NaN rows are ignored. ValueError if fewer than 3 finite points or no plane."""
    P = as_cloud(cloud)
    r = _core().segment_table(P, plane_threshold=plane_threshold, plane_iterations=plane_iterations,
                              min_height=min_height, max_height=max_height, cluster_tolerance=cluster_tolerance,
                              min_cluster_size=min_cluster_size, up=np.asarray(up, float))
    clusters = [np.asarray(c, dtype=np.int64) for c in r["clusters"]]
    return SegmentationResult(plane=np.asarray(r["plane"]), plane_inliers=np.asarray(r["plane_inliers"], np.int64),
                              clusters=clusters, cluster_points=[P[c] for c in clusters])


# ---------------------------------------------------------------------------------------------
@dataclass
class RegistrationResult:
    """One model's registration. ``transform`` maps model coordinates to the cloud's frame."""

    success: bool
    reason: str
    transform: np.ndarray
    fitness: float      # fraction of downsampled scene points within 1.5 voxel of the model
    rmse: float         # RMS distance of those inliers (m)
    delta: float        # fitting error (m), see the module docstring
    phi: float          # exp(-delta^2 / (2 sigma^2)), unnormalised
    weight: float       # phi normalised over the successful models of the call
    up_cos: float       # cos of the angle between the model's +z in the scene and `up`
    scene_points: int
    model_points: int
    time_features: float
    time_global: float
    time_icp: float
    model: Any = None   # the name or index of the model

    def as_dict(self) -> dict:
        return {"model": self.model, "success": self.success, "reason": self.reason,
                "transform": np.asarray(self.transform).tolist(), "fitness": self.fitness, "rmse": self.rmse,
                "delta": self.delta, "phi": self.phi, "weight": self.weight}


def model_samples(model, voxel: float = 0.005, seed: int = 0, samples: int = 0) -> Tuple[np.ndarray, np.ndarray]:
    """(points, outward normals) on a model's surface, for :func:`register`. ``model``: a mesh
    ((V, F) or an object with .vertices/.faces): sampled uniformly, area-weighted, seeded; an
    (N, 6) array of points and normals; a (points, normals) tuple of two (N, 3) arrays; or an
    Open3D cloud with normals. ValueError if it has no surface."""
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
                and len(A) == len(B) and not np.issubdtype(B.dtype, np.integer):
            return np.ascontiguousarray(A, float), np.ascontiguousarray(B, float)
    V, F = as_mesh(model, "model")
    P, N = _core().model_from_mesh(V, F, voxel=float(voxel), seed=int(seed), samples=int(samples))
    return np.asarray(P), np.asarray(N)


def _check_cloud(cloud) -> np.ndarray:
    P = as_cloud(cloud)
    if len(P) == 0:
        raise ValueError("cloud: is empty")
    if not np.isfinite(P).all(axis=1).any():
        raise ValueError("cloud: has no finite points")
    return P


def _result(r: dict, model, reason: Optional[str] = None, extra_feature_time: float = 0.0) -> RegistrationResult:
    return RegistrationResult(
        success=bool(r["success"]), reason=r["reason"] if reason is None else reason,
        transform=np.asarray(r["transform"]), fitness=float(r["fitness"]), rmse=float(r["rmse"]),
        delta=float(r["delta"]), phi=float(r["phi"]), weight=float(r["weight"]), up_cos=float(r["up_cos"]),
        scene_points=int(r["scene_points"]), model_points=int(r["model_points"]),
        time_features=float(r["time_features"]) + extra_feature_time, time_global=float(r["time_global"]),
        time_icp=float(r["time_icp"]), model=model)


class Registrar:
    """Object models prepared once, partial clouds registered against them many times.

    Preparing a model (downsampling, normals, FPFH features, k-d trees) does not depend on the
    cloud, so it is done here once per model; :meth:`register` does only the per-cloud work. With
    the same parameters, seed and viewpoint, ``Registrar(models).register(cloud)`` gives exactly the
    transforms, fits and weights of ``register(cloud, models)``.

    >>> reg = Registrar([mug_a, mug_b, mug_c], names=["a", "b", "c"])
    >>> for cloud, eye in views:
    ...     results = reg.register(cloud, viewpoint=eye)        # all models
    ...     best = reg.register(cloud, viewpoint=eye, models=["b"])[0]

    Args:
        models: meshes or surface samples (see :func:`model_samples`).
        voxel, up_prior, up, upright, model_seed, params: as for :func:`register` (fixed for the
            registrar's life; ``params`` without ``seed`` and ``viewpoint``, which are per call).
        names: a name per model (else the index), used in the results and by ``models=`` of
            :meth:`register`.
    """

    def __init__(self, models: Sequence, voxel: float = 0.005, up_prior: bool = True, up=(0.0, 0.0, 1.0),
                 upright: bool = True, model_seed: int = 0, names: Optional[Sequence] = None, **params):
        if not isinstance(voxel, (int, float)) or not (voxel > 0) or not math.isfinite(voxel):
            raise ValueError(f"voxel: must be positive and finite, got {voxel}")
        for k in ("seed", "viewpoint"):
            if k in params:
                raise ValueError(f"{k}: is given per call, to Registrar.register")
        models = list(models)
        if not models:
            raise ValueError("models: is empty")
        if names is not None:
            names = list(names)
            if len(names) != len(models):
                raise ValueError(f"names: expected {len(models)} names, got {len(names)}")
        self.names = names if names is not None else list(range(len(models)))
        samples, self._failed = [], {}
        for i, m in enumerate(models):
            try:
                samples.append(model_samples(m, voxel=voxel, seed=model_seed + i))
            except ValueError as e:
                if "no surface" not in str(e) and "no area" not in str(e):
                    raise ValueError(f"models[{i}]: {e}") from None
                self._failed[i] = f"model has no surface ({e})"
                samples.append((np.zeros((0, 3)), np.zeros((0, 3))))
        self.voxel = float(voxel)
        self._core = _core().Registrar(samples, voxel=float(voxel), up_prior=bool(up_prior), upright=bool(upright),
                                       up=np.asarray(up, float), **params)

    def __len__(self) -> int:
        return len(self._core)

    def preparation_time(self, i: int) -> float:
        """Seconds spent preparing model ``i`` (downsampling, normals, FPFH, k-d trees)."""
        return float(self._core.model_info(int(i))["time"])

    def _indices(self, models) -> List[int]:
        if models is None:
            return list(range(len(self.names)))
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
        P = _check_cloud(cloud)
        idx = self._indices(models)
        vp = None if viewpoint is None else np.asarray(viewpoint, float)
        raw = self._core.register(P, seed=int(seed), viewpoint=vp, models=idx)
        return [_result(r, self.names[i], self._failed.get(i)) for i, r in zip(idx, raw)]


def register(cloud, models: Sequence, voxel: float = 0.005, seed: int = 0, viewpoint=None, up_prior: bool = True,
             up=(0.0, 0.0, 1.0), upright: bool = True, model_seed: int = 0, names: Optional[Sequence] = None,
             **params) -> List[RegistrationResult]:
    """Registers a partial cloud against every model in one parallel call (a one-shot
    :class:`Registrar`; to register many clouds against the same models, make one Registrar).

    Args:
        cloud: (N, 3) / organised (H, W, 3) array or Open3D cloud; NaN rows are dropped.
        models: meshes or surface samples (see :func:`model_samples`).
        voxel: the one size every radius and threshold scales from (m).
        seed: RANSAC seed (same seed, same result); ``model_seed`` seeds the surface sampling.
        viewpoint: the camera centre in the cloud's frame (scene normals point towards it); without
            it they point away from the cloud's centroid.
        up_prior, up, upright: see the module docstring.
        params: restarts, ransac_iterations, hypotheses, icp_iterations, feature_neighbours,
            normal_radius, feature_radius, inlier_distance, icp_distance (multiples of voxel),
            weight_sigma (x voxel), max_tilt_deg, min_scene_points, threads, pcl_features (PCL's
            normal and FPFH estimators instead of ours: same definitions, slower).

    Returns one :class:`RegistrationResult` per model, in order (``time_features`` includes the
    model's preparation). A model with no surface, or a cloud with too few points for the features,
    gives ``success=False`` with a ``reason`` (the transform is then the identity). ValueError for an
    empty or all-NaN cloud, no models, or bad parameters.
    """
    P = _check_cloud(cloud)
    reg = Registrar(models, voxel=voxel, up_prior=up_prior, up=up, upright=upright, model_seed=model_seed,
                    names=names, **params)
    res = reg.register(P, seed=seed, viewpoint=viewpoint)
    for i, r in enumerate(res):
        r.time_features += reg.preparation_time(i)
    return res


def rotation_error(Ra, Rb, axis=None) -> float:
    """Angle (rad) between two rotations; with ``axis`` (model frame), rotation about it is ignored."""
    ax = None if axis is None else np.asarray(axis, float)
    return float(_core().rotation_error(np.asarray(Ra, float), np.asarray(Rb, float), ax))


# ---------------------------------------------------------------------------------------------
def _load(name_or_path):
    from bayesgrasp.objects import load_object

    return load_object(name_or_path)


def register_command(scene_object, pose, models, json_out: bool = False, png: Optional[str] = None,
                     voxel: float = 0.005, seed: int = 0, eye=(0.45, -0.45, 0.45), print_fn=print) -> dict:
    """``bayesgrasp register``: places ``scene_object`` (built-in name or mesh path) on the table at
    ``pose`` = (x, y, yaw) (or "X,Y,YAW"), renders one noisy view from ``eye`` (relative to the
    object, looking at it), segments the table, registers the largest cluster against each of
    ``models`` and prints transform, fitness, RMSE and weight per model (``json_out``: one JSON
    document ``{"models": [{"model", "transform", "fitness", "rmse", "weight"}, ...]}``).
    Writes a PNG of the partial cloud over each registered model to ``png`` if given. Returns the
    JSON-able dict (with extra keys ``success``, ``reason``, ``delta``, ``phi``)."""
    if isinstance(pose, str):
        try:
            pose = [float(v) for v in pose.split(",")]
        except ValueError:
            raise ValueError(f"pose: expected X,Y,YAW, got {pose!r}") from None
    pose = [float(v) for v in pose]
    if len(pose) != 3 or not all(math.isfinite(v) for v in pose):
        raise ValueError(f"pose: expected three finite numbers X,Y,YAW, got {pose}")
    if isinstance(models, str):
        models = [models]
    if not models:
        raise ValueError("models: give at least one model")
    obj = _load(scene_object)
    x, y, yaw = pose
    c, s = math.cos(yaw), math.sin(yaw)
    T = np.array([[c, -s, 0, x], [s, c, 0, y], [0, 0, 1, 0], [0, 0, 0, 1.0]])
    V = obj.vertices @ T[:3, :3].T + T[:3, 3]
    centre = V.mean(axis=0)
    cam = Camera.looking_at(eye=centre + np.asarray(eye, float), target=centre)
    cloud = cam.capture([(V, obj.faces)], table={"z": 0.0, "center": (x, y), "half_extents": (0.6, 0.6)},
                        seed=seed)
    if len(cloud) == 0:
        raise ValueError("the camera sees nothing: move the object or the camera")
    seg = segment_table(cloud)
    if not seg.clusters:
        raise ValueError("no object found above the table")
    part = seg.cluster_points[0]
    model_objs = [_load(m) for m in models]
    names = [str(m) for m in models]
    res = register(part, model_objs, voxel=voxel, seed=seed, viewpoint=cam.eye, names=names)
    doc = {"scene_object": str(scene_object), "pose": pose, "scene_points": int(len(part)),
           "models": [r.as_dict() for r in res]}
    if json_out:
        print_fn(json.dumps(doc, indent=2))
    else:
        print_fn(f"scene object {scene_object} at x={x:.3f} y={y:.3f} yaw={yaw:.3f}: "
                 f"{len(part)} points in the largest cluster")
        for r in res:
            if not r.success:
                print_fn(f"  {r.model}: registration failed: {r.reason}")
                continue
            print_fn(f"  {r.model}: fitness {r.fitness:.3f}  rmse {r.rmse * 1000:.2f} mm  "
                     f"delta {r.delta * 1000:.2f} mm  weight {r.weight:.3f}")
            for row in r.transform:
                print_fn("      [" + " ".join(f"{v: .4f}" for v in row) + "]")
    if png:
        plot_registrations(part, model_objs, res, png)
    return doc


def plot_registrations(cloud: np.ndarray, models: Sequence, results: Sequence[RegistrationResult], path: str,
                       max_points: int = 4000) -> None:
    """A PNG with one 3-D panel per model: the model's surface samples (grey) moved by the
    registration, and the partial cloud (red) over them."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    n = len(results)
    cols = min(n, 3)
    rows = (n + cols - 1) // cols
    fig = plt.figure(figsize=(4.2 * cols, 4.2 * rows))
    rng = np.random.default_rng(0)
    C = np.asarray(cloud)[np.isfinite(cloud).all(axis=1)]
    if len(C) > max_points:
        C = C[rng.choice(len(C), max_points, replace=False)]
    for k, (m, r) in enumerate(zip(models, results)):
        ax = fig.add_subplot(rows, cols, k + 1, projection="3d")
        P, _ = model_samples(m, samples=3000)
        P = P @ r.transform[:3, :3].T + r.transform[:3, 3]
        ax.scatter(P[:, 0], P[:, 1], P[:, 2], s=1, c="0.6", alpha=0.5)
        ax.scatter(C[:, 0], C[:, 1], C[:, 2], s=1, c="tab:red")
        title = f"{r.model}\n" + (f"fit {r.fitness:.2f}  rmse {r.rmse * 1e3:.1f} mm  w {r.weight:.2f}"
                                  if r.success else f"failed: {r.reason[:40]}")
        ax.set_title(title, fontsize=9)
        allp = np.vstack([P, C])
        mid, half = allp.mean(axis=0), (allp.max(axis=0) - allp.min(axis=0)).max() / 2
        ax.set_xlim(mid[0] - half, mid[0] + half)
        ax.set_ylim(mid[1] - half, mid[1] + half)
        ax.set_zlim(mid[2] - half, mid[2] + half)
        ax.set_xlabel("x")
        ax.set_ylabel("y")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
