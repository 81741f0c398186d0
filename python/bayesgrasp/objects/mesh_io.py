"""Triangle-mesh objects: loading OBJ / STL / PLY files and their mass properties.

An :class:`ObjectModel` is a closed triangle mesh in metres (vertices ``(N, 3)`` float64, faces
``(M, 3)`` int32, counter-clockwise seen from outside) with a uniform density. Its mass properties
(volume, mass, centre of mass, inertia about the centre of mass) come from the C++ core
(:func:`bayesgrasp._core.geometry.mass_properties`).

Bad input raises clear exceptions: a missing file :class:`FileNotFoundError`, a file that is not a
mesh or has an unsupported extension :class:`ValueError`, a mesh without faces or with non-finite
vertices :class:`ValueError`. A mesh that is not watertight only warns (:class:`MeshWarning`); its
mass properties are then those of the solid it bounds, found by sampling, or of a thin shell
(:mod:`bayesgrasp.objects.mass`). ``mass=`` (kg, a scale's reading) sets the density instead.
"""
from __future__ import annotations

import os
import sys
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Optional, Tuple, Union

import numpy as np

from . import mass as _mass
from .topology import _check_solid, mesh_is_watertight, orient_outward

#: Default density for meshes loaded from files, kg/m^3. Water's density: typical of household
#: objects as a whole (a full bottle, a plastic box, a wooden toy are 500-1200 kg/m^3); pass
#: ``density=`` to load_mesh / load_object for anything else. Built-in objects carry their own.
DEFAULT_DENSITY = 1000.0

#: Meshes of more triangles than this say on stderr what their loading is doing (it takes seconds).
BIG_MESH = 50_000

#: File extensions load_mesh reads (and ObjectModel.save writes).
MESH_EXTENSIONS = (".obj", ".stl", ".ply")


class MeshWarning(UserWarning):
    """A mesh problem that does not stop loading (e.g. it is not watertight)."""


def _checked_pieces(pieces, name: str) -> list:
    out = [np.asarray(p, dtype=np.float64) for p in pieces]
    if not out or any(p.ndim != 2 or p.shape[1] != 3 or len(p) < 4 or not np.all(np.isfinite(p)) for p in out):
        raise ValueError(f"convex_pieces of '{name}': expected a non-empty list of finite (K, 3) arrays with K >= 4")
    return out


@dataclass
class ObjectModel:
    """A rigid object: a closed triangle mesh (metres) of uniform density (kg/m^3).

    Attributes:
        name: built-in name (e.g. ``"mug/3"``) or the file's stem.
        vertices: (N, 3) float64, metres, in the object's own frame.
        faces: (M, 3) int32 vertex indices, counter-clockwise seen from outside.
        density: kg/m^3 (> 0).
        source: where it came from (``"builtin:mug/3"`` or the file path).
        params: the parameter dict that generated a built-in object (empty for files).
        parts: (M,) int32 part index per triangle, or None (no labels); ``part_names`` names them
            (see :mod:`bayesgrasp.objects.parts`).

    Mass properties (``volume``, ``mass``, ``com``, ``inertia`` about the centre of mass, in this
    frame) are computed once at construction; ``mass_method`` says how: ``"mesh"`` (closed: exact),
    ``"fill"`` (open: the solid it bounds, sampled) or ``"shell"`` (open and enclosing nothing: a
    thin wall), see :mod:`bayesgrasp.objects.mass`. ``mass`` (kg), if given, sets the density
    (mass / volume).
    """

    name: str
    vertices: np.ndarray
    faces: np.ndarray
    density: float = DEFAULT_DENSITY
    source: str = ""
    params: dict = field(default_factory=dict)
    warn_if_open: bool = True
    parts: Optional[np.ndarray] = None
    part_names: Tuple[str, ...] = ()
    given_mass: Optional[float] = None
    #: (mass properties in this frame or None, their method, watertight) already known: a copy's
    known_mass: Optional[tuple] = field(default=None, repr=False, compare=False)
    #: the convex pieces ((K_i, 3) arrays, this frame) the lift test uses, when known without a
    #: decomposition (a warped model's: its training model's pieces moved by the same warp), or a
    #: callable returning them when the lift test first needs them; None: the lift test decomposes
    #: the mesh (CoACD, cached)
    convex_pieces: Optional[Union[list, Callable[[], list]]] = field(default=None, repr=False, compare=False)

    def __post_init__(self):
        V = np.ascontiguousarray(np.asarray(self.vertices, dtype=np.float64))
        F = np.asarray(self.faces)
        if V.ndim != 2 or V.shape[1] != 3:
            raise ValueError(f"vertices of '{self.name}' must have shape (N, 3), got {V.shape}")
        if F.ndim != 2 or F.shape[1] != 3:
            raise ValueError(f"faces of '{self.name}' must have shape (M, 3), got {F.shape}")
        if len(F) == 0:
            raise ValueError(f"mesh '{self.name}' has no faces")
        if not np.issubdtype(F.dtype, np.integer):
            raise ValueError(f"faces of '{self.name}' must be integer indices, got {F.dtype}")
        if not np.all(np.isfinite(V)):
            raise ValueError(f"mesh '{self.name}' has NaN or infinite vertex coordinates")
        if F.min() < 0 or F.max() >= len(V):
            raise ValueError(f"faces of '{self.name}' index vertices out of range [0, {len(V)})")
        if not (np.isfinite(self.density) and self.density > 0):
            raise ValueError(f"density must be finite and > 0 kg/m^3, got {self.density}")
        self.density = float(self.density)
        self.vertices = V
        self.faces = np.ascontiguousarray(F, dtype=np.int32)
        if self.parts is not None:
            from .parts import check_part_labels

            self.parts, self.part_names = check_part_labels(self.parts, self.part_names, len(self.faces),
                                                            what=f"parts of '{self.name}'")
        elif self.part_names:
            raise ValueError(f"part_names of '{self.name}' given without parts")
        _check_solid(self.vertices, self.faces, self.name)
        known_mp, known_method, self._watertight = self.known_mass or (None, None, mesh_is_watertight(self.faces))
        if known_mp is not None:
            self._mp, self.mass_method = known_mp, known_method
        elif self._watertight:
            self._mp, self.mass_method = _mass.closed_mass_properties(self.vertices, self.faces, self.density), "mesh"
        else:
            self._mp, self.mass_method = _mass.open_mass_properties(self.vertices, self.faces, self.density)
            if self.warn_if_open and self.given_mass is None:   # weighed: its volume only sets the density
                how = ("the solid it bounds (sampled)" if self.mass_method == "fill" else
                       f"a {1000 * _mass.DEFAULT_SHELL_THICKNESS:g} mm shell (it encloses no volume)")
                warnings.warn(f"mesh '{self.name}' ({self.source or 'in memory'}) is not watertight: its mass "
                              f"properties are those of {how}; pass mass= (--mass) to give its weight",
                              MeshWarning, stacklevel=3)
        self.known_mass = None
        if self.convex_pieces is not None and not callable(self.convex_pieces):
            self.convex_pieces = _checked_pieces(self.convex_pieces, self.name)
        if self.given_mass is not None:
            if not (np.isfinite(self.given_mass) and self.given_mass > 0):
                raise ValueError(f"mass must be finite and > 0 kg, got {self.given_mass}")
            self.given_mass = float(self.given_mass)
            if self._mp.mass != self.given_mass:
                self._mp = _mass.with_mass(self._mp, self.given_mass)
            self.density = self.given_mass / self._mp.volume

    # ---- mass properties -------------------------------------------------------------------
    @property
    def mass_properties(self) -> dict:
        """dict with ``volume`` (m^3), ``mass`` (kg), ``com`` (3,), ``inertia`` (3, 3) about com."""
        return self._mp.to_dict()

    @property
    def volume(self) -> float:
        return self._mp.volume

    @property
    def mass(self) -> float:
        return self._mp.mass

    @property
    def com(self) -> np.ndarray:
        return np.array(self._mp.com)

    @property
    def inertia(self) -> np.ndarray:
        return np.array(self._mp.inertia)

    # ---- geometry --------------------------------------------------------------------------
    @property
    def bounds(self) -> np.ndarray:
        """(2, 3): row 0 the minimum corner, row 1 the maximum corner of the bounding box."""
        return np.stack([self.vertices.min(axis=0), self.vertices.max(axis=0)])

    @property
    def extent(self) -> np.ndarray:
        """(3,) bounding-box size along x, y, z (metres)."""
        b = self.bounds
        return b[1] - b[0]

    @property
    def is_watertight(self) -> bool:
        """Every edge shared by exactly two faces."""
        return self._watertight

    @property
    def max_radius_from_com(self) -> float:
        """Largest distance from the centre of mass to a vertex: the torque scale of the GWS."""
        return float(np.linalg.norm(self.vertices - self._mp.com, axis=1).max())

    @property
    def n_faces(self) -> int:
        return int(len(self.faces))

    def lift_pieces(self) -> Optional[list]:
        """:attr:`convex_pieces`, computed first if given as a callable (then kept); None: not given."""
        if callable(self.convex_pieces):
            self.convex_pieces = _checked_pieces(self.convex_pieces(), self.name)
        return self.convex_pieces

    def transformed(self, T: np.ndarray, name: Optional[str] = None) -> "ObjectModel":
        """A copy with vertices mapped by the 4x4 transform ``T`` (rigid: the same object, its
        mass too; otherwise, e.g. scaled, a new shape at this density)."""
        T = np.asarray(T, dtype=np.float64)
        if T.shape != (4, 4) or not np.all(np.isfinite(T)):
            raise ValueError(f"T must be a finite 4x4 transform, got shape {T.shape}")
        V = self.vertices @ T[:3, :3].T + T[:3, 3]
        # A closed mesh's mass properties are recomputed on the moved mesh (as they always were: the
        # same bits as a fresh load); an open one's sampled ones are carried under a rigid motion
        # (sampling again would cost seconds) and sampled again under any other transform.
        R = T[:3, :3]
        rigid = np.allclose(R.T @ R, np.eye(3), atol=1e-12) and np.linalg.det(R) > 0
        carried = self.mass_method != "mesh" and rigid
        known = (_mass.moved(self._mp, T) if carried else None, self.mass_method if carried else None, self._watertight)
        return ObjectModel(name or self.name, V, self.faces.copy(), self.density, self.source,
                           dict(self.params), warn_if_open=False,
                           parts=None if self.parts is None else self.parts.copy(), part_names=self.part_names,
                           given_mass=self.given_mass if rigid else None, known_mass=known,
                           convex_pieces=None if self.convex_pieces is None
                           else (lambda: [p @ T[:3, :3].T + T[:3, 3] for p in self.lift_pieces()]))

    def with_mass(self, mass: float) -> "ObjectModel":
        """A copy weighing ``mass`` kg (a scale's reading): same shape, density = mass / volume."""
        return ObjectModel(self.name, self.vertices.copy(), self.faces.copy(), self.density, self.source,
                           dict(self.params), warn_if_open=False,
                           parts=None if self.parts is None else self.parts.copy(), part_names=self.part_names,
                           given_mass=mass, known_mass=(self._mp, self.mass_method, self._watertight),
                           convex_pieces=self.convex_pieces)

    @property
    def mass_properties_core(self):
        """The core's MassProperties (this frame), e.g. for the lift test."""
        return self._mp

    def part_of_faces(self, faces) -> np.ndarray:
        """The part names (array of str) of triangles given by index; ValueError without labels."""
        if self.parts is None:
            raise ValueError(f"object '{self.name}' has no part labels")
        return np.asarray(self.part_names, dtype=object)[self.parts[np.asarray(faces, dtype=np.int64)]]

    def to_trimesh(self):
        """A ``trimesh.Trimesh`` view of the mesh (no processing)."""
        import trimesh

        return trimesh.Trimesh(vertices=self.vertices.copy(), faces=self.faces.copy(), process=False)

    def save(self, path: Union[str, os.PathLike]) -> Path:
        """Write the mesh to ``path`` (.obj, .stl or .ply, chosen by the extension)."""
        path = Path(path)
        ext = path.suffix.lower()
        if ext not in MESH_EXTENSIONS:
            raise ValueError(f"cannot save '{path}': unsupported extension '{ext}' "
                             f"(use one of {', '.join(MESH_EXTENSIONS)})")
        path.parent.mkdir(parents=True, exist_ok=True)
        self.to_trimesh().export(str(path), file_type=ext[1:])
        return path

    def __repr__(self) -> str:
        e = self.extent
        return (f"ObjectModel('{self.name}', {len(self.vertices)} vertices, {len(self.faces)} faces, "
                f"extent=({e[0]:.3f}, {e[1]:.3f}, {e[2]:.3f}) m, mass={self.mass:.3f} kg)")


def load_mesh(path: Union[str, os.PathLike], density: Optional[float] = None,
              name: Optional[str] = None, units: Optional[str] = None,
              mass: Optional[float] = None) -> ObjectModel:
    """Load an OBJ, STL or PLY triangle mesh as an :class:`ObjectModel` in metres.

    Vertices are merged (STL stores each triangle separately), inconsistent face winding is made
    consistent and inward-facing closed components are flipped so that their volume is positive.

    Args:
        path: the mesh file.
        density: kg/m^3 (default :data:`DEFAULT_DENSITY`).
        name: object name (default: the file's stem).
        units: the file's length unit, ``"m"`` (default), ``"cm"`` or ``"mm"``.
        mass: kg (a scale's reading): the density becomes mass / volume (not with ``density``).

    Raises:
        FileNotFoundError: the file does not exist.
        ValueError: unsupported extension, not a mesh, no faces, NaN/infinite coordinates, an
            extent outside 5 mm .. 2 m (the message names the likely unit).

    Warns:
        MeshWarning: the mesh is not watertight (mass properties then of the solid it bounds, or
            of a thin shell: :mod:`bayesgrasp.objects.mass`).
    """
    check_mass_or_density(mass, density)
    p = Path(path)
    V, F = read_triangles(p)
    return _object_from_arrays(V, F, f"'{p}'", name or p.stem, density, units, source=str(p), label_path=p, mass=mass)


def check_mass_or_density(mass: Optional[float], density: Optional[float]) -> None:
    """ValueError when both are given: the mass sets the density."""
    if mass is not None and density is not None:
        raise ValueError("mass, density: give one of them (the mass sets the density)")


def read_triangles(path: Union[str, os.PathLike]) -> Tuple[np.ndarray, np.ndarray]:
    """(V, F) of a mesh file as stored: every triangle in file order, nothing merged or dropped
    (the file's own units). FileNotFoundError / ValueError as :func:`load_mesh`."""
    import trimesh

    p = Path(path)
    if not p.is_file():
        raise FileNotFoundError(f"mesh file not found: '{p}'")
    ext = p.suffix.lower()
    if ext not in MESH_EXTENSIONS:
        raise ValueError(f"'{p}': unsupported mesh file extension '{ext}' "
                         f"(supported: {', '.join(MESH_EXTENSIONS)})")
    try:
        loaded = trimesh.load(str(p), file_type=ext[1:], process=False)
        if isinstance(loaded, trimesh.Scene):   # several geometries (or none): one mesh
            loaded = (trimesh.util.concatenate(list(loaded.geometry.values()))
                      if len(loaded.geometry) else trimesh.Trimesh())
    except Exception as e:  # trimesh raises many kinds on garbage
        raise ValueError(f"'{p}' is not a readable {ext[1:].upper()} mesh: {e}") from e
    if isinstance(loaded, trimesh.PointCloud):
        raise ValueError(f"'{p}': mesh has no faces (a point cloud of {len(loaded.vertices)} "
                         "vertices)")
    if isinstance(loaded, (list, tuple)):
        raise ValueError(f"'{p}' is not a triangle mesh")
    if not isinstance(loaded, trimesh.Trimesh):
        raise ValueError(f"'{p}' is not a triangle mesh (read as {type(loaded).__name__})")
    V = np.asarray(loaded.vertices, dtype=np.float64)
    F = np.asarray(loaded.faces)
    if len(V) == 0 and len(F) == 0:
        raise ValueError(f"'{p}' is not a {ext[1:].upper()} mesh: no vertices or faces could be read")
    return V, F


def mesh_from_object(mesh, name: str = "mesh", density: Optional[float] = None,
                     units: Optional[str] = None, mass: Optional[float] = None) -> ObjectModel:
    """An :class:`ObjectModel` from an in-memory mesh: a ``trimesh.Trimesh``, an
    ``open3d.geometry.TriangleMesh`` or an ``open3d.t.geometry.TriangleMesh`` (the input is not
    modified; the same repairs and checks as :func:`load_mesh`)."""
    if hasattr(mesh, "to_legacy") and hasattr(mesh, "vertex"):        # Open3D tensor mesh
        mesh = mesh.to_legacy()
    if hasattr(mesh, "faces") and hasattr(mesh, "vertices"):           # trimesh.Trimesh
        V, F = np.asarray(mesh.vertices), np.asarray(mesh.faces)
    elif hasattr(mesh, "triangles") and hasattr(mesh, "vertices"):     # Open3D legacy mesh
        V, F = np.asarray(mesh.vertices), np.asarray(mesh.triangles)
    else:
        raise ValueError(f"{name}: expected a trimesh.Trimesh or an Open3D TriangleMesh, got {type(mesh).__name__}")
    check_mass_or_density(mass, density)
    return _object_from_arrays(np.array(V, dtype=np.float64), np.array(F), name, name, density, units,
                               source=f"in memory ({type(mesh).__name__})", mass=mass)


def _object_from_arrays(V: np.ndarray, F: np.ndarray, what: str, name: str, density: Optional[float],
                        units: Optional[str], source: str, label_path: Optional[Path] = None,
                        mass: Optional[float] = None) -> ObjectModel:
    """The shared checks and repairs of a mesh given as vertex and face arrays, scaled to metres."""
    import trimesh

    from ..io.units import check_extent, unit_scale

    scale = unit_scale(units)
    if len(F) == 0:
        raise ValueError(f"{what}: mesh has no faces ({len(V)} vertices)")
    if V.ndim != 2 or V.shape[1] != 3:
        raise ValueError(f"{what}: vertices must be 3-D, got shape {V.shape}")
    if F.ndim != 2 or F.shape[1] != 3 or not np.issubdtype(F.dtype, np.integer):
        raise ValueError(f"{what}: faces must be integer triangles (M, 3), got {F.shape} {F.dtype}")
    if F.min() < 0 or F.max() >= len(V):
        raise ValueError(f"{what}: faces index vertices out of range [0, {len(V)})")
    if not np.all(np.isfinite(V)):
        bad = int(np.count_nonzero(~np.all(np.isfinite(V), axis=1)))
        raise ValueError(f"{what}: mesh has {bad} vertices with NaN or infinite coordinates")
    V = V * scale
    check_extent(V[np.unique(F)], what, units)
    big = len(F) > BIG_MESH
    if big:
        print(f"  reading {what}: {len(F):,} triangles (merging, orienting, then weighing)", file=sys.stderr, flush=True)
    mesh = trimesh.Trimesh(vertices=V, faces=F, process=False)
    mesh.merge_vertices(merge_tex=True, merge_norm=True)
    mesh.remove_unreferenced_vertices()
    V = np.asarray(mesh.vertices, dtype=np.float64)
    F = np.asarray(mesh.faces, dtype=np.int64)
    # drop faces that collapse to a line or point (repeated indices)
    keep = (F[:, 0] != F[:, 1]) & (F[:, 1] != F[:, 2]) & (F[:, 2] != F[:, 0])
    parts, part_names = _label_file(label_path, keep) if label_path is not None else (None, ())
    F = F[keep]
    if len(F) == 0:
        raise ValueError(f"{what}: mesh has no non-degenerate faces")
    F = orient_outward(V, F)
    if big:
        print(f"  weighing {what}", file=sys.stderr, flush=True)
    d = DEFAULT_DENSITY if density is None else density
    return ObjectModel(name, V, F.astype(np.int32), d, source=source, parts=parts, part_names=part_names,
                       given_mass=mass)


def _label_file(mesh_path: Path, keep: np.ndarray):
    """The mesh's part labels from ``<stem>.parts.json`` beside it, if there is one, for the
    loaded faces: a label per triangle of the file (file order; the degenerate ones' labels are
    dropped with them) or, the same labels already without them, one per loaded face."""
    from .parts import label_file_for, load_part_labels

    f = label_file_for(mesh_path)
    if not f.is_file():
        return None, ()
    n_file, n_loaded = len(keep), int(np.count_nonzero(keep))
    parts, names = load_part_labels(f, (n_file, n_loaded))
    return (parts[keep] if len(parts) == n_file else parts), names
