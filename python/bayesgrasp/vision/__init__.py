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

import numpy as np

from bayesgrasp import _core

from .camera import Camera, Intrinsics, NoiseModel, SegmentationOptions, SegmentationResult, Table, segment_table
from .inputs import as_cloud, as_mesh
from .deform import CpdOptions, MeshWarp, coherent_point_drift, warp_mesh
from .registration import (FeatureEstimator, RegistrationOptions, RegistrationResult, RegistrationStatus,
                           RegistrationWarning, Registrar, model_samples, register, registration_options)

__all__ = [
    "Camera", "SegmentationResult", "RegistrationResult", "RegistrationWarning", "Registrar", "segment_table", "register",
    "model_samples", "rotation_error", "as_cloud", "as_mesh", "registration_options",
    "RegistrationOptions", "FeatureOptions", "CorrespondenceOptions", "RansacOptions", "IcpOptions", "UpPrior",
    "FeatureEstimator", "RegistrationStatus", "Intrinsics", "Table", "NoiseModel", "SegmentationOptions",
    "CpdOptions", "MeshWarp", "coherent_point_drift", "warp_mesh",
]

_v = _core.vision

FeatureOptions = _v.FeatureOptions
CorrespondenceOptions = _v.CorrespondenceOptions
RansacOptions = _v.RansacOptions
IcpOptions = _v.IcpOptions
UpPrior = _v.UpPrior


def rotation_error(Ra, Rb, axis=None) -> float:
    """Angle (rad) between two rotations; with ``axis`` (model frame), rotation about it is ignored."""
    ax = None if axis is None else np.asarray(axis, float)
    return float(_v.rotation_error(np.asarray(Ra, float), np.asarray(Rb, float), ax))
