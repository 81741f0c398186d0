"""Part labels of the procedural objects: which part of the object each triangle belongs to.

A task grasp is defined by where the hand may touch (a mug by its handle, a knife by its handle,
never by the blade), so every triangle of a built-in object carries a part label. The labels are
computed from the object's generating parameters and each triangle's centroid, after the mesh is
built (a boolean union re-meshes the parts, so labels cannot be carried through it):

* vessels (mugs, the pitcher): ``handle`` (centroid outside the body's outer radius at its height
  on the handle's side), ``rim`` (within 1.5 wall thicknesses of the top), ``body`` (the rest:
  outer and inner wall, bottom);
* bottles: ``body`` (below the shoulder), ``shoulder``, ``neck``, ``cap`` by height;
* hammers: ``handle`` and ``head`` (from the head's inner face on); knives: ``handle`` and ``blade``;
* cube and cylinder: one part, ``body``.

User meshes may bring a label file (:func:`load_part_labels`): JSON ``{"parts": [names...],
"faces": [one part index per triangle]}``.
"""
from __future__ import annotations

import json
from pathlib import Path
from typing import Callable, Dict, Sequence, Tuple

import numpy as np

PartLabels = Tuple[np.ndarray, Tuple[str, ...]]


def _centroids(V: np.ndarray, F: np.ndarray) -> np.ndarray:
    return V[F].mean(axis=1)


def _vessel_outer_radius(p: dict) -> Callable[[np.ndarray], np.ndarray]:
    """r_out(z) of the vessel profile (objects.library._vessel_profile)."""
    H = p["height"]

    def r_out(z):
        u = np.clip(z / H, 0, 1)
        return p["r_bottom"] + (p["r_top"] - p["r_bottom"]) * u + p["bulge"] * np.sin(np.pi * u)

    return r_out


def _vessel(p: dict, C: np.ndarray) -> PartLabels:
    names = ("body", "rim", "handle")
    r = np.hypot(C[:, 0], C[:, 1])
    out = r > _vessel_outer_radius(p)(C[:, 2]) + 0.25 * p["handle_thickness"]
    handle = out & (C[:, 0] > 0)
    rim = ~handle & (C[:, 2] > p["height"] - 1.5 * p["wall"])
    labels = np.zeros(len(C), dtype=np.int32)
    labels[rim] = 1
    labels[handle] = 2
    return labels, names


def _bottle(p: dict, C: np.ndarray) -> PartLabels:
    names = ("body", "shoulder", "neck", "cap")
    H = p["height"]
    z_neck = H - p["neck_height"] - p["cap_height"]
    z_shoulder = z_neck - p["shoulder_height"]
    z = C[:, 2]
    labels = np.zeros(len(C), dtype=np.int32)
    labels[z >= z_shoulder] = 1
    labels[z >= z_neck] = 2
    labels[z >= H - p["cap_height"]] = 3
    return labels, names


def _hammer(p: dict, C: np.ndarray) -> PartLabels:
    x_head = p["length"] - p["head_width"]
    return (C[:, 0] >= x_head - 1e-4).astype(np.int32), ("handle", "head")


def _knife(p: dict, C: np.ndarray) -> PartLabels:
    return (C[:, 0] >= p["handle_length"]).astype(np.int32), ("handle", "blade")


def _single(p: dict, C: np.ndarray) -> PartLabels:
    return np.zeros(len(C), dtype=np.int32), ("body",)


_BY_KIND: Dict[str, Callable[[dict, np.ndarray], PartLabels]] = {
    "vessel": _vessel, "bottle": _bottle, "hammer": _hammer, "knife": _knife, "cube": _single, "cylinder": _single}


def part_labels(params: dict, vertices, faces) -> PartLabels:
    """(labels (M,) int32 per triangle, part names) of a procedural object from its parameters."""
    kind = params.get("kind")
    if kind not in _BY_KIND:
        raise ValueError(f"params['kind']: no part rule for {kind!r}")
    V = np.asarray(vertices, dtype=float)
    F = np.asarray(faces)
    return _BY_KIND[kind](params, _centroids(V, F))


def check_part_labels(labels, names: Sequence[str], n_faces: int, what: str = "parts") -> PartLabels:
    """Validated (labels, names): one non-negative index below len(names) per triangle."""
    names = tuple(str(n) for n in names)
    if not names or len(set(names)) != len(names):
        raise ValueError(f"{what}: need distinct part names, got {list(names)}")
    a = np.asarray(labels)
    if a.shape != (n_faces,):
        raise ValueError(f"{what}: expected one label per triangle ({n_faces}), got shape {a.shape}")
    if a.size and not np.issubdtype(a.dtype, np.integer):
        raise ValueError(f"{what}: labels must be integer part indices, got {a.dtype}")
    if a.size and (a.min() < 0 or a.max() >= len(names)):
        raise ValueError(f"{what}: labels must lie in [0, {len(names)}), got [{a.min()}, {a.max()}]")
    return np.ascontiguousarray(a, dtype=np.int32), names


def load_part_labels(path, n_faces) -> PartLabels:
    """A user's label file: JSON ``{"parts": [names], "faces": [part index per triangle]}``.

    ``n_faces``: the triangle count the labels must have, or a pair (the file's triangles, the
    loaded mesh's faces after its degenerate triangles were dropped): either count is accepted."""
    p = Path(path)
    try:
        doc = json.loads(p.read_text())
    except (OSError, ValueError) as e:
        raise ValueError(f"part labels {p}: cannot read ({e})") from None
    if not isinstance(doc, dict) or "parts" not in doc or "faces" not in doc:
        raise ValueError(f"part labels {p}: expected an object with keys 'parts' and 'faces'")
    what = f"part labels {p}"
    if isinstance(n_faces, tuple):
        n_file, n_loaded = n_faces
        try:
            got = np.shape(doc["faces"])
        except ValueError:                      # a ragged list
            raise ValueError(f"{what}: 'faces' must be a flat list of part indices") from None
        if got in ((n_file,), (n_loaded,)):
            return check_part_labels(doc["faces"], doc["parts"], got[0], what=what)
        counts = (f"{n_file}, one per triangle of the mesh file in file order" if n_file == n_loaded else
                  f"{n_file}, one per triangle of the mesh file in file order, or {n_loaded}, one per "
                  f"face of the loaded mesh ({n_file - n_loaded} degenerate triangles dropped)")
        raise ValueError(f"{what}: expected {counts}; got shape {got}")
    return check_part_labels(doc["faces"], doc["parts"], n_faces, what=what)


def label_file_for(mesh_path) -> Path:
    """Where a mesh's label file is looked for: ``<mesh stem>.parts.json`` beside it."""
    p = Path(mesh_path)
    return p.with_name(p.stem + ".parts.json")
