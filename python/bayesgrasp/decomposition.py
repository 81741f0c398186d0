"""The lift test's approximate convex decomposition of a concave object (CoACD), for any mesh
that loads: a clean procedural mesh, a 16k-triangle scan, a 200k-triangle artist model.

Steps (:func:`convex_decomposition`):

1. **simplify**: a mesh of more than :data:`DECOMPOSITION_FACES` triangles is decimated to that
   many by quadric error (Open3D) before CoACD sees it - CoACD's time grows with the triangles
   while the pieces only need to follow the surface to within about a millimetre (BENCHMARKS.md
   gives the deviation and the time on YCB scans);
2. **decompose**: CoACD with a search lighter than its defaults (:data:`COACD_SEARCH`; lighter
   still on a simplified mesh, :data:`COACD_SEARCH_SIMPLIFIED`), in a thread, with a progress
   line on stderr every few seconds while it runs (``say``);
3. **keep the solid pieces**: a piece whose hull spans (almost) no volume - flat slivers CoACD
   leaves on a scan's thin walls or open borders - is dropped, and counted in a warning;
4. **fall back**: if CoACD fails or leaves no solid piece, the whole mesh's convex hull is the one
   piece (the lift test still runs, honestly for grasps outside the concavity), with a warning.

The result is cached per mesh and parameters (``.npz``, :mod:`bayesgrasp.cache`); a fallback is
not (the next run tries again). Dropping flat pieces changes nothing for the built-in objects,
whose cached pieces all span more than 5 mm^3.
"""
from __future__ import annotations

import hashlib
import os
import sys
import warnings
from pathlib import Path
from typing import Callable, List, Optional, Union

import numpy as np

from bayesgrasp._args import c_seed
from bayesgrasp.cache import atomic_write, cache_root, load_cached
from bayesgrasp.progress import heartbeat

#: Triangles above which the mesh is simplified before CoACD (the built-in objects, at most
#: 3,640, stay below).
DECOMPOSITION_FACES = 4000

#: CoACD's search, lighter than its defaults (the lift test needs pieces near the hand's contacts,
#: not the tightest decomposition; BENCHMARKS.md gives its time and pieces on the mug).
COACD_SEARCH = {"mcts_iterations": 50, "mcts_nodes": 10, "resolution": 1000, "max_ch_vertex": 48}
#: The search on a simplified mesh (a scan): shallower and shorter still - a scan's rough inside
#: asks for more cuts, each searched for less (BENCHMARKS.md: time and pieces on YCB scans).
COACD_SEARCH_SIMPLIFIED = {**COACD_SEARCH, "mcts_iterations": 20, "mcts_max_depth": 2}

#: A piece must span more than this volume (m^3; 1 mm^3) to be kept.
MIN_PIECE_VOLUME = 1e-9

#: Seconds between progress lines while CoACD runs.
PROGRESS_EVERY = 5.0


class DecompositionWarning(UserWarning):
    """The decomposition dropped pieces or fell back to the convex hull."""


def decomposition_cache_dir() -> Path:
    """Where :func:`convex_decomposition` keeps its results: ``$BAYESGRASP_CACHE`` (or
    ``~/.cache/bayesgrasp``) / ``convex_decomposition``."""
    return cache_root() / "convex_decomposition"


def _read_pieces(path: Path) -> List[np.ndarray]:
    with np.load(path, allow_pickle=False) as z:
        return [np.array(z[f"piece_{i}"], dtype=np.float64) for i in range(int(z["count"]))]


def _coacd_version() -> str:
    try:
        from importlib.metadata import version
        return version("coacd")
    except Exception:  # noqa: BLE001 - the version only salts the cache key
        return "unknown"


def _check(V: np.ndarray, F: np.ndarray, threshold: float) -> None:
    if V.ndim != 2 or V.shape[1] != 3 or len(V) < 4:
        raise ValueError(f"vertices: expected shape (N, 3) with N >= 4, got {V.shape}")
    if not np.all(np.isfinite(V)):
        raise ValueError("vertices: contain NaN or infinity")
    if F.ndim != 2 or F.shape[1] != 3 or len(F) < 4:
        raise ValueError(f"faces: expected shape (M, 3) with M >= 4, got {F.shape}")
    if F.min() < 0 or F.max() >= len(V):
        raise ValueError(f"faces: indices must be in [0, {len(V)}), got [{F.min()}, {F.max()}]")
    if not (np.isfinite(threshold) and 0 < threshold <= 1):
        raise ValueError(f"threshold: must be in (0, 1], got {threshold}")


def _search(n_faces: int, max_faces: int) -> dict:
    return COACD_SEARCH_SIMPLIFIED if n_faces > max_faces else COACD_SEARCH


def _cache_path(V, F, threshold, seed, max_faces, cache_dir) -> Path:
    h = hashlib.sha256()
    h.update(V.tobytes())
    h.update(F.astype(np.int32).tobytes())
    h.update(f"coacd-{_coacd_version()}-t{threshold!r}-s{int(seed)}-{sorted(_search(len(F), max_faces).items())}".encode())
    if len(F) > max_faces:   # only simplified meshes salt the key with it (the others' keys are as before)
        h.update(f"-simplified-{int(max_faces)}".encode())
    return Path(decomposition_cache_dir() if cache_dir is None else cache_dir) / f"{h.hexdigest()[:32]}.npz"


def simplify(V: np.ndarray, F: np.ndarray, max_faces: int = DECOMPOSITION_FACES):
    """(V, F) decimated to at most ``max_faces`` triangles by quadric error (Open3D); as given
    when already that small."""
    if len(F) <= max_faces:
        return V, F
    import open3d as o3d

    m = o3d.geometry.TriangleMesh(o3d.utility.Vector3dVector(V), o3d.utility.Vector3iVector(F.astype(np.int32)))
    m = m.simplify_quadric_decimation(target_number_of_triangles=int(max_faces))
    m.remove_degenerate_triangles()
    m.remove_unreferenced_vertices()
    return np.asarray(m.vertices, dtype=np.float64), np.asarray(m.triangles, dtype=np.int64)


def _run_coacd(V: np.ndarray, F: np.ndarray, threshold: float, seed: int, search: dict,
               say: Optional[Callable[[str], None]], what: str) -> list:
    """CoACD's pieces (list of vertex arrays); a progress line every PROGRESS_EVERY s while it
    runs (CoACD is a ctypes call: it runs without the GIL)."""
    import coacd  # only needed here

    coacd.set_log_level("error")
    with heartbeat(say, f"decomposing {what} for the lift test", every=PROGRESS_EVERY):
        parts = coacd.run_coacd(coacd.Mesh(V, F.astype(np.int32)), threshold=float(threshold), seed=seed, **search)
    return [np.ascontiguousarray(p[0], dtype=np.float64) for p in parts]


def _hull_volume(P: np.ndarray) -> float:
    from scipy.spatial import ConvexHull, QhullError

    if len(P) < 4:
        return 0.0
    try:
        return float(ConvexHull(P).volume)
    except (QhullError, ValueError):
        return 0.0


def solid_pieces(pieces: List[np.ndarray], min_volume: float = MIN_PIECE_VOLUME):
    """(the pieces whose hull spans more than ``min_volume``, how many were dropped)."""
    kept = [p for p in pieces if np.all(np.isfinite(p)) and _hull_volume(p) > min_volume]
    return kept, len(pieces) - len(kept)


def stderr_say(line: str) -> None:
    print(line, file=sys.stderr, flush=True)


def convex_decomposition(vertices, faces, threshold: float = 0.05, seed: int = 0,
                         cache_dir: Union[str, os.PathLike, None, bool] = None, name: Optional[str] = None,
                         say: Optional[Callable[[str], None]] = stderr_say,
                         max_faces: int = DECOMPOSITION_FACES) -> List[np.ndarray]:
    """Approximate convex decomposition of a triangle mesh for the lift test, cached per mesh
    (the module docstring gives the steps).

    Args:
        vertices: (N, 3) float vertices (m). faces: (M, 3) int triangles.
        threshold: CoACD's concavity threshold (smaller: more, tighter pieces). 0.05 (CoACD's
            default) cuts the built-in mug into a few dozen pieces that keep its opening and
            handle.
        seed: CoACD's random seed (same mesh and seed give the same pieces).
        cache_dir: directory of the ``.npz`` cache (None: :func:`decomposition_cache_dir`;
            False: no cache). The key is a SHA-256 of the mesh's bytes and the parameters.
        name: the mesh's name in warnings and progress lines.
        say: where progress lines go while CoACD runs (default stderr; None: silent).
        max_faces: meshes with more triangles are simplified to this many first.

    Returns:
        list of (K_i, 3) float64 arrays: the vertices of each convex piece, in the mesh's frame.

    Warns:
        DecompositionWarning: pieces without volume were dropped, or CoACD failed and the convex
            hull is used.
    """
    V = np.ascontiguousarray(vertices, dtype=np.float64)
    F = np.ascontiguousarray(faces, dtype=np.int64)
    _check(V, F, threshold)
    seed = c_seed(seed, "seed")
    what = f"'{name}'" if name else "the mesh"
    path = None if cache_dir is False else _cache_path(V, F, threshold, seed, max_faces, cache_dir)
    if path is not None:
        cached = load_cached(path, "convex decomposition cache file", _read_pieces)
        if cached is not None:
            return cached
    if say is not None:
        say(f"  decomposing {what} for the lift test (once per mesh, then cached; {len(F)} triangles"
            + (f", simplified to {max_faces})" if len(F) > max_faces else ")"))
    Vs, Fs = simplify(V, F, max_faces)
    try:
        pieces, dropped = solid_pieces(_run_coacd(Vs, Fs, threshold, seed, _search(len(F), max_faces), say, what))
        if dropped:
            warnings.warn(f"convex decomposition of {what}: dropped {dropped} of {dropped + len(pieces)} pieces "
                          "that span no volume (flat slivers)", DecompositionWarning, stacklevel=2)
        failure = None if pieces else "it left no piece with a volume"
    except Exception as e:  # noqa: BLE001 - the lift test must still run
        pieces, failure = [], f"CoACD failed ({type(e).__name__}: {e})"
    if failure:   # not cached: the next run tries again (and warns again)
        warnings.warn(f"convex decomposition of {what}: {failure}; the lift test uses its convex hull",
                      DecompositionWarning, stacklevel=2)
        return [V]
    if path is not None:
        # atomic and checksummed: concurrent runs never read a half-written file (bayesgrasp.cache)
        atomic_write(path, lambda tmp: np.savez(tmp, count=len(pieces), **{f"piece_{i}": p for i, p in enumerate(pieces)}))
    return pieces
