"""The built-in procedural object library: real-world sizes in metres, no downloads.

Names:

* the thesis's known-object set: ``cube`` (6 cm), ``cylinder`` (r 3.5 cm, h 12 cm), ``mug`` (the
  default mug of the demo and benchmarks, about 2,000 triangles), ``mug2`` (taller, tapered, square
  handle), ``pitcher`` (bulged body, large handle);
* categories with shape variation: ``mug/0`` ... ``mug/6``, ``bottle/0`` ... ``bottle/10``,
  ``hammer/0`` ... ``hammer/3``, ``knife/0`` and ``knife/1``.

Every object is a deterministic function of a parameter dict (:func:`generate`); category members
draw theirs from a generator seeded by the category and the member index (:func:`sample_params`),
so ``mug/3`` is the same mesh everywhere. Any non-negative index is accepted (``bottle/25``);
:func:`list_objects` lists the members the thesis's experiments use.

Object frames: z up, the object standing (or lying) on z = 0 in its natural rest pose, centred
about the z axis (cylindrical bodies) or with the handle along +x (hammers, knives).

Meshes are closed and wound outward. Parts (a mug's body and handle, a hammer's handle and head) are
joined with a mesh boolean union when ``manifold3d`` is installed (through ``trimesh.boolean``);
without it the parts are built to touch without overlapping, so the mesh is watertight per
component and its mass properties are still those of the solid.
"""
from __future__ import annotations

import re
from typing import Callable, Dict, List, Optional

import numpy as np

from .mesh_io import DEFAULT_DENSITY, ObjectModel
from .parts import part_labels
from .primitives import _combine, _rotate, boolean_available, box, prism, revolve, sweep

_RX90 = np.array([[1, 0, 0], [0, 0, -1], [0, 1, 0]], dtype=np.float64)   # +90 deg about x: z -> -y

# --------------------------------------------------------------------------------------------
# shapes
# --------------------------------------------------------------------------------------------


def _cube(p):
    h = p["size"] / 2
    return box([0, 0, h], [h, h, h])


def _cylinder(p):
    R, H = p["radius"], p["height"]
    return revolve([[0, 0], [R, 0], [R, H], [0, H]], p["segments"])


def _arc(r0, r1, z0, z1, n, convex_out=True):
    """Quarter-ellipse fillet points from (r0, z0) to (r1, z1), excluding the first point."""
    s = np.linspace(0, np.pi / 2, n + 1)[1:]
    if convex_out:   # bottom-outer corner: starts horizontal, ends vertical
        return np.column_stack([r0 + (r1 - r0) * np.sin(s), z1 - (z1 - z0) * np.cos(s)])
    return np.column_stack([r1 - (r1 - r0) * np.cos(s), z0 + (z1 - z0) * np.sin(s)])


def _vessel_profile(p):
    """(r, z) profile of a hollow vessel (mug, pitcher): outer wall, rounded rim, inner wall.

    The outer radius follows r(u) = r_bottom + (r_top - r_bottom) u + bulge sin(pi u) for
    u = z / height. The inner wall is the outer wall moved in by the wall thickness; the cavity's
    floor is at the base thickness.
    """
    H, t, tb, f = p["height"], p["wall"], p["base"], p["fillet"]
    nw = p["wall_points"]

    def r_out(z):
        u = np.clip(z / H, 0, 1)
        return p["r_bottom"] + (p["r_top"] - p["r_bottom"]) * u + p["bulge"] * np.sin(np.pi * u)

    pts = [[0.0, 0.0], [r_out(0.0) - f, 0.0]]
    pts += _arc(r_out(0.0) - f, r_out(f), 0.0, f, 2).tolist()
    for z in np.linspace(f, H - t / 2, nw)[1:]:
        pts.append([r_out(z), z])
    # rounded rim: a half circle of diameter t over the wall's top
    rc = r_out(H - t / 2) - t / 2
    for a in np.linspace(0, np.pi, 5)[1:-1]:
        pts.append([rc + t / 2 * np.cos(a), H - t / 2 + t / 2 * np.sin(a)])
    for z in np.linspace(H - t / 2, tb + f / 2, nw):
        pts.append([r_out(z) - t, z])
    pts.append([r_out(tb) - t - f / 2, tb])
    pts.append([0.0, tb])
    return np.array(pts), r_out


def _handle_path(p, r_out, sink: float):
    """Centre line of a handle in the xz plane on the +x side of a body of outer radius r_out(z).

    Ends meet the body horizontally at z_low and z_high. ``sink`` > 0 pushes the ends into the
    wall (for a boolean union); sink = 0 puts the end caps on the wall's surface.
    """
    z0, z1 = p["handle_z"]
    zc, az = (z0 + z1) / 2, (z1 - z0) / 2
    e = p["handle_squareness"]          # 1: ellipse, > 1: squarer
    phi = np.linspace(np.pi / 2, -np.pi / 2, p["handle_points"])
    c, s = np.cos(phi), np.sin(phi)
    cx = np.sign(c) * np.abs(c) ** (1 / e)
    sz = np.sign(s) * np.abs(s) ** (1 / e)
    z = zc + az * sz
    x = r_out(z) + p["handle_reach"] * cx
    path = np.column_stack([x, np.zeros_like(x), z])
    # extend both ends horizontally into the wall by `sink`
    path[0, 0] -= sink
    path[-1, 0] -= sink
    return path


def _project_end_onto_wall(V, idx, r_out):
    """Move the given vertices along x onto the body's outer surface (x^2 + y^2 = r_out(z)^2)."""
    y, z = V[idx, 1], V[idx, 2]
    V[idx, 0] = np.sqrt(np.maximum(r_out(z) ** 2 - y ** 2, 0.0))


def _vessel(p, use_boolean):
    prof, r_out = _vessel_profile(p)
    body = revolve(prof, p["segments"])
    sink = p["wall"] * 0.6 if use_boolean else 0.0
    path = _handle_path(p, r_out, sink)
    m = p["handle_segments"]
    # cross-section: width across the loop's plane (y), thickness in it
    hv, hf = sweep(path, (p["handle_width"] / 2, p["handle_thickness"] / 2), m,
                   normal_hint=[0.0, 1.0, 0.0])
    if not use_boolean:
        K = len(path)
        first = np.r_[np.arange(m), K * m]
        last = np.r_[(K - 1) * m + np.arange(m), K * m + 1]
        _project_end_onto_wall(hv, first, r_out)
        _project_end_onto_wall(hv, last, r_out)
    return _combine([body, (hv, hf)], use_boolean)


def _bottle(p):
    R, H = p["radius"], p["height"]
    rn, hn, hc = p["neck_radius"], p["neck_height"], p["cap_height"]
    z_sh1 = H - hn - hc                  # top of the shoulder
    z_sh0 = z_sh1 - p["shoulder_height"]  # bottom of the shoulder
    f = p["fillet"]
    pts = [[0.0, 0.0], [R - f, 0.0]] + _arc(R - f, R, 0.0, f, 3).tolist()
    for z in np.linspace(f, z_sh0, 8)[1:]:
        u = (z - f) / (z_sh0 - f)
        pts.append([R - p["waist"] * np.sin(np.pi * u) ** 2, z])
    for u in np.linspace(0, 1, 9)[1:]:
        # cosine shoulder from R down to the neck radius
        pts.append([rn + (R - rn) * 0.5 * (1 + np.cos(np.pi * u)), z_sh0 + u * (z_sh1 - z_sh0)])
    pts.append([rn, H - hc])
    rc = rn + p["cap_lip"]
    pts += [[rc, H - hc], [rc, H - 0.002], [rc - 0.002, H], [0.0, H]]
    return revolve(pts, p["segments"])


def _hammer(p, use_boolean):
    L, hw = p["length"], p["head_width"]
    a, b = p["handle_radii"]             # handle semi-axes: y (across), z (up)
    hl, hh = p["head_length"], p["head_height"]
    zc = hh / 2                          # the hammer lies on its head; handle axis at head centre
    x_head = L - hw
    x_end = x_head + (hw / 2 if use_boolean else 0.0)
    path = np.column_stack([np.linspace(0.0, x_end, p["handle_points"]),
                            np.zeros(p["handle_points"]), np.full(p["handle_points"], zc)])
    handle = sweep(path, (b, a), p["handle_segments"], normal_hint=[0.0, 0.0, 1.0])
    if p["head_shape"] == "box":
        head = box([x_head + hw / 2, 0.0, zc], [hw / 2, hl / 2, hh / 2])
    else:  # round head: a cylinder along y, lying on the table
        hv, hf = revolve([[0, 0], [hw / 2, 0], [hw / 2, hl], [0, hl]], 32)
        hv = _rotate(hv, _RX90, [x_head + hw / 2, hl / 2, zc])
        head = (hv, hf)
        if not use_boolean:
            # end cap of the handle onto the round head's surface (touching, no overlap)
            hv2, m = handle[0].copy(), p["handle_segments"]
            K = p["handle_points"]
            idx = np.r_[(K - 1) * m + np.arange(m), K * m + 1]
            dz = hv2[idx, 2] - zc
            hv2[idx, 0] = x_head + hw / 2 - np.sqrt(np.maximum((hw / 2) ** 2 - dz ** 2, 0.0))
            handle = (hv2, handle[1])
    return _combine([handle, head], use_boolean)


def _knife(p, use_boolean):
    Lh, Lb, wb, tb = p["handle_length"], p["blade_length"], p["blade_width"], p["blade_thickness"]
    a, b = p["handle_radii"]
    zc = b                               # the knife lies on its handle
    path = np.column_stack([np.linspace(0.0, Lh, 12), np.zeros(12), np.full(12, zc)])
    handle = sweep(path, (b, a), p["handle_segments"], normal_hint=[0.0, 0.0, 1.0])
    # blade outline (convex): straight spine at +wb/2, edge curving up to the tip
    s = np.linspace(0, 1, 12)
    tip_y = wb / 2 - p["tip_drop"]
    edge = np.column_stack([Lh + Lb * s, -wb / 2 + (tip_y + wb / 2) * s ** 2.5])
    poly = np.vstack([[[Lh, -wb / 2]], edge[1:], [[Lh + Lb * 0.97, wb / 2]], [[Lh, wb / 2]]])
    blade = prism(poly, zc - tb / 2, zc + tb / 2)
    parts = [handle, blade]
    if use_boolean:  # a tang inside the handle joins the blade to it
        parts.append(box([Lh - 0.01, 0.0, zc], [0.012, 0.7 * a, tb / 2]))
    return _combine(parts, use_boolean)


# --------------------------------------------------------------------------------------------
# parameters
# --------------------------------------------------------------------------------------------

_MUG_BASE = dict(kind="vessel", r_bottom=0.040, r_top=0.040, bulge=0.0, height=0.095, wall=0.004,
                 base=0.006, fillet=0.004, wall_points=5, segments=48, handle_z=(0.022, 0.078),
                 handle_reach=0.030, handle_squareness=1.0, handle_thickness=0.010,
                 handle_width=0.014, handle_points=30, handle_segments=12, density=2300.0)

_FIXED: Dict[str, dict] = {
    "cube": dict(kind="cube", size=0.06, density=700.0),
    "cylinder": dict(kind="cylinder", radius=0.035, height=0.12, segments=64, density=700.0),
    "mug": dict(_MUG_BASE),
    "mug2": dict(_MUG_BASE, r_bottom=0.034, r_top=0.043, height=0.115, wall=0.0045,
                 handle_z=(0.025, 0.095), handle_reach=0.028, handle_squareness=2.5,
                 handle_thickness=0.008, handle_width=0.018, handle_points=36),
    "pitcher": dict(_MUG_BASE, r_bottom=0.060, r_top=0.058, bulge=0.012, height=0.20, wall=0.005,
                    base=0.008, fillet=0.008, wall_points=9, segments=56, handle_z=(0.05, 0.175),
                    handle_reach=0.045, handle_squareness=1.4, handle_thickness=0.014,
                    handle_width=0.020, handle_points=36, density=2300.0),
}

#: Members per category listed by list_objects (any non-negative index can be generated).
CATEGORY_SIZES = {"mug": 7, "bottle": 11, "hammer": 4, "knife": 2}
_CATEGORY_SEEDS = {"mug": 1101, "bottle": 1102, "hammer": 1103, "knife": 1104}


def _sample_mug(rng):
    r = rng.uniform(0.035, 0.050)
    h = rng.uniform(0.080, 0.120)
    taper = rng.uniform(-0.15, 0.15)          # r_top / r_bottom - 1 (symmetric about r)
    hz0 = h * rng.uniform(0.18, 0.30)
    hz1 = h * rng.uniform(0.72, 0.85)
    return dict(_MUG_BASE, r_bottom=r * (1 - taper / 2), r_top=r * (1 + taper / 2),
                bulge=rng.uniform(0.0, 0.006), height=h, wall=rng.uniform(0.003, 0.005),
                base=rng.uniform(0.005, 0.008), handle_z=(hz0, hz1),
                handle_reach=rng.uniform(0.022, 0.035), handle_squareness=rng.uniform(1.0, 2.5),
                handle_thickness=rng.uniform(0.008, 0.012), handle_width=rng.uniform(0.010, 0.018))


def _sample_bottle(rng):
    R = rng.uniform(0.030, 0.045)
    H = rng.uniform(0.18, 0.30)
    rn = rng.uniform(0.011, 0.016)
    return dict(kind="bottle", radius=R, height=H, neck_radius=rn,
                neck_height=rng.uniform(0.02, 0.05), cap_height=rng.uniform(0.012, 0.02),
                cap_lip=rng.uniform(0.0005, 0.002), shoulder_height=H * rng.uniform(0.12, 0.3),
                waist=R * rng.choice([0.0, rng.uniform(0.05, 0.15)]), fillet=rng.uniform(0.003, 0.008),
                segments=40, density=1000.0)


def _sample_hammer(rng):
    hw = rng.uniform(0.022, 0.032)
    return dict(kind="hammer", length=rng.uniform(0.25, 0.35), head_width=hw,
                head_length=rng.uniform(0.09, 0.13), head_height=hw * rng.uniform(1.0, 1.3),
                head_shape=str(rng.choice(["box", "round"])),
                handle_radii=(rng.uniform(0.010, 0.014), rng.uniform(0.007, 0.010)),
                handle_points=10, handle_segments=16, density=3000.0)


def _sample_knife(rng):
    return dict(kind="knife", handle_length=rng.uniform(0.10, 0.13),
                blade_length=rng.uniform(0.12, 0.20), blade_width=rng.uniform(0.025, 0.040),
                blade_thickness=rng.uniform(0.0015, 0.0025), tip_drop=rng.uniform(0.002, 0.01),
                handle_radii=(rng.uniform(0.010, 0.013), rng.uniform(0.007, 0.009)),
                handle_segments=16, density=2000.0)


_SAMPLERS: Dict[str, Callable] = {"mug": _sample_mug, "bottle": _sample_bottle,
                                  "hammer": _sample_hammer, "knife": _sample_knife}

# Member 0 of the categories that share a fixed object are otherwise independent samples.


def sample_params(category_name: str, index: int) -> dict:
    """The parameter dict of member ``index`` of a category (deterministic)."""
    if category_name not in _SAMPLERS:
        raise ValueError(f"unknown category '{category_name}' (categories: {', '.join(_SAMPLERS)})")
    if int(index) != index or index < 0:
        raise ValueError(f"index must be a non-negative integer, got {index!r}")
    rng = np.random.default_rng([_CATEGORY_SEEDS[category_name], int(index)])
    return _SAMPLERS[category_name](rng)


def generate(params: dict, name: str = "object", use_boolean: Optional[bool] = None,
             density: Optional[float] = None) -> ObjectModel:
    """Build an object from its parameter dict (see :func:`object_params` for examples).

    Args:
        params: shape parameters with a ``kind`` of ``cube``, ``cylinder``, ``vessel``,
            ``bottle``, ``hammer`` or ``knife`` (lengths in metres) and a ``density``.
        name: the object's name.
        use_boolean: join parts with a boolean union (default: when manifold3d is installed).
        density: overrides ``params["density"]`` (kg/m^3).
    """
    if use_boolean is None:
        use_boolean = boolean_available()
    kind = params.get("kind")
    if kind == "cube":
        V, F = _cube(params)
    elif kind == "cylinder":
        V, F = _cylinder(params)
    elif kind == "vessel":
        V, F = _vessel(params, use_boolean)
    elif kind == "bottle":
        V, F = _bottle(params)
    elif kind == "hammer":
        V, F = _hammer(params, use_boolean)
    elif kind == "knife":
        V, F = _knife(params, use_boolean)
    else:
        raise ValueError(f"params['kind'] must be one of cube, cylinder, vessel, bottle, hammer, "
                         f"knife; got {kind!r}")
    d = params.get("density", DEFAULT_DENSITY) if density is None else density
    parts, part_names = part_labels(params, V, F)
    return ObjectModel(name, V, F.astype(np.int32), d, source=f"builtin:{name}", params=dict(params),
                       parts=parts, part_names=part_names)


_NAME_RE = re.compile(r"^([a-z]+)/(\d+)$")


def list_objects() -> List[str]:
    """Names of the built-in objects: the known-object set, then each category's members."""
    names = list(_FIXED)
    for c, n in CATEGORY_SIZES.items():
        names += [f"{c}/{i}" for i in range(n)]
    return names


def categories() -> List[str]:
    """Names of the shape categories (``mug``, ``bottle``, ``hammer``, ``knife``)."""
    return list(CATEGORY_SIZES)


def category(name: str) -> List[str]:
    """The listed members of a category, e.g. ``category("bottle")`` -> ``["bottle/0", ...]``."""
    if name not in CATEGORY_SIZES:
        raise ValueError(f"unknown category '{name}' (categories: {', '.join(CATEGORY_SIZES)})")
    return [f"{name}/{i}" for i in range(CATEGORY_SIZES[name])]


def object_params(name: str) -> Optional[dict]:
    """The parameter dict of a built-in name, or None if ``name`` is not a built-in."""
    if name in _FIXED:
        return dict(_FIXED[name])
    m = _NAME_RE.match(name)
    if m and m.group(1) in _SAMPLERS:
        return sample_params(m.group(1), int(m.group(2)))
    return None


def builtin(name: str, density: Optional[float] = None,
            use_boolean: Optional[bool] = None) -> ObjectModel:
    """A built-in object by name (``mug``, ``mug/3``, ``bottle/7``, ...)."""
    p = object_params(name)
    if p is None:
        raise ValueError(f"unknown built-in object '{name}'{_did_you_mean(name)}; available: {', '.join(list_objects())}")
    _warn_if_new_member(name)
    return generate(p, name=name, use_boolean=use_boolean, density=density)


class NewMemberWarning(UserWarning):
    """A category member beyond the library's listed ones: a new shape generated from its seed
    (nothing is cached for it yet: its models are built on first use)."""


def _warn_if_new_member(name: str) -> None:
    import warnings

    m = _NAME_RE.match(name)
    if m and m.group(1) in CATEGORY_SIZES and int(m.group(2)) >= CATEGORY_SIZES[m.group(1)]:
        cat, n = m.group(1), CATEGORY_SIZES[m.group(1)]
        warnings.warn(f"{name}: not one of the library's {cat}/0 ... {cat}/{n - 1}; a new {cat} generated from its "
                      f"seed (its models, if needed, are built on first use: minutes)", NewMemberWarning, stacklevel=3)


def _did_you_mean(name: str) -> str:
    """The hint " (did you mean 'mug'?)" for a near miss of a built-in name (difflib), else ""."""
    import difflib

    close = difflib.get_close_matches(name, list_objects(), n=1, cutoff=0.6)
    return f" (did you mean '{close[0]}'?)" if close else ""


def load_object(name_or_path, density: Optional[float] = None, units: Optional[str] = None,
                mass: Optional[float] = None) -> ObjectModel:
    """A built-in object by name (``"mug"``, ``"mug/3"``, ``"bottle/7"``), a mesh file by path, or
    an in-memory ``trimesh.Trimesh`` / Open3D ``TriangleMesh``.

    Args:
        name_or_path: a built-in name (see :func:`list_objects`; category members accept any
            non-negative index), the path of an OBJ / STL / PLY file, or a mesh object.
        density: kg/m^3; default: the built-in's own (ceramic mugs 2300, bottles 1000, ...) or
            :data:`~bayesgrasp.objects.mesh_io.DEFAULT_DENSITY` for files.
        units: the length unit of a file or mesh object (``"m"`` default, ``"cm"``, ``"mm"``); an
            extent outside 5 mm .. 2 m is refused with the likely unit named.
        mass: kg (a scale's reading): sets the density to mass / volume (not with ``density``).

    Raises:
        ValueError: neither a built-in name nor an existing file (the message lists the names), or
            the file is not a valid mesh.
        FileNotFoundError: a path-like argument (with a directory or a mesh extension) that does
            not exist.
    """
    import os
    from pathlib import Path

    from .mesh_io import MESH_EXTENSIONS, check_mass_or_density, load_mesh, mesh_from_object

    check_mass_or_density(mass, density)
    if isinstance(name_or_path, ObjectModel):
        return name_or_path if mass is None else name_or_path.with_mass(mass)
    if hasattr(name_or_path, "vertices") and (hasattr(name_or_path, "faces") or hasattr(name_or_path, "triangles")) \
            or hasattr(name_or_path, "to_legacy"):
        return mesh_from_object(name_or_path, density=density, units=units, mass=mass)
    if not isinstance(name_or_path, (str, os.PathLike)):
        raise ValueError(f"name_or_path must be a built-in name or a file path, got "
                         f"{type(name_or_path).__name__}")
    s = os.fspath(name_or_path)
    if isinstance(name_or_path, str) and object_params(s) is not None:
        obj = builtin(s, density=density)
        return obj if mass is None else obj.with_mass(mass)
    p = Path(s)
    if p.is_file():
        return load_mesh(p, density=density, units=units, mass=mass)
    if p.suffix.lower() in MESH_EXTENSIONS or os.sep in s and not _NAME_RE.match(s):
        raise FileNotFoundError(f"mesh file not found: '{s}' (and it is not a built-in object name)")
    raise ValueError(f"'{s}' is neither a built-in object nor an existing file{_did_you_mean(s)}; built-in objects: "
                     f"{', '.join(list_objects())} (category members accept any index, e.g. mug/12)")
