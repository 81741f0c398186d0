"""A URDF as the hand conversion (the package :mod:`bayesgrasp.hand_urdf`) reads it: poses from URDF origins,
the tree of links and joints, and the links' collision shapes (boxes, capsules, convex hulls) in
the hand file's form."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

_TOL = 1e-6           # geometric checks (m, or cosine of an angle)
# Directions (cosines of angles) a URDF writes with rounded numbers: an axis within 1e-4 rad of the
# palm plane or of another axis is taken as in it or parallel to it, and used projected (1.5708
# written for pi/2 tilts an axis by 3.7e-6 rad; 1e-4 rad moves a point 5 cm away by 5 micrometres).
_AXIS_TOL = 1e-4
_PRISM_SIDES = 32     # a lone cylinder's convex prism


class HandFileError(ValueError):
    """A URDF or sidecar the conversion cannot take (the message names the file and what)."""


# ---------------------------------------------------------------- small geometry ----

def _rpy(rpy) -> np.ndarray:
    r, p, y = (float(v) for v in rpy)
    cr, sr, cp, sp, cy, sy = math.cos(r), math.sin(r), math.cos(p), math.sin(p), math.cos(y), math.sin(y)
    return np.array([[cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
                     [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
                     [-sp, cp * sr, cp * cr]])


def _pose(R: np.ndarray, t) -> np.ndarray:
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = R, np.asarray(t, dtype=float)
    return T


def _origin(x) -> np.ndarray:
    return np.eye(4) if x is None else np.asarray(x, dtype=float)


def _unit(v) -> np.ndarray:
    v = np.asarray(v, dtype=float)
    return v / np.linalg.norm(v)


# ---------------------------------------------------------------- the URDF's tree ----

class _Tree:
    """The URDF's links and joints at the zero configuration, in the hand (palm) frame."""

    def __init__(self, robot, where: str):
        self.where = where
        self.held: dict[str, float] = {}   # joints held at a value (the sidecar's held_joints): fixed there
        self.links = {l.name: l for l in robot.links}
        self.joints = {j.name: j for j in robot.joints}
        self.parent_joint: dict[str, object] = {}
        for j in robot.joints:
            for end in (j.parent, j.child):
                if end not in self.links:
                    raise HandFileError(f"{where}: joint '{j.name}' names a link '{end}' that the URDF does not have")
            if j.child in self.parent_joint:
                raise HandFileError(f"{where}: kinematic loop: link '{j.child}' is the child of two joints "
                                    f"('{self.parent_joint[j.child].name}' and '{j.name}')")
            self.parent_joint[j.child] = j
        for name in self.links:  # a cycle without a double parent (every link on it has one parent)
            seen, n = {name}, name
            while n in self.parent_joint:
                n = self.parent_joint[n].parent
                if n in seen:
                    raise HandFileError(f"{where}: kinematic loop through link '{n}'")
                seen.add(n)

    def below(self, root: str, what: str = "root") -> "_Tree":
        """Only link ``root`` and the links under it, with the joints between them: a hand read out
        of a larger URDF (an arm, a simulator's drive joints above the palm). Poses are then
        relative to ``root``."""
        if root not in self.links:
            raise HandFileError(f"{self.where}: {what} names link '{root}', which the URDF does not have")
        keep = {root}
        grew = True
        while grew:
            grew = False
            for j in self.joints.values():
                if j.parent in keep and j.child not in keep:
                    keep.add(j.child)
                    grew = True
        self.links = {n: l for n, l in self.links.items() if n in keep}
        self.joints = {n: j for n, j in self.joints.items() if j.parent in keep and j.child in keep}
        self.parent_joint = {c: j for c, j in self.parent_joint.items() if c in keep and c != root}
        return self

    def joint(self, name: str, what: str):
        if name not in self.joints:
            raise HandFileError(f"{self.where}: {what} names joint '{name}', which the URDF does not have")
        return self.joints[name]

    def chain(self, link: str) -> list:
        """Joints from the root down to `link` (root first)."""
        out = []
        while link in self.parent_joint:
            j = self.parent_joint[link]
            out.append(j)
            link = j.parent
        return out[::-1]

    def hold(self, values: dict, what: str) -> None:
        """Holds each named revolute or prismatic joint at its value (rad or m; within its limits):
        from then on it is a fixed joint there."""
        for name, v in values.items():
            j = self.joint(name, f"{what} '{name}'")
            if j.type not in ("revolute", "prismatic", "continuous"):
                raise HandFileError(f"{self.where}: {what}: joint '{name}' is {j.type}; only a moving joint can be held")
            if j.limit is not None and j.type != "continuous" and not (j.limit.lower - 1e-9 <= v <= j.limit.upper + 1e-9):
                raise HandFileError(f"{self.where}: {what}: joint '{name}' held at {v:g}, outside its limits "
                                    f"[{j.limit.lower:g}, {j.limit.upper:g}]")
            self.held[name] = float(v)

    def moves(self, j) -> bool:
        """Whether joint j moves (not fixed, not held)."""
        return j.type != "fixed" and j.name not in self.held

    def zero_pose(self, link: str) -> np.ndarray:
        """The link's frame in the root's frame at every joint 0 (a joint at 0 is its origin) and
        every held joint at its value."""
        from scipy.spatial.transform import Rotation

        T = np.eye(4)
        for j in self.chain(link):
            T = T @ _origin(j.origin)
            if j.name in self.held:
                axis = _unit(j.axis if j.axis is not None else (1, 0, 0))
                M = np.eye(4)
                if j.type == "prismatic":
                    M[:3, 3] = axis * self.held[j.name]
                else:
                    M[:3, :3] = Rotation.from_rotvec(axis * self.held[j.name]).as_matrix()
                T = T @ M
        return T


# ---------------------------------------------------------------- collision shapes ----

def _mesh_points(geom_mesh, urdf_dir: Path, where: str, link: str) -> list:
    """The vertices (in the link's frame, scaled) of each connected piece of a collision mesh."""
    import trimesh

    name = geom_mesh.filename
    rel = name.split("://", 1)[1] if "://" in name else name
    if name.startswith("package://"):   # package://PKG/path: resolved beside the URDF without PKG, or with it
        cands = [urdf_dir / rel.split("/", 1)[-1], urdf_dir / rel]
    else:
        cands = [Path(rel) if Path(rel).is_absolute() else urdf_dir / rel]
    path = next((c for c in cands if c.is_file()), None)
    if path is None:
        raise HandFileError(f"{where}: link '{link}': mesh file '{name}' not found (looked for {cands[0]})")
    try:
        m = trimesh.load(str(path), force="mesh")
    except Exception as e:  # noqa: BLE001 - trimesh's loaders raise many kinds
        raise HandFileError(f"{where}: link '{link}': cannot read mesh '{path}' ({e})") from None
    V = np.asarray(m.vertices, dtype=float)
    if len(V) < 4:
        raise HandFileError(f"{where}: link '{link}': mesh '{path}' has fewer than 4 vertices")
    scale = 1.0 if geom_mesh.scale is None else np.asarray(geom_mesh.scale, dtype=float)
    # each connected piece its own convex hull (one hull over a multi-piece mesh would fill the
    # space between the pieces); pieces with fewer than 4 vertices bound no volume and are left out
    pieces = [np.asarray(p.vertices, dtype=float) * scale for p in m.split(only_watertight=False)] if len(m.faces) else []
    pieces = [P for P in pieces if len(P) >= 4 and np.linalg.matrix_rank(P - P.mean(axis=0), tol=1e-9) == 3]
    return pieces or [V * scale]


def _transform(T: np.ndarray, P: np.ndarray) -> np.ndarray:
    return P @ T[:3, :3].T + T[:3, 3]


def _convex(points: np.ndarray, where: str = "convex shape") -> dict:
    """The convex hull of the points (Qhull, through scipy) as a hand file's convex shape: its
    vertices and its triangles wound counter-clockwise seen from outside."""
    from scipy.spatial import ConvexHull, QhullError

    P = np.asarray(points, dtype=float)
    try:
        hull = ConvexHull(P)
    except QhullError:
        raise HandFileError(f"{where}: its points span no volume (flat or degenerate)") from None
    keep = hull.vertices
    index = {int(v): i for i, v in enumerate(keep)}
    V = P[keep]
    faces = []
    for tri, eq in zip(hull.simplices, hull.equations):   # equations: outward normal n and offset, n.x + c <= 0
        a, b, c = (index[int(v)] for v in tri)
        if np.cross(V[b] - V[a], V[c] - V[a]) @ eq[:3] < 0:
            b, c = c, b
        faces.append([a, b, c])
    return {"type": "convex", "vertices": [[float(x) for x in p] for p in V], "faces": faces}


def _box(T: np.ndarray, size) -> dict:
    """A URDF box at pose T in our link frame: a box if its axes are the link's (up to order and
    sign), else its 8 corners as a convex shape."""
    h = 0.5 * np.asarray(size, dtype=float)
    R = T[:3, :3]
    A = np.abs(R)
    if np.all((A < _TOL) | (np.abs(A - 1.0) < _TOL)):
        return {"type": "box", "center": [float(x) for x in T[:3, 3]], "half_extents": [float(x) for x in A @ h]}
    corners = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]) * h
    return _convex(_transform(T, corners), "a box")


def _shapes_of(items: list, where: str) -> list:
    """Our shapes from (kind, pose in our link frame, geometry) items; a cylinder with a sphere of
    its radius at each end cap becomes one capsule."""
    spheres = [(i, T[:3, 3], g.radius) for i, (kind, T, g) in enumerate(items) if kind == "sphere"]
    used, out = set(), []
    for i, (kind, T, g) in enumerate(items):
        if kind != "cylinder":
            continue
        axis = T[:3, 2]
        p0, p1 = T[:3, 3] - 0.5 * g.length * axis, T[:3, 3] + 0.5 * g.length * axis
        caps = [next((k for k, c, r in spheres if k not in used and abs(r - g.radius) < _TOL
                      and np.linalg.norm(c - p) < _TOL), None) for p in (p0, p1)]
        if None not in caps and caps[0] != caps[1]:
            used.update(caps)
            used.add(i)
            out.append({"type": "capsule", "p0": [float(x) for x in p0], "p1": [float(x) for x in p1],
                        "radius": float(g.radius)})
    for i, (kind, T, g) in enumerate(items):
        if i in used:
            continue
        if kind == "sphere":
            c = [float(x) for x in T[:3, 3]]
            out.append({"type": "capsule", "p0": c, "p1": c, "radius": float(g.radius)})
        elif kind == "box":
            out.append(_box(T, g.size))
        elif kind == "cylinder":
            a = np.linspace(0.0, 2.0 * np.pi, _PRISM_SIDES, endpoint=False)
            ring = np.c_[g.radius * np.cos(a), g.radius * np.sin(a)]
            P = np.vstack([np.c_[ring, np.full(len(a), z)] for z in (-0.5 * g.length, 0.5 * g.length)])
            out.append(_convex(_transform(T, P), f"{where}: a cylinder"))
        else:  # mesh points, already in our link frame
            out.append(_convex(g, f"{where}: a mesh"))
    return out
