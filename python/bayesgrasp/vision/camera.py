"""The simulated depth camera and table-top segmentation (C++: ``_core.vision``)."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Optional, Sequence, Tuple, Union

import numpy as np

from bayesgrasp import _core
from bayesgrasp._args import c_int, with_fields

from .inputs import as_cloud, as_mesh

_v = _core.vision

Intrinsics = _v.Intrinsics
Table = _v.Table
NoiseModel = _v.NoiseModel
SegmentationOptions = _v.SegmentationOptions
SegmentationResult = _v.SegmentationResult


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
        nm = with_fields(NoiseModel, noise if isinstance(noise, NoiseModel) else NoiseModel(enabled=bool(noise)),
                         {**noise_fields, "seed": seed})
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
