"""A camera's cloud to the object in the table frame (z up, table top at z = 0), through Open3D:
the table plane by RANSAC on a sample of the points (or a given camera-to-table extrinsic), the
points above the table over its extent, voxel down-sampling of those, the largest Euclidean
(DBSCAN) cluster, statistical outlier removal, the units guard, and normals oriented towards the
camera. (Down-sampling the whole cloud first would spend most of the time on the table.)

>>> from bayesgrasp.io import to_table_frame
>>> view = to_table_frame(cloud_in_camera_frame)          # finds the table
>>> view = to_table_frame(cloud, extrinsic=T_table_camera)
>>> view.object_points, view.transform, view.viewpoint
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

import numpy as np

from .camera_data import read_extrinsic
from .clouds import as_points, to_open3d
from .units import SCENE_EXTENT_MAX, check_extent


@dataclass(frozen=True)
class TableFrameOptions:
    """voxel: the object's down-sampling voxel (m; 0: none); plane_threshold: RANSAC inlier
    distance (m); plane_iterations; plane_samples: the RANSAC runs on at most this many points
    drawn from the cloud; min_plane_fraction: the table must hold this share of them;
    min_height, max_height: the object's points lie this far above the table (m); margin: the
    object must stand within the table's points' footprint grown by this (m); cluster_tolerance:
    DBSCAN's eps (m); min_cluster_points; outlier_neighbours, outlier_std: statistical outlier
    removal (0 neighbours: none); normal_radius (m); seed: the RANSAC's."""

    voxel: float = 0.003
    plane_threshold: float = 0.006
    plane_iterations: int = 500
    plane_samples: int = 20000
    min_plane_fraction: float = 0.1
    min_height: float = 0.008
    max_height: float = 1.0
    margin: float = 0.05
    cluster_tolerance: float = 0.012
    min_cluster_points: int = 30
    outlier_neighbours: int = 20
    outlier_std: float = 2.5
    normal_radius: float = 0.01
    seed: int = 0

    def __post_init__(self):
        for k in ("voxel", "margin"):
            v = getattr(self, k)
            if not (np.isfinite(v) and v >= 0):
                raise ValueError(f"{k}: must be >= 0, got {v}")
        for k in ("plane_threshold", "cluster_tolerance", "normal_radius", "outlier_std", "max_height"):
            v = getattr(self, k)
            if not (np.isfinite(v) and v > 0):
                raise ValueError(f"{k}: must be positive, got {v}")
        if not (np.isfinite(self.min_height) and 0 <= self.min_height < self.max_height):
            raise ValueError(f"min_height: must be in [0, max_height), got {self.min_height}")
        if not 0 < self.min_plane_fraction <= 1:
            raise ValueError(f"min_plane_fraction: must be in (0, 1], got {self.min_plane_fraction}")
        for k, lo in (("plane_iterations", 1), ("plane_samples", 3), ("min_cluster_points", 1), ("outlier_neighbours", 0), ("seed", 0)):
            v = getattr(self, k)
            if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or not lo <= v < 2**31:
                raise ValueError(f"{k}: must be an integer in [{lo}, 2^31), got {v!r}")


@dataclass
class TableView:
    """object_points, object_normals: (N, 3) in the table frame; transform: input frame -> table
    frame (4x4); plane: the table plane (a, b, c, d) in the input frame, unit normal towards the
    camera; viewpoint: the camera centre in the table frame (None when unknown); table_points:
    the number of table inliers; dropped: input points with NaN or infinite coordinates."""

    object_points: np.ndarray
    object_normals: np.ndarray
    transform: np.ndarray
    plane: np.ndarray
    viewpoint: Optional[np.ndarray]
    table_points: int
    dropped: int = 0


def to_table_frame(cloud, extrinsic=None, *, frame: str = "camera", viewpoint=None, units: Optional[str] = None,
                   options: Optional[TableFrameOptions] = None, **keywords) -> TableView:
    """The object's cloud in the table frame, from a camera's cloud.

    Args:
        cloud: (N, 3) / (H, W, 3) array, Open3D (legacy or tensor) or trimesh cloud; not modified.
        extrinsic: the camera's pose in the table frame (4x4, camera -> table); when given, the
            table is z = 0 of that frame and no plane is searched for.
        frame: ``"camera"`` (the camera at the origin; default) or ``"table"`` (the cloud is already
            in the table frame: only the object is cut out).
        viewpoint: the camera centre in the table frame, for ``frame="table"``.
        units: the cloud's unit (m, cm, mm).
        options, keywords: :class:`TableFrameOptions` and its fields as keywords.

    ValueError, naming the cause, for an empty or all-NaN cloud, no table plane, nothing above the
    table, an extrinsic that is not rigid, or an object whose size says it is in another unit.
    """
    if frame not in ("camera", "table"):
        raise ValueError(f"frame: expected 'camera' or 'table', got {frame!r}")
    if frame == "table" and extrinsic is not None:
        raise ValueError("extrinsic: a cloud already in the table frame takes none")
    opts = options or TableFrameOptions()
    if keywords:
        from dataclasses import replace

        unknown = set(keywords) - set(TableFrameOptions.__dataclass_fields__)
        if unknown:
            raise ValueError(f"{sorted(unknown)[0]}: unknown option (known: "
                             f"{', '.join(TableFrameOptions.__dataclass_fields__)})")
        opts = replace(opts, **keywords)
    T_given = None if extrinsic is None else read_extrinsic(extrinsic)
    vp = None if viewpoint is None else _point(viewpoint, "viewpoint")
    n_in = _count(cloud)
    P = as_points(cloud, units=units)
    check_extent(P, "cloud", units, lo=0.0, hi=SCENE_EXTENT_MAX)
    if T_given is not None:
        T, plane = T_given, _plane_of(T_given)
    elif frame == "table":
        T, plane = np.eye(4), np.array([0.0, 0.0, 1.0, 0.0])
    else:
        plane = fit_table_plane(P, opts)
        T = frame_from_plane(plane)
    Q = P @ T[:3, :3].T + T[:3, 3]
    if frame == "camera":
        vp = T[:3, 3].copy()
    on_table = np.abs(Q[:, 2]) <= opts.plane_threshold
    try:
        obj = downsample(to_open3d(Q[above_table(Q, on_table, opts)]), opts.voxel)
        obj = remove_outliers(largest_cluster(obj, opts), opts)
    except ValueError as e:
        raise ValueError(f"{e}{_table_frame_hint(frame, plane)}") from None
    O = np.asarray(obj.points)
    check_extent(O, "the object's cloud", units)
    if T_given is None and frame == "camera":            # origin under the object's centre
        shift = np.eye(4)
        shift[:2, 3] = -O[:, :2].mean(axis=0)
        T, O, vp = shift @ T, O + shift[:3, 3], vp + shift[:3, 3]
        obj.translate(shift[:3, 3])
    N = normals(obj, opts, vp)
    return TableView(object_points=O.copy(), object_normals=N, transform=T, plane=plane, viewpoint=vp,
                     table_points=int(on_table.sum()), dropped=n_in - len(P))


# ---- the steps ---------------------------------------------------------------------------------------------
def downsample(pcd, voxel: float):
    """Open3D's voxel grid filter (``voxel`` 0: the cloud as it is)."""
    return pcd.voxel_down_sample(voxel) if voxel > 0 else pcd


def fit_table_plane(P: np.ndarray, opts: TableFrameOptions) -> np.ndarray:
    """The dominant plane (Open3D's RANSAC, seeded) of at most ``plane_samples`` points drawn
    from ``P`` (seeded), unit normal towards the camera at the origin."""
    import open3d as o3d

    n = len(P)
    if n < 3:
        raise ValueError(f"cloud: {n} points, too few for a table plane")
    rng = np.random.default_rng(opts.seed)
    sample = P if n <= opts.plane_samples else P[rng.choice(n, opts.plane_samples, replace=False)]
    o3d.utility.random.seed(int(opts.seed))
    plane, inliers = to_open3d(sample).segment_plane(distance_threshold=opts.plane_threshold, ransac_n=3,
                                                     num_iterations=int(opts.plane_iterations))
    plane = np.asarray(plane, dtype=np.float64)
    plane /= np.linalg.norm(plane[:3])
    if len(inliers) < max(3, opts.min_plane_fraction * len(sample)):
        raise ValueError(f"no table plane found: the best plane holds {len(inliers) / len(sample):.0%} of the points "
                         f"(needs {opts.min_plane_fraction:.0%}); pass the camera-to-table extrinsic instead")
    return plane if plane[3] > 0 else -plane          # the camera (origin) on the normal's side


def frame_from_plane(plane: np.ndarray) -> np.ndarray:
    """Camera -> table: z the plane's normal, the origin the camera's foot on the plane, x the
    camera's viewing direction projected on the table (its image-up direction when it looks down)."""
    n, d = plane[:3], plane[3]
    x = np.array([0.0, 0.0, 1.0]) - n[2] * n
    if np.linalg.norm(x) < 0.1:
        x = np.array([0.0, -1.0, 0.0]) + n[1] * n
    x /= np.linalg.norm(x)
    R = np.stack([x, np.cross(n, x), n])              # rows: the table axes in camera coordinates
    T = np.eye(4)
    T[:3, :3] = R
    T[:3, 3] = -R @ (-d * n)                          # the camera's foot -d n goes to the origin
    return T


def _plane_of(T: np.ndarray) -> np.ndarray:
    """The plane z = 0 of the table frame, in the camera frame, normal towards the camera."""
    n = T[2, :3]                                       # table z in camera coordinates
    plane = np.append(n, T[2, 3])                      # n . p + t_z = 0 <=> table z = 0
    return plane if plane[3] > 0 else -plane


def above_table(Q: np.ndarray, on_table: np.ndarray, opts: TableFrameOptions) -> np.ndarray:
    """Indices of the points min..max height above the table, within its footprint (+ margin)."""
    x, y, z = Q[:, 0], Q[:, 1], Q[:, 2]
    keep = (z >= opts.min_height) & (z <= opts.max_height)
    if on_table.sum() >= 3:
        tx, ty = x[on_table], y[on_table]
        m = opts.margin
        keep &= (x >= tx.min() - m) & (x <= tx.max() + m) & (y >= ty.min() - m) & (y <= ty.max() + m)
    idx = np.flatnonzero(keep)
    if len(idx) == 0:
        raise ValueError(f"nothing above the table: no point {opts.min_height * 1000:g} mm to "
                         f"{opts.max_height:g} m above it")
    return idx


#: a camera this close to the table plane it found (m) cannot have seen the object from above
CAMERA_ON_TABLE = 0.02


def _table_frame_hint(frame: str, plane: np.ndarray) -> str:
    """The hint for a cloud read in the camera frame whose origin lies on the table plane found:
    it is most likely in the table frame already."""
    if frame != "camera" or abs(float(plane[3])) > CAMERA_ON_TABLE:
        return ""
    return (f"; the cloud's origin, taken as the camera, lies on the table plane ({abs(float(plane[3])) * 1000:.0f} mm "
            f"from it): if the cloud is already in the table frame, pass --cloud-frame table (frame='table')")


def largest_cluster(pcd, opts: TableFrameOptions):
    """The largest DBSCAN cluster (Open3D's ``cluster_dbscan``) of the points above the table."""
    labels = np.asarray(pcd.cluster_dbscan(eps=opts.cluster_tolerance, min_points=4, print_progress=False))
    counts = np.bincount(labels[labels >= 0]) if np.any(labels >= 0) else np.zeros(0, int)
    if len(counts) == 0 or counts.max() < opts.min_cluster_points:
        raise ValueError(f"nothing above the table: no cluster of {opts.min_cluster_points} points "
                         f"(the largest has {int(counts.max()) if len(counts) else 0})")
    return pcd.select_by_index(np.flatnonzero(labels == int(np.argmax(counts))).tolist())


def remove_outliers(pcd, opts: TableFrameOptions):
    """Open3D's statistical outlier removal (kept as is when too few points for it)."""
    k = int(opts.outlier_neighbours)
    if k == 0 or len(pcd.points) <= k:
        return pcd
    kept, _ = pcd.remove_statistical_outlier(nb_neighbors=k, std_ratio=float(opts.outlier_std))
    return kept


def normals(pcd, opts: TableFrameOptions, viewpoint: Optional[np.ndarray]) -> np.ndarray:
    """Open3D's normals (hybrid radius / 30 neighbours), oriented towards the camera when known."""
    import open3d as o3d

    pcd.estimate_normals(o3d.geometry.KDTreeSearchParamHybrid(radius=opts.normal_radius, max_nn=30))
    if viewpoint is not None:
        pcd.orient_normals_towards_camera_location(np.asarray(viewpoint, float))
    return np.asarray(pcd.normals).copy()


def _point(v, name: str) -> np.ndarray:
    a = np.asarray(v, dtype=np.float64).ravel()
    if a.shape != (3,) or not np.all(np.isfinite(a)):
        raise ValueError(f"{name}: expected three finite numbers, got {v!r}")
    return a


def _count(cloud) -> int:
    try:
        from .clouds import _raw_points

        a = np.asarray(_raw_points(cloud, "cloud"))
        return int(a.size // 3) if a.ndim >= 2 and a.shape[-1] == 3 else 0
    except ValueError:
        return 0
