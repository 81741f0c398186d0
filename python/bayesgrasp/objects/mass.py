"""Mass properties of object meshes, closed or open (scans, artist meshes).

A closed (watertight) mesh has exact mass properties: the divergence-theorem integral of the core
(:func:`bayesgrasp._core.geometry.mass_properties`). A scan is rarely closed: holes, a missing
bottom, non-manifold seams. Its convex hull would count a mug's or a bowl's whole inside as
material, so an open mesh is measured by what it encloses instead:

* ``"fill"``: the solid the surface bounds, found by sampling. The bounding box is cut into cells
  of equal volume (about :data:`FILL_SAMPLES` of them); one point jittered inside each cell (seeded)
  is inside when most of :data:`FILL_RAYS` rays from it, in directions spread evenly over the sphere
  (a Fibonacci lattice), cross the surface an odd number of times (Open3D's
  ``RaycastingScene.count_intersections``). The vote lets the rays that leave through a hole be
  outvoted: in a cup whose rim is missing, a ray from the cavity that crosses the inner wall and
  leaves through the rim's gap counts once, the many that cross both walls twice. (Open3D's own
  ``compute_occupancy(nsamples=k)`` was tried first: its votes agreed with a single ray, and it
  counted 4.5% of such a cup's cavity as material.) Volume = inside cells x cell volume; centre of
  mass and inertia are the sums over the inside cells (each a point of its cell's mass plus the
  cell's own box inertia).
* ``"shell"``: a surface that encloses (almost) nothing from anywhere - a bent sheet, a lid, a
  plate scanned as one layer - is a thin shell of thickness ``shell_thickness``: each triangle a
  lamina of mass density x area x thickness, with its exact second moment (integral of x x^T over
  a triangle = A/12 (a a^T + b b^T + c c^T + s s^T), s = a + b + c).

The fill is used unless it finds less than a quarter of the shell's volume (then the shell).

What geometry cannot tell: a container modelled as one sheet with its opening left open (a cup
without wall thickness) is the same surface as a solid whose top face is missing; the fill reads
both as solid. Real scans model the wall's two sides (the YCB mug's fill is its wall, 138 cm^3,
not its 525 cm^3 hull); for a one-sheet container, ``mass=`` gives the weight.
"""
from __future__ import annotations

from typing import Tuple

import numpy as np

#: Cells of the fill's sampling grid (its relative standard error on a mug's wall volume is
#: below 1%).
FILL_SAMPLES = 200_000
#: Rays per sample point (odd: a majority always exists).
FILL_RAYS = 15
#: Wall thickness of the shell model, m (a thin plastic or ceramic wall).
DEFAULT_SHELL_THICKNESS = 0.003


def _core_mass_properties(volume: float, mass: float, com, inertia):
    from bayesgrasp import _core

    return _core.geometry.MassProperties(float(volume), float(mass), np.asarray(com, dtype=float),
                                         np.asarray(inertia, dtype=float))


def closed_mass_properties(V: np.ndarray, F: np.ndarray, density: float):
    """The core's exact MassProperties of a closed mesh at ``density``."""
    from bayesgrasp import _core

    return _core.geometry.mass_properties(V, F, float(density))


def _point_masses(P: np.ndarray, m: np.ndarray, own: np.ndarray):
    """(mass, com, inertia about com) of point masses ``m`` at ``P`` plus their own inertia
    ``own`` (3, 3), summed about the origin first."""
    M = float(m.sum())
    com = (m[:, None] * P).sum(axis=0) / M
    R = P - com
    second = np.einsum("i,ij,ik->jk", m, R, R)               # sum m r r^T
    inertia = np.trace(second) * np.eye(3) - second + own
    return M, com, 0.5 * (inertia + inertia.T)


def _sphere_directions(n: int) -> np.ndarray:
    """(n, 3) unit vectors spread evenly over the sphere (Fibonacci lattice), none along an axis."""
    k = np.arange(n) + 0.5
    z = 1 - 2 * k / n
    phi = np.pi * (1 + 5 ** 0.5) * k + 0.1
    rho = np.sqrt(1 - z ** 2)
    return np.column_stack([rho * np.cos(phi), rho * np.sin(phi), z])


def fill_mass_properties(V: np.ndarray, F: np.ndarray, density: float, samples: int = FILL_SAMPLES,
                         rays: int = FILL_RAYS, seed: int = 0):
    """MassProperties of the solid an open mesh bounds, by jittered-grid occupancy sampling
    (module docstring), or None when no sample is inside."""
    import open3d as o3d

    lo, hi = V.min(axis=0), V.max(axis=0)
    size = np.maximum(hi - lo, 1e-6)
    h = float((np.prod(size) / samples) ** (1.0 / 3.0))     # cell edge
    n = np.maximum(1, np.ceil(size / h).astype(int))
    cell = size / n
    grid = np.stack(np.meshgrid(*(np.arange(k) for k in n), indexing="ij"), axis=-1).reshape(-1, 3)
    rng = np.random.default_rng(seed)
    P = lo + (grid + rng.random(grid.shape)) * cell
    scene = o3d.t.geometry.RaycastingScene()
    scene.add_triangles(o3d.core.Tensor(V.astype(np.float32)), o3d.core.Tensor(F.astype(np.uint32)))
    odd = np.zeros(len(P), dtype=np.int32)
    for d in _sphere_directions(rays):
        R = np.hstack([P, np.broadcast_to(d, P.shape)]).astype(np.float32)
        odd += scene.count_intersections(o3d.core.Tensor(R)).numpy().astype(np.int64) % 2
    inside = 2 * odd > rays
    k = int(np.count_nonzero(inside))
    if k == 0:
        return None
    cell_volume = float(np.prod(cell))
    dm = density * cell_volume
    a2 = cell ** 2
    own = k * dm / 12.0 * np.diag([a2[1] + a2[2], a2[0] + a2[2], a2[0] + a2[1]])   # each cell a box
    mass, com, inertia = _point_masses(P[inside], np.full(k, dm), own)
    return _core_mass_properties(k * cell_volume, mass, com, inertia)


def shell_mass_properties(V: np.ndarray, F: np.ndarray, density: float,
                          thickness: float = DEFAULT_SHELL_THICKNESS):
    """MassProperties of the surface as a thin shell (module docstring); volume = area x thickness."""
    a, b, c = V[F[:, 0]], V[F[:, 1]], V[F[:, 2]]
    area = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1)
    m = density * thickness * area
    M = float(m.sum())
    s = a + b + c
    com = (m[:, None] * s / 3.0).sum(axis=0) / M
    # integral of x x^T over each triangle, about the origin, times its areal mass / area
    w = m / 12.0
    second = (np.einsum("i,ij,ik->jk", w, a, a) + np.einsum("i,ij,ik->jk", w, b, b)
              + np.einsum("i,ij,ik->jk", w, c, c) + np.einsum("i,ij,ik->jk", w, s, s))
    second -= M * np.outer(com, com)                        # about the centre of mass
    inertia = np.trace(second) * np.eye(3) - second
    return _core_mass_properties(float(area.sum()) * thickness, M, com, 0.5 * (inertia + inertia.T))


def open_mass_properties(V: np.ndarray, F: np.ndarray, density: float,
                         shell_thickness: float = DEFAULT_SHELL_THICKNESS, seed: int = 0) -> Tuple[object, str]:
    """(MassProperties, method) of an open mesh: ``"fill"`` unless it holds less than a quarter
    of what the shell of ``shell_thickness`` would (it encloses next to nothing), then ``"shell"``."""
    shell = shell_mass_properties(V, F, density, shell_thickness)
    fill = fill_mass_properties(V, F, density, seed=seed)
    if fill is not None and fill.volume >= 0.25 * shell.volume:
        return fill, "fill"
    return shell, "shell"


def with_mass(mp, mass: float):
    """The same mass properties scaled to ``mass`` kg (density = mass / volume)."""
    r = float(mass) / mp.mass
    return _core_mass_properties(mp.volume, mass, mp.com, np.asarray(mp.inertia) * r)


def moved(mp, T: np.ndarray):
    """Mass properties under the rigid transform ``T`` (4x4)."""
    R = T[:3, :3]
    return _core_mass_properties(mp.volume, mp.mass, R @ np.asarray(mp.com) + T[:3, 3],
                                 R @ np.asarray(mp.inertia) @ R.T)


def cache_salt(obj) -> bytes:
    """What a cache key of lift-tested results must add for an object whose lift test does not
    weigh its closed mesh at its density (an open scan, a weighed object): its mass properties.
    Empty otherwise, so the keys of closed meshes stay what they were."""
    if obj.mass_method == "mesh" and obj.given_mass is None:
        return b""
    mp = obj.mass_properties_core
    return (f"mass-{obj.mass_method}-{mp.mass!r}-{np.asarray(mp.com).tolist()}-"
            f"{np.asarray(mp.inertia).ravel().tolist()}").encode()
