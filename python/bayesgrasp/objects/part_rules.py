"""Part labels for a scan by simple geometric rules: the label file (``<stem>.parts.json``) a user
writes for a mesh of their own, one label per triangle of the file in file order.

A rule is ``NAME:AXISOPVALUE`` with AXIS one of x, y, z, r (the distance from the vertical axis
through the bounding box's centre), OP ``<`` or ``>`` and VALUE in metres, in the frame the object
is grasped in (the mesh's xy bounding box centred on the origin, its lowest point at z = 0, as a
Scene places it); ``handle:r>0.05`` is everything farther than 5 cm from the axis. Each triangle
takes the first rule its centroid meets, else the default part.
"""
from __future__ import annotations

import json
import re
from pathlib import Path
from typing import List, Sequence, Tuple

import numpy as np

from .parts import label_file_for

_RULE = re.compile(r"^\s*([A-Za-z_][\w-]*)\s*:\s*([xyzr])\s*([<>])\s*([-+]?[\d.]+(?:[eE][-+]?\d+)?)\s*$")

Rule = Tuple[str, str, str, float]


def parse_rule(text: str) -> Rule:
    """``"handle:r>0.05"`` -> ("handle", "r", ">", 0.05); ValueError naming the rule otherwise."""
    m = _RULE.match(text)
    if not m:
        raise ValueError(f"rule {text!r}: expected NAME:AXIS<VALUE or NAME:AXIS>VALUE, AXIS one of x, y, z, r "
                         "(metres), e.g. handle:r>0.05")
    return m.group(1), m.group(2), m.group(3), float(m.group(4))


def _centred(V: np.ndarray, F: np.ndarray) -> np.ndarray:
    """V in the frame a Scene places the mesh in (bounds of the vertices the faces use)."""
    used = V[np.unique(F)]
    lo, hi = used.min(axis=0), used.max(axis=0)
    return V - np.array([(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, lo[2]])


def label_by_rules(vertices, faces, rules: Sequence[Rule], default: str = "body") -> Tuple[np.ndarray, List[str]]:
    """(labels per triangle, part names) by the rules (module docstring); names: the default
    first, then each rule's part in order of first mention."""
    F = np.asarray(faces)
    V = _centred(np.asarray(vertices, dtype=float), F)
    C = V[F].mean(axis=1)
    value = {"x": C[:, 0], "y": C[:, 1], "z": C[:, 2], "r": np.hypot(C[:, 0], C[:, 1])}
    names = [default] + [n for n in dict.fromkeys(r[0] for r in rules) if n != default]
    labels = np.zeros(len(C), dtype=np.int32)
    done = np.zeros(len(C), dtype=bool)
    for name, axis, op, v in rules:
        hit = ~done & (value[axis] > v if op == ">" else value[axis] < v)
        labels[hit] = names.index(name)
        done |= hit
    return labels, names


def write_label_file(mesh_path, rules: Sequence[Rule], default: str = "body", units=None) -> Path:
    """Labels the triangles of ``mesh_path`` in file order by the rules and writes
    ``<stem>.parts.json`` beside it; returns its path."""
    from ..io.units import unit_scale
    from .mesh_io import read_triangles

    p = Path(mesh_path)
    V, F = read_triangles(p)                            # the file's triangles, as load_mesh reads them
    labels, names = label_by_rules(V * unit_scale(units), F, rules, default)
    out = label_file_for(p)
    out.write_text(json.dumps({"parts": names, "faces": labels.tolist()}))
    return out
