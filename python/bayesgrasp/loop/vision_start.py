"""The planning loop's start from vision (Fig. 3.4's "initial uncertain guess from vision"): the
known object's mesh registered to a camera's cloud gives the pose estimate, and the fit sets the
initial belief's spread.

A registration can settle on a wrong yaw that fits almost as well (a mug seen with its handle
hidden or foreshortened), so the fit is also profiled over yaw: the registered model is turned
about the vertical through its centre in 5-degree steps and the fitting error ``delta`` (the
truncated RMS distance of :mod:`bayesgrasp.vision`, ``tau = 1.5 voxel``) is computed at each.
The estimate takes the best yaw of that profile; the yaw spread is the largest turn from it whose
``delta`` is within ``YAW_TOLERANCE`` (``delta <= 1.25 delta_best + 0.5 mm``), at least 10 degrees
and at most 180 (a view that cannot tell the yaw leaves it unknown). The position spread is
``clip(POSITION_GAIN * delta_best, 0.01, 0.04)`` m.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

import numpy as np

from ..vision import RegistrationResult, model_samples, register

POSITION_GAIN = 5.0
POSITION_RANGE = (0.01, 0.04)
YAW_STEP = np.radians(5.0)
YAW_MIN = np.radians(10.0)
YAW_TOLERANCE = (1.25, 0.0005)     # (relative, absolute m)


@dataclass
class VisionStart:
    """estimate: (x, y, yaw) of the object in the table frame; half_width: the initial belief's
    (m, m, rad); registration: the fit they come from; yaw_offsets, yaw_delta: the fit's profile
    over turns about the vertical from the registered yaw."""

    estimate: np.ndarray
    half_width: np.ndarray
    registration: RegistrationResult
    yaw_offsets: np.ndarray
    yaw_delta: np.ndarray


def yaw_profile(samples: np.ndarray, T: np.ndarray, c: np.ndarray, cloud: np.ndarray, offsets: np.ndarray,
                tau: float) -> np.ndarray:
    """delta of the model (surface ``samples``, model frame) placed by ``T`` turned by each offset
    about the vertical through ``c`` (its placed centre), against ``cloud`` (table frame)."""
    from scipy.spatial import cKDTree

    tree = cKDTree(samples)
    out = np.empty(len(offsets))
    for k, a in enumerate(offsets):
        Rz = np.array([[np.cos(a), -np.sin(a), 0.0], [np.sin(a), np.cos(a), 0.0], [0.0, 0.0, 1.0]])
        R = Rz @ T[:3, :3]
        t = Rz @ (T[:3, 3] - c) + c
        d, _ = tree.query((cloud - t) @ R, distance_upper_bound=tau)     # cloud in the model frame
        out[k] = np.sqrt(np.mean(np.minimum(d, tau) ** 2))
    return out


def vision_start(obj, cloud, viewpoint: Optional[np.ndarray] = None, seed: int = 0,
                 voxel: float = 0.005) -> VisionStart:
    """Registers ``obj`` (an ObjectModel) to ``cloud`` (table frame); ValueError if it does not register."""
    r = register(cloud, [obj], voxel=voxel, seed=seed, viewpoint=viewpoint, names=[obj.name])[0]
    if not r.success:
        raise ValueError(f"the object's mesh did not register to the cloud: {r.reason}")
    T = np.asarray(r.transform, float)
    samples, _ = model_samples(obj, voxel=voxel, seed=seed)
    offsets = np.arange(-np.pi, np.pi, YAW_STEP)
    c = T[:3, :3] @ samples.mean(axis=0) + T[:3, 3]
    delta = yaw_profile(samples, T, c, np.asarray(cloud, float), offsets, 1.5 * voxel)
    best = int(np.argmin(delta))
    plausible = delta <= YAW_TOLERANCE[0] * delta[best] + YAW_TOLERANCE[1]
    turn = np.abs((offsets - offsets[best] + np.pi) % (2 * np.pi) - np.pi)
    yaw_spread = float(np.clip(turn[plausible].max(), YAW_MIN, np.pi))
    a = offsets[best]
    Rz = np.array([[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]])
    xy = Rz @ (T[:2, 3] - c[:2]) + c[:2]                                  # the model origin after the turn
    yaw = float((np.arctan2(T[1, 0], T[0, 0]) + a + np.pi) % (2 * np.pi) - np.pi)
    position = float(np.clip(POSITION_GAIN * delta[best], *POSITION_RANGE))
    return VisionStart(np.array([xy[0], xy[1], yaw]), np.array([position, position, yaw_spread]), r, offsets, delta)
