"""Registration of a partial cloud against object models (C++: ``_core.vision``): its options,
results, the :class:`Registrar` (models prepared once) and :func:`register` (one shot)."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, List, Optional, Sequence, Tuple

import numpy as np

from bayesgrasp import _core
from bayesgrasp._args import c_int, c_seed, with_fields
from bayesgrasp.belief import shape_weights

from .inputs import as_cloud, as_mesh

_v = _core.vision

RegistrationOptions = _v.RegistrationOptions
FeatureEstimator = _v.FeatureEstimator
RegistrationStatus = _v.RegistrationStatus


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
        if step:   # a step's field; the whole is validated once, below (keyword order does not matter)
            sub = getattr(out, step)
            try:
                setattr(out, step, with_fields(type(sub), sub, {name: value}, validate=False))
            except (ValueError, TypeError) as e:   # a value that does not convert, named with its step
                raise type(e)(f"{step}.{e}") from None
        else:
            out = with_fields(RegistrationOptions, out, {name: value}, validate=False)
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


class RegistrationWarning(UserWarning):
    """Models registered, but none fits the cloud well: the shape weights still sum to 1 over them."""


#: the fitness (share of the cloud's points within the inlier distance) below which no model is
#: taken to fit: a right model placed right covers nearly all of a view (>= 0.9 on our views)
GOOD_FITNESS = 0.8


def _warn_if_no_fit(raw: Sequence, names: Sequence) -> None:
    import warnings

    ok = [(float(r.fitness), n) for r, n in zip(raw, names) if r.success]
    if ok and max(ok)[0] < GOOD_FITNESS:
        best, name = max(ok, key=lambda t: t[0])
        warnings.warn(f"no model fits the cloud well: the best fitness is {best:.2f} ({name}; a fit covers "
                      f">= {GOOD_FITNESS} of the points); the weights still sum to 1 over the {len(ok)} models "
                      f"that registered: is the object of the models' kind?", RegistrationWarning, stacklevel=3)


def _results(raw: Sequence, names: Sequence) -> List[RegistrationResult]:
    """Python results from the core's, with the shape weights over the models of the call
    (:class:`RegistrationWarning` when none fits well)."""
    weights = shape_weights([r.phi for r in raw], [r.success for r in raw])
    _warn_if_no_fit(raw, names)
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
                has_area = _core.geometry.surface_area(V, F) > 0
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
