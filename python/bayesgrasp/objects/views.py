"""A simulated depth view of an object on the table, segmented: what the robot's camera gives
the category planner and the registration (thesis §4.2: one RGB-D snapshot, reduced to the
object's partial cloud by a planar-support heuristic)."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence, Union

import numpy as np

from ..vision import Camera, segment_table
from .library import load_object
from .mesh_io import ObjectModel

#: Default camera position relative to the object's centre (m): in front, to the side, above.
DEFAULT_EYE_OFFSET = (0.45, -0.45, 0.45)


@dataclass
class ObjectView:
    """The whole noisy cloud (world frame), the object's cluster after table segmentation, the
    camera, the object and its planar pose (x, y, yaw)."""

    cloud: np.ndarray
    object_points: np.ndarray
    camera: Camera
    object: ObjectModel
    pose: tuple


def capture_view(obj: Union[str, ObjectModel], pose: Sequence[float] = (0.0, 0.0, 0.0),
                 eye_offset: Sequence[float] = DEFAULT_EYE_OFFSET, seed: int = 0,
                 table_half_extent: float = 0.6) -> ObjectView:
    """Places ``obj`` on the table at ``pose`` = (x, y, yaw), renders one noisy depth view from the
    object's centre + ``eye_offset`` looking at the centre, and segments the table away.

    ValueError if the pose is not three finite numbers, the camera sees nothing or no object is
    found above the table."""
    p = np.asarray(pose, dtype=float).ravel()
    if p.shape != (3,) or not np.all(np.isfinite(p)):
        raise ValueError(f"pose: expected three finite numbers x, y, yaw, got {pose!r}")
    o = load_object(obj)
    x, y, yaw = (float(v) for v in p)
    c, s = np.cos(yaw), np.sin(yaw)
    V = o.vertices @ np.array([[c, -s, 0], [s, c, 0], [0, 0, 1.0]]).T + np.array([x, y, 0.0])
    centre = V.mean(axis=0)
    cam = Camera.looking_at(eye=centre + np.asarray(eye_offset, float), target=centre)
    cloud = cam.capture([(V, o.faces)], table={"z": 0.0, "center": (x, y),
                                                "half_extents": (table_half_extent, table_half_extent)}, seed=seed)
    if len(cloud) == 0:
        raise ValueError("the camera sees nothing: move the object or the camera")
    seg = segment_table(cloud)
    if not seg.clusters:
        raise ValueError("no object found above the table")
    return ObjectView(cloud=cloud, object_points=seg.cluster_points[0], camera=cam, object=o, pose=(x, y, yaw))
