"""A partial view of an object on the table, as a depth camera sees it, for the cgn peer.

    .venv/bin/python bench/peers/make_partial_cloud.py MESH OUT.npy [--pose x y yaw]
        [--eye 0.5 0 0.5] [--size 640 480] [--fov 45] [--table-half 0.15] [--no-table]

Visibility method: ray casting (Open3D `RaycastingScene`) of a pinhole camera at `--eye` looking at
the centre of the placed object's bounding box, `--size` pixels with a vertical field of view of
`--fov` degrees; every pixel's first hit is one point. The table is a square at z = 0 centred under
the object, 0.3 m a side (`--table-half 0.15`; left out with --no-table). Writes an (N, 3) float32 array in the table frame
(metres, z up); prints the point counts.
"""
import argparse

import numpy as np
import open3d as o3d


def placed_mesh(path, pose):
    mesh = o3d.io.read_triangle_mesh(path)
    if len(mesh.triangles) == 0:
        raise ValueError(f"mesh: no triangles read from {path}")
    x, y, yaw = pose
    tf = np.eye(4)
    tf[:2, :2] = [[np.cos(yaw), -np.sin(yaw)], [np.sin(yaw), np.cos(yaw)]]
    tf[:2, 3] = [x, y]
    return mesh.transform(tf)


def table_square(centre_xy, half):
    cx, cy = centre_xy
    verts = np.array([[cx - half, cy - half, 0], [cx + half, cy - half, 0],
                      [cx + half, cy + half, 0], [cx - half, cy + half, 0]], dtype=float)
    tris = np.array([[0, 1, 2], [0, 2, 3]])
    return o3d.geometry.TriangleMesh(o3d.utility.Vector3dVector(verts), o3d.utility.Vector3iVector(tris))


def render(mesh, eye, size, fov, table_half):
    scene = o3d.t.geometry.RaycastingScene()
    obj_id = scene.add_triangles(o3d.t.geometry.TriangleMesh.from_legacy(mesh))
    if table_half > 0:
        centre = mesh.get_axis_aligned_bounding_box().get_center()
        scene.add_triangles(o3d.t.geometry.TriangleMesh.from_legacy(table_square(centre[:2], table_half)))
    target = mesh.get_axis_aligned_bounding_box().get_center()
    rays = scene.create_rays_pinhole(fov_deg=fov, center=list(target), eye=list(eye), up=[0, 0, 1],
                                     width_px=size[0], height_px=size[1])
    hit = scene.cast_rays(rays)
    t = hit["t_hit"].numpy().reshape(-1)
    geom = hit["geometry_ids"].numpy().reshape(-1)
    r = rays.numpy().reshape(-1, 6)
    ok = np.isfinite(t)
    pts = r[ok, :3] + t[ok, None] * r[ok, 3:]
    return pts.astype(np.float32), int(np.count_nonzero(geom[ok] == obj_id))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("mesh")
    ap.add_argument("out")
    ap.add_argument("--pose", type=float, nargs=3, default=[0.0, 0.0, 0.0])
    ap.add_argument("--eye", type=float, nargs=3, default=[0.5, 0.0, 0.5])
    ap.add_argument("--size", type=int, nargs=2, default=[640, 480])
    ap.add_argument("--fov", type=float, default=45.0)
    ap.add_argument("--table-half", type=float, default=0.15, help="half side of the table square (m)")
    ap.add_argument("--no-table", action="store_true")
    a = ap.parse_args()
    pts, n_obj = render(placed_mesh(a.mesh, a.pose), a.eye, a.size, a.fov, 0.0 if a.no_table else a.table_half)
    np.save(a.out, pts)
    print(f"{a.out}: {len(pts)} points ({n_obj} on the object) seen from {a.eye}")


if __name__ == "__main__":
    main()
