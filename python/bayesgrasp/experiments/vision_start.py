"""The planning loop's start from vision (Fig. 3.4's "initial uncertain guess from vision"): the
known object's mesh registered to a camera's cloud gives the pose estimate, and the fit sets the
initial belief's spread.

Spread (uniform half-widths of the initial belief): position ``clip(POSITION_GAIN * delta,
0.01, 0.04)`` m with ``delta`` the registration's fitting error (truncated RMS distance, see
:mod:`bayesgrasp.vision`), and yaw that position spread over the object's radius, clipped to
10..45 degrees. A perfect fit still keeps 1 cm and 10 degrees (the sensor's own error); the
upper bounds are the thesis's default belief (+-4 cm, +-45 degrees).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

import numpy as np

from ..vision import RegistrationResult, register

POSITION_GAIN = 5.0
POSITION_RANGE = (0.01, 0.04)
YAW_RANGE = (np.radians(10.0), np.radians(45.0))


@dataclass
class VisionStart:
    """estimate: (x, y, yaw) of the object in the table frame; half_width: the initial belief's
    (m, m, rad); registration: the fit they come from."""

    estimate: np.ndarray
    half_width: np.ndarray
    registration: RegistrationResult


def vision_start(obj, cloud, viewpoint: Optional[np.ndarray] = None, seed: int = 0,
                 voxel: float = 0.005) -> VisionStart:
    """Registers ``obj`` (an ObjectModel) to ``cloud`` (table frame); ValueError if it does not register."""
    r = register(cloud, [obj], voxel=voxel, seed=seed, viewpoint=viewpoint, names=[obj.name])[0]
    if not r.success:
        raise ValueError(f"the object's mesh did not register to the cloud: {r.reason}")
    T = np.asarray(r.transform, float)
    estimate = np.array([T[0, 3], T[1, 3], np.arctan2(T[1, 0], T[0, 0])])
    position = float(np.clip(POSITION_GAIN * r.delta, *POSITION_RANGE))
    yaw = float(np.clip(position / max(obj.max_radius_from_com, 1e-3), *YAW_RANGE))
    return VisionStart(estimate, np.array([position, position, yaw]), r)
