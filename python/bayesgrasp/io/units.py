"""Length units of meshes and clouds, and the guard against data in the wrong unit.

bayesgrasp works in metres. Sensor software and CAD files often write millimetres or centimetres;
an object read in the wrong unit is 1000 times too large (or small) and every grasp on it is
meaningless, so an extent outside [5 mm, 2 m] is refused with the likely unit named.
"""
from __future__ import annotations

import math
from typing import Optional

import numpy as np

#: Metres per unit.
UNITS = {"m": 1.0, "cm": 0.01, "mm": 0.001}

#: An object's largest extent must lie in this range (m).
OBJECT_EXTENT = (0.005, 2.0)
#: A whole scene's (table, walls, the object) largest extent must stay under this (m).
SCENE_EXTENT_MAX = 20.0


def unit_scale(units: Optional[str], name: str = "units") -> float:
    """Metres per unit for ``units`` (``"m"``, ``"cm"``, ``"mm"``; None means metres)."""
    if units is None:
        return 1.0
    if not isinstance(units, str) or units not in UNITS:
        raise ValueError(f"{name}: expected one of {', '.join(UNITS)}, got {units!r}")
    return UNITS[units]


def _likely_unit(extent_m: float, scale: float) -> Optional[str]:
    """The unit that would bring ``extent_m`` (read with ``scale`` metres per unit) closest to a
    graspable size (20 cm, in log scale), if that is a different unit."""
    raw = extent_m / scale
    best = min(UNITS, key=lambda u: abs(math.log10(max(raw * UNITS[u], 1e-300) / 0.2)))
    return None if UNITS[best] == scale else best


def check_extent(points: np.ndarray, what: str, units: Optional[str] = None,
                 lo: float = OBJECT_EXTENT[0], hi: float = OBJECT_EXTENT[1]) -> float:
    """The largest axis-aligned extent (m) of ``points`` (N, 3), already scaled to metres; a
    ValueError naming the likely unit and the fix if it is outside [lo, hi]."""
    P = np.asarray(points, dtype=np.float64)
    if len(P) == 0:
        return 0.0
    extent = float(np.max(P.max(axis=0) - P.min(axis=0)))
    if lo <= extent <= hi:
        return extent
    scale = unit_scale(units)
    given = units or "m"
    guess = _likely_unit(extent, scale)
    side = "over" if extent > hi else "under"
    bound = f"{hi:g} m" if extent > hi else f"{lo * 1000:g} mm"
    hint = (f"it looks like {guess}: pass --units {guess} (units='{guess}' in the API)" if guess else
            "check that it is the right file")
    raise ValueError(f"{what}: extent {extent:.4g} m read in {given} is {side} {bound}; {hint}")
