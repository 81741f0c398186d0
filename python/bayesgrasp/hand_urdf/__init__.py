"""Hands from a URDF and a sidecar file (issue 31).

A URDF gives the links, their collision geometry, the joints with their axes, limits and mimic
couplings. The sidecar (``NAME.hand.json`` beside ``NAME.urdf``) says what a URDF cannot: the
palm frame and approach axis, the spread joint, which joints close each finger and how (the
closing scheme), each joint's motor torque with its source, and the joints the "fingers read"
measurement uses. :func:`hand_json_from_urdf` turns the pair into the text of a hand file (the
format of ``barrett_bh8.json``), so a URDF hand runs through the same C++ model as any other.

What the conversion needs of the URDF (each is checked and refused in one line naming it):

* every finger is a planar chain: its phalanx joints are revolute with parallel axes lying in
  the palm plane, or (a thumb) in a plane rolled about the finger's outward direction; a
  positive angle closes the finger (turns it towards the approach axis); or
  it is a jaw: one prismatic joint in the palm plane that opens with a positive value (the
  convention of two-finger grippers' URDFs); a mimic between two fingers' first joints (a
  gripper's second jaw) is dropped: each finger closes on its own;
* a finger's spread joint (if any) is a revolute joint about the approach axis between the palm
  and the finger's first phalanx joint: the sidecar's spread joint or a mimic of it;
* every other link hangs from the palm or a phalanx by fixed joints (it joins that body), or
  from one of the sidecar's ``passive_joints`` (a four-bar's other bar, a <mimic> of a finger's
  first joint): those links' collision geometry is left out;
* the closing scheme: ``breakaway`` (the BH8) needs every coupling's multiplier >= 0;
  ``linkage`` takes any sign (a 2F-85's pad joint, multiplier -1, stays parallel) and a contact
  stops the whole finger; ``independent`` (one motor per joint) takes no mimics;
* the sidecar's ``held_joints`` are read as fixed joints at their values (abduction, a thumb's
  opposition at a preshape);
* the tree has no loop (a link that is the child of two joints).

Collision shapes: boxes (axis-aligned with the link after the conversion, else their 8 corners
as a convex shape), spheres, cylinders (a cylinder with a sphere of its radius at each end cap
is one capsule; else a 32-sided prism), and meshes (their convex hull). Units: metres and radians.
"""
from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Optional

import numpy as np

from .urdf import _AXIS_TOL, _TOL, HandFileError, _mesh_points, _origin, _pose, _rpy, _shapes_of, _transform, _Tree, _unit

__all__ = ["HandFileError", "hand_json_from_urdf", "sidecar_path"]

SIDECAR_SUFFIX = ".hand.json"


def sidecar_path(urdf: Path) -> Path:
    """The sidecar that goes with a URDF: ``NAME.hand.json`` beside ``NAME.urdf``."""
    return urdf.with_name(urdf.stem + SIDECAR_SUFFIX)


# ---------------------------------------------------------------- reading the two files ----

def _load_sidecar(path: Path) -> dict:
    import jsonschema

    try:
        data = json.loads(path.read_text())
    except OSError as e:
        raise HandFileError(f"{path}: cannot read the sidecar ({e.strerror or e})") from None
    except json.JSONDecodeError as e:
        raise HandFileError(f"{path}: not valid JSON ({e})") from None
    schema = json.loads((Path(__file__).parent.parent / "data" / "schema" / "hand_sidecar.schema.json").read_text())
    errors = sorted(jsonschema.Draft202012Validator(schema).iter_errors(data), key=lambda e: list(e.absolute_path))
    if errors:
        e = errors[0]
        where = ".".join(str(p) for p in e.absolute_path) or "top level"
        keys = [s.get("required", [None])[0] for s in e.validator_value] if e.validator == "oneOf" else []
        if keys and all(keys):   # a choice of keys: say which
            raise HandFileError(f"{path}: {where}: needs exactly one of {', '.join(keys)}")
        raise HandFileError(f"{path}: {where}: {e.message}")
    return data


def _declare_prefixes(text: bytes) -> bytes:
    """``text`` with every namespace prefix it uses but does not declare (a simulator's
    extension such as ``<drake:...>``, which URDF readers skip) declared on its root element, so
    that a strict XML parser reads it; other text is left as it is."""
    import re

    used = set(re.findall(rb"</?([A-Za-z_][\w.-]*):[A-Za-z_]", text)) | set(re.findall(rb"\s([A-Za-z_][\w.-]*):[\w.-]+\s*=", text))
    declared = set(re.findall(rb"xmlns:([A-Za-z_][\w.-]*)\s*=", text))
    missing = sorted(used - declared - {b"xml", b"xmlns"})
    if not missing:
        return text
    decl = b"".join(b' xmlns:%s="urn:undeclared:%s"' % (p, p) for p in missing)
    return re.sub(rb"<robot\b", b"<robot" + decl, text, count=1)


def _load_urdf(path: Path):
    import io

    import yourdfpy
    from lxml import etree

    try:
        text = _declare_prefixes(path.read_bytes())
    except OSError as e:
        raise HandFileError(f"{path}: cannot read the URDF ({e})") from None
    try:  # strict XML first: yourdfpy recovers from broken XML with a guess
        root = etree.fromstring(text)
    except etree.XMLSyntaxError as e:
        raise HandFileError(f"{path}: not a readable URDF (XML: {e})") from None
    if root.tag != "robot":
        raise HandFileError(f"{path}: not a readable URDF (its root element is <{root.tag}>, not <robot>)")
    try:
        robot = yourdfpy.URDF.load(io.BytesIO(text), build_scene_graph=False, load_meshes=False,
                                   build_collision_scene_graph=False, load_collision_meshes=False)
    except OSError as e:
        raise HandFileError(f"{path}: cannot read the URDF ({e.strerror or e})") from None
    except Exception as e:  # noqa: BLE001 - lxml and yourdfpy raise many kinds; one line names the file
        raise HandFileError(f"{path}: not a readable URDF ({type(e).__name__}: {e})") from None
    return robot.robot


# ---------------------------------------------------------------- the conversion ----

def hand_json_from_urdf(urdf: str | Path, sidecar: Optional[str | Path] = None, with_joint_map: bool = False):
    """The hand-file text (JSON) of a URDF hand and its sidecar (default: ``NAME.hand.json``
    beside ``NAME.urdf``); with ``with_joint_map`` also the URDF's joints as functions of ours
    (see ``_Converter._joint_map``). Raises :class:`HandFileError` naming the file and what is wrong."""
    urdf = Path(urdf)
    side_path = Path(sidecar) if sidecar is not None else sidecar_path(urdf)
    if not urdf.is_file():
        raise HandFileError(f"{urdf}: URDF file not found")
    if not side_path.is_file():
        raise HandFileError(f"{urdf}: its sidecar {side_path.name} is missing (palm frame, spread, fingers, "
                            "actuation; see the README, 'Bring your own hand')")
    side = _load_sidecar(side_path)
    named = (side_path.parent / side["urdf"]).resolve()
    if named != urdf.resolve():
        raise HandFileError(f"{side_path}: urdf: names {side['urdf']}, but it was loaded with {urdf}")
    tree = _Tree(_load_urdf(urdf), str(urdf))
    if side.get("root") is not None:
        tree = tree.below(side["root"], f"{side_path}: root")
    tree.hold(side.get("held_joints", {}), f"{side_path}: held_joints")
    conv = _Converter(tree, side, str(side_path), urdf.parent)
    text = json.dumps(conv.hand(), indent=1)
    return text if not with_joint_map else (text, conv.joint_map)


class _Converter:
    def __init__(self, tree: _Tree, side: dict, where: str, urdf_dir: Path):
        self.tree, self.side, self.where, self.urdf_dir = tree, side, where, urdf_dir
        palm = side["palm"]
        if palm["link"] not in tree.links:
            raise HandFileError(f"{where}: palm.link names link '{palm['link']}', which the URDF does not have")
        # hand frame H in the root frame: palm link's zero pose times the sidecar's offset
        self.H = tree.zero_pose(palm["link"]) @ _pose(_rpy(palm["rpy"]), palm["xyz"])
        self.Hinv = np.linalg.inv(self.H)
        self.body_of: dict[str, str] = {}   # URDF link -> our link name
        self.frames: dict[str, np.ndarray] = {}  # our link name -> its frame in the hand frame (URDF zero)

    def _in_hand(self, T_root: np.ndarray) -> np.ndarray:
        return self.Hinv @ T_root

    def _fail(self, msg: str):
        raise HandFileError(f"{self.where}: {msg}")

    # -- the spread --
    def _spread(self) -> tuple[dict, Optional[object]]:
        sp = self.side["spread"]
        if sp is None:
            return {"lower_deg": 0.0, "upper_deg": 0.0, "default_deg": 0.0}, None
        j = self.tree.joint(sp["joint"], "spread.joint")
        if j.type != "revolute" or j.limit is None:
            self._fail(f"spread.joint '{j.name}' must be a revolute joint with limits (it is {j.type})")
        lo, hi = math.degrees(j.limit.lower), math.degrees(j.limit.upper)
        if not lo <= sp["default_deg"] <= hi:
            self._fail(f"spread.default_deg {sp['default_deg']} lies outside the joint's limits [{lo:.6g}, {hi:.6g}]")
        return {"lower_deg": lo, "upper_deg": hi, "default_deg": float(sp["default_deg"])}, j

    # -- one finger --
    def _finger(self, fi: int, spec: dict, spread_joint, joint0: int) -> dict:
        w = f"fingers[{fi}]"
        joints = [self.tree.joint(p["joint"], f"{w}.phalanges[{k}].joint") for k, p in enumerate(spec["phalanges"])]
        if joints[0].type == "prismatic":
            return self._jaw(fi, spec, joints, joint0)
        for k, j in enumerate(joints):
            if j.type not in ("revolute", "continuous"):
                self._fail(f"{w}.phalanges[{k}]: joint '{j.name}' is {j.type}; a finger's joints must be revolute "
                           "(or one prismatic joint: a jaw)")
            if "torque_nm" not in spec["phalanges"][k]:
                self._fail(f"{w}.phalanges[{k}]: a revolute joint's motor is given as torque_nm")
        # the chain from the palm to the first joint: fixed joints and at most a spread joint
        above = self.tree.chain(joints[0].parent)
        spread_here = [j for j in above if self.tree.moves(j)]
        palm_chain = self.tree.chain(self.side["palm"]["link"])
        spread_here = [j for j in spread_here if j not in palm_chain]
        if len(spread_here) > 1:
            self._fail(f"{w}: joints {[j.name for j in spread_here]} move the finger's base; at most one spread joint")
        # each phalanx joint's child must hang from the previous one through fixed joints only
        for k in range(1, len(joints)):
            up = self.tree.chain(joints[k].parent)
            if joints[k - 1] not in up or any(self.tree.moves(j) for j in up[up.index(joints[k - 1]) + 1:]):
                self._fail(f"{w}: joint '{joints[k].name}' does not follow '{joints[k - 1].name}' through fixed joints")
        z = np.array([0.0, 0.0, 1.0])
        T0 = [self._in_hand(self.tree.zero_pose(j.child)) for j in joints]     # child frames = joint frames at 0
        pos = [T[:3, 3] for T in T0]
        axes = [_unit(T[:3, :3] @ np.asarray(j.axis if j.axis is not None else (1, 0, 0), dtype=float))
                for T, j in zip(T0, joints)]
        a = axes[0]
        roll = 0.0
        if abs(a @ z) > _AXIS_TOL:
            # a flexion axis out of the palm plane (a thumb): the finger's plane turned about its
            # outward direction d by roll, a = cos(roll) (d x z) - sin(roll) z
            horizontal = np.linalg.norm(a - (a @ z) * z)
            if horizontal < 0.1:
                self._fail(f"{w}: joint '{joints[0].name}' turns about the approach axis (a spread or abduction joint; "
                           "name it as the spread, or hold it with held_joints)")
            roll = math.atan2(-(a @ z), horizontal)
        a0 = _unit(a - (a @ z) * z)          # in the palm plane (within the tolerance: a itself, projected)
        a = a0 if roll == 0.0 else a
        for k, ak in enumerate(axes[1:], 1):
            if ak @ a < 1.0 - _AXIS_TOL:
                self._fail(f"{w}: joint '{joints[k].name}' axis is not parallel to '{joints[0].name}''s "
                           "(a finger is a planar chain; a positive angle closes every joint)")
        d = np.cross(z, a0)  # outward direction: a positive angle turns d towards +z (a0 = d x z)
        up = math.cos(roll) * z + math.sin(roll) * a0   # the finger plane's "up" (Theta = 90 deg)
        # the finger's base and spread
        if spread_here:
            sj = spread_here[0]
            Ts = self._in_hand(self.tree.zero_pose(sj.child))
            saxis = Ts[:3, :3] @ _unit(sj.axis if sj.axis is not None else (1, 0, 0))
            if abs(abs(saxis @ z) - 1.0) > _AXIS_TOL:
                self._fail(f"{w}: joint '{sj.name}' moves the finger's base but does not turn about the approach axis")
            if spread_joint is None:
                self._fail(f"{w}: joint '{sj.name}' moves the finger's base but the sidecar's spread is null")
            if sj.name == spread_joint.name:
                mult, off = 1.0, 0.0
            elif sj.mimic is not None and sj.mimic.joint == spread_joint.name:
                mult, off = float(sj.mimic.multiplier or 1.0), float(sj.mimic.offset or 0.0)
            else:
                self._fail(f"{w}: joint '{sj.name}' moves the finger's base but is neither the spread joint "
                           f"'{spread_joint.name}' nor a mimic of it")
            sign = float(np.sign(saxis @ z))
            base = Ts[:3, 3] + (pos[0][2] - Ts[2, 3]) * z
            spread_sign, yaw_offset = sign * mult, sign * off
            urdf_map = [(sj.name, 0, mult, off)]     # the URDF's value of this spread joint from our spread
        else:
            base, spread_sign, yaw_offset = pos[0].copy(), 0.0, 0.0
            urdf_map = []
        knuckle = float((pos[0] - base) @ d)
        if np.linalg.norm(pos[0] - base - knuckle * d) > _TOL or knuckle < -_TOL:
            self._fail(f"{w}: joint '{joints[0].name}' is not on the finger's outward line from its base "
                       f"(off by {np.linalg.norm(pos[0] - base - knuckle * d):.3g} m)")
        base_yaw = math.degrees(math.atan2(d[1], d[0])) + math.degrees(yaw_offset)  # mimic offset: yaw at spread 0
        # phalanx lengths and directions at URDF zero
        tip = _transform(T0[-1], np.asarray(spec["fingertip"], dtype=float)[None])[0]
        ends = pos[1:] + [tip]
        theta_prev, phalanges = 0.0, []
        driver = joints[0]
        lower0 = float(driver.limit.lower) if driver.limit is not None else 0.0
        frames = []
        for k, (j, p) in enumerate(zip(joints, spec["phalanges"])):
            v = ends[k] - pos[k]
            length = float(np.linalg.norm(v))
            if length < 1e-9:
                self._fail(f"{w}.phalanges[{k}]: joint '{j.name}' has zero length to the next joint or fingertip")
            x = v / length
            if abs(x @ a) > _AXIS_TOL:
                self._fail(f"{w}.phalanges[{k}]: link '{j.child}' does not lie in the finger's plane")
            if abs(x @ a) > _TOL:
                x = _unit(x - (x @ a) * a)
            theta = math.atan2(x @ up, x @ d)
            phi = theta - theta_prev  # our relative angle at the URDF's zero
            theta_prev = theta
            if j.limit is None or j.type == "continuous":
                self._fail(f"{w}.phalanges[{k}]: joint '{j.name}' needs limits")
            lo, hi = j.limit.lower + phi, j.limit.upper + phi
            # coupling while free: the driver runs from its lower limit at t = 0 with ratio 1
            if p["name"] == "knuckle":
                self._fail(f"{w}.phalanges[{k}]: name 'knuckle' is the finger's knuckle link (the body its spread "
                           "joint moves); name the phalanx otherwise")
            if "ratio" in p and self.side["closing"] != "independent":
                self._fail(f"{w}.phalanges[{k}]: a ratio is given only with closing 'independent' (otherwise the "
                           "URDF's <mimic> couples the joint)")
            if self.side["closing"] == "independent":
                if j.mimic is not None:
                    self._fail(f"{w}.phalanges[{k}]: joint '{j.name}' mimics '{j.mimic.joint}'; with closing "
                               "'independent' every phalanx has its own motor")
                # its own motor: open at the URDF's zero (within the limits), closing at the sidecar's speed
                ratio = float(p.get("ratio", 1.0))
                offset = phi + min(max(0.0, j.limit.lower), j.limit.upper)
            elif k == 0:
                ratio, offset = 1.0, lo
            elif (coupling := self._coupling(j, driver)) is not None:
                m, o = coupling
                if m < 0 and self.side["closing"] != "linkage":
                    self._fail(f"{w}.phalanges[{k}]: joint '{j.name}' turns against '{driver.name}' (mimic multiplier "
                               f"{m:g}), which closing '{self.side['closing']}' cannot do; a linkage that keeps a "
                               "pad parallel is \"closing\": \"linkage\" in the sidecar")
                ratio, offset = m, phi + m * lower0 + o
            else:
                self._fail(f"{w}.phalanges[{k}]: joint '{j.name}' is neither the finger's first joint nor a mimic "
                           f"of '{driver.name}' (the closing law needs the coupling)")
            frame = np.eye(4)
            frame[:3, 0], frame[:3, 1], frame[:3, 2], frame[:3, 3] = x, a, np.cross(x, a), pos[k]
            frames.append(frame)
            urdf_map.append((j.name, joint0 + k, 1.0, -phi))   # ours = the URDF's angle + phi
            phalanges.append({"name": p["name"], "joint": "revolute", "length": length, "lower_deg": math.degrees(lo),
                              "upper_deg": math.degrees(hi), "offset_deg": math.degrees(offset), "ratio": ratio,
                              "torque_nm": float(p["torque_nm"]), "link": j.child})
        knuckle_frame = np.eye(4)
        knuckle_frame[:3, 0], knuckle_frame[:3, 1], knuckle_frame[:3, 2], knuckle_frame[:3, 3] = d, a, np.cross(d, a), base
        return {"spec": spec, "joints": joints, "base": base, "base_yaw": base_yaw, "spread_sign": spread_sign,
                "roll": roll,
                "knuckle": max(knuckle, 0.0), "knuckle_frame": knuckle_frame, "phalanges": phalanges, "frames": frames,
                "spread_joint": spread_here[0] if spread_here else None, "first_q": joint0, "urdf_map": urdf_map}

    def _jaw(self, fi: int, spec: dict, joints: list, joint0: int) -> dict:
        """A parallel jaw: one prismatic joint whose positive direction opens the finger (the URDF
        convention of two-finger grippers), in the palm plane; its link points along the approach."""
        w = f"fingers[{fi}]"
        if len(joints) != 1:
            self._fail(f"{w}: a prismatic joint must be its finger's only phalanx (a jaw)")
        j, p = joints[0], spec["phalanges"][0]
        if "force_n" not in p:
            self._fail(f"{w}.phalanges[0]: a prismatic joint's motor is given as force_n")
        if j.limit is None:
            self._fail(f"{w}.phalanges[0]: joint '{j.name}' needs limits")
        z = np.array([0.0, 0.0, 1.0])
        T0 = self._in_hand(self.tree.zero_pose(j.child))
        d = _unit(T0[:3, :3] @ np.asarray(j.axis if j.axis is not None else (1, 0, 0), dtype=float))
        if abs(d @ z) > _AXIS_TOL:
            self._fail(f"{w}: joint '{j.name}' does not slide in the palm plane (its axis's z in the hand frame is "
                       f"{d @ z:.3g}; up to {_AXIS_TOL:g} is taken as in it)")
        if abs(d @ z) > _TOL:
            d = _unit(d - (d @ z) * z)
        for above in self.tree.chain(j.parent):
            if self.tree.moves(above) and above not in self.tree.chain(self.side["palm"]["link"]):
                self._fail(f"{w}: joint '{above.name}' moves the jaw's base; a jaw hangs from the palm by fixed joints")
        pos = T0[:3, 3]
        tip = _transform(T0, np.asarray(spec["fingertip"], dtype=float)[None])[0]
        length = float((tip - pos) @ z)
        if length <= 1e-9:
            self._fail(f"{w}: the fingertip is not beyond the jaw's joint along the approach")
        lo, hi = float(j.limit.lower), float(j.limit.upper)
        # our travel inwards q = upper - q_urdf; at the URDF's zero the joint sits at pos
        a = np.cross(d, z)
        frame = np.eye(4)
        frame[:3, 0], frame[:3, 1], frame[:3, 2], frame[:3, 3] = z, a, d, pos
        phalanx = {"name": p["name"], "joint": "prismatic", "length": length, "lower_m": 0.0, "upper_m": hi - lo,
                   "offset_m": 0.0, "ratio": 1.0, "force_n": float(p["force_n"]), "link": j.child}
        return {"spec": spec, "joints": joints, "base": pos, "base_yaw": math.degrees(math.atan2(d[1], d[0])),
                "spread_sign": 0.0, "knuckle": hi, "knuckle_frame": None, "phalanges": [phalanx], "frames": [frame],
                "spread_joint": None, "first_q": joint0, "urdf_map": [(j.name, joint0, -1.0, hi)]}   # ours = hi - URDF

    def _as_root(self, j) -> tuple:
        """(root joint, m, o): j's value = m * root's + o, following its <mimic> chain to a joint
        that mimics nothing (a loop of mimics is refused)."""
        m, o, seen = 1.0, 0.0, {j.name}
        while j.mimic is not None:
            mm, oo = float(j.mimic.multiplier if j.mimic.multiplier is not None else 1.0), float(j.mimic.offset or 0.0)
            m, o = m * mm, m * oo + o
            j = self.tree.joint(j.mimic.joint, f"joint '{j.name}'s mimic")
            if j.name in seen:
                self._fail(f"joint '{j.name}': its <mimic> chain loops")
            seen.add(j.name)
        return j, m, o

    def _coupling(self, j, driver) -> Optional[tuple]:
        """(m, o) with j's value = m * driver's + o when the URDF makes them so, directly or through
        any chain of <mimic>s to a common joint (another finger's driver, say); else None."""
        rj, mj, oj = self._as_root(j)
        rd, md, od = self._as_root(driver)
        if rj.name != rd.name or md == 0.0:
            return None
        return mj / md, oj - mj / md * od

    def _joint_map(self, fingers: list, spread_joint) -> list:
        """Every moving URDF joint of the hand as an affine function of one of our joints, in URDF
        order: {"name", "index" (into our joint vector), "scale", "offset"} with
        URDF value = scale * ours[index] + offset (rad or m)."""
        entries = {} if spread_joint is None else {spread_joint.name: (0, 1.0, 0.0)}
        for f in fingers:
            for name, index, scale, offset in f["urdf_map"]:
                entries.setdefault(name, (index, scale, offset))
        for name, value in self.tree.held.items():
            entries.setdefault(name, (0, 0.0, value))      # held: reported at its value, reads nothing
        for name, (f, m, o) in self.passive.items():
            # URDF passive = m * URDF driver + o, URDF driver = scale * ours + offset (the driver's map)
            _, index, scale, offset = next(e for e in f["urdf_map"] if e[0] == f["joints"][0].name)
            entries.setdefault(name, (index, m * scale, m * offset + o))
        return [{"name": j.name, "index": entries[j.name][0], "scale": entries[j.name][1], "offset": entries[j.name][2]}
                for j in self.tree.joints.values() if j.name in entries]

    def _passive(self, fingers: list) -> dict:
        """The sidecar's passive joints: name -> (the finger whose first joint drives it, m, o) with
        URDF value = m * that joint's + o. Of the fingers whose first joint it follows (by the URDF's
        mimics, one gripper's fingers are all equivalent), the one whose first joint is nearest (a
        four-bar's bars sit on one side); a passive joint no finger's first joint drives is refused."""
        out = {}
        for k, name in enumerate(self.side.get("passive_joints", [])):
            j = self.tree.joint(name, f"passive_joints[{k}]")
            if not self.tree.moves(j):
                self._fail(f"passive_joints[{k}]: joint '{name}' is fixed or held (only moving joints are passive)")
            for f in fingers:
                if j in f["joints"]:
                    self._fail(f"passive_joints[{k}]: joint '{name}' closes {f['spec']['name']}/"
                               f"{f['phalanges'][f['joints'].index(j)]['name']} (a phalanx is not passive)")
            at = self.tree.zero_pose(j.child)[:3, 3]
            near = sorted(((np.linalg.norm(self.tree.zero_pose(f["joints"][0].child)[:3, 3] - at), i, f, c)
                           for i, f in enumerate(fingers) if (c := self._coupling(j, f["joints"][0])) is not None),
                          key=lambda e: e[:2])
            if near:
                out[name] = (near[0][2], *near[0][3])
            else:
                self._fail(f"passive_joints[{k}]: joint '{name}' is not a <mimic> of any finger's first joint "
                           f"({', '.join(f['joints'][0].name for f in fingers)})")
        return out

    # -- which URDF links make each of our links --
    def _bodies(self, fingers: list) -> dict:
        """Our link name -> (frame in hand, [URDF links]) by following fixed joints from each moving one."""
        owner = {}  # the joint (or None: the palm) that moves each URDF link
        for name in self.tree.links:
            moving = [j for j in self.tree.chain(name) if self.tree.moves(j)]
            owner[name] = moving[-1].name if moving else None
        ours: dict[str, tuple] = {}
        by_joint = {None: "palm"}
        ours["palm"] = (np.eye(4), [])
        for f in fingers:
            fname = f["spec"]["name"]
            if f["spread_joint"] is not None:
                by_joint[f["spread_joint"].name] = f"{fname}/knuckle"
                ours[f"{fname}/knuckle"] = (f["knuckle_frame"], [])
            for p, j, frame in zip(f["phalanges"], f["joints"], f["frames"]):
                by_joint[j.name] = f"{fname}/{p['name']}"
                ours[f"{fname}/{p['name']}"] = (frame, [])
        for name, j in owner.items():
            if j in self.passive:
                continue   # a linkage's other bar: its geometry is left out
            if j not in by_joint:
                self._fail(f"joint '{j}' moves link '{name}', but the sidecar names it nowhere "
                           "(neither the spread nor a finger's phalanx)")
            ours[by_joint[j]][1].append(name)
        return ours

    def _link_shapes(self, frame: np.ndarray, urdf_links: list) -> list:
        inv = np.linalg.inv(frame)
        items = []
        for name in urdf_links:
            T_link = inv @ self._in_hand(self.tree.zero_pose(name))
            for c in self.tree.links[name].collisions or []:
                T = T_link @ _origin(c.origin)
                g = c.geometry
                if g.box is not None:
                    items.append(("box", T, g.box))
                elif g.sphere is not None:
                    items.append(("sphere", T, g.sphere))
                elif g.cylinder is not None:
                    items.append(("cylinder", T, g.cylinder))
                elif g.mesh is not None:
                    items += [("mesh", T, _transform(T, P)) for P in _mesh_points(g.mesh, self.urdf_dir, self.where, name)]
        return _shapes_of(items, self.where)

    def hand(self) -> dict:
        spread, spread_joint = self._spread()
        fingers, q = [], 1
        for fi, spec in enumerate(self.side["fingers"]):
            fingers.append(self._finger(fi, spec, spread_joint, q))
            q += len(spec["phalanges"])
        names = [f["spec"]["name"] for f in fingers]
        if len(set(names)) != len(names):
            self._fail(f"fingers: names repeat ({names})")
        joint_names = {}
        for f in fingers:
            for p, j in zip(f["phalanges"], f["joints"]):
                if j.name in joint_names:
                    self._fail(f"joint '{j.name}' closes two phalanges ({joint_names[j.name]} and {f['spec']['name']}/{p['name']})")
                joint_names[j.name] = f"{f['spec']['name']}/{p['name']}"
        self.passive = self._passive(fingers)
        self.joint_map = self._joint_map(fingers, spread_joint)
        bodies = self._bodies(fingers)
        measured = []
        for k, n in enumerate(self.side["measured_joints"]):
            self.tree.joint(n, f"measured_joints[{k}]")
            if n not in joint_names:
                self._fail(f"measured_joints[{k}]: joint '{n}' is not a finger's phalanx joint")
            measured.append(joint_names[n])
        out_fingers = []
        for f in fingers:
            fname = f["spec"]["name"]
            kn = bodies.get(f"{fname}/knuckle")
            out_fingers.append({
                "name": fname, "base": [float(x) for x in f["base"]], "base_yaw_deg": f["base_yaw"],
                "spread_sign": f["spread_sign"], **({"roll_deg": math.degrees(f["roll"])} if f.get("roll") else {}),
                "knuckle": {"length": f["knuckle"], "shapes": self._link_shapes(*kn) if kn else []},
                "phalanges": [{k: v for k, v in p.items() if k != "link"} |
                              {"shapes": self._link_shapes(*bodies[f"{fname}/{p['name']}"])}
                              for p in f["phalanges"]]})
        return {"name": self.side["name"], "description": self.side.get("description", ""),
                "actuation": self.side["actuation"], "frame": "converted from a URDF: origin at the centre of the palm "
                "face (the sidecar's palm frame); +z is the approach direction",
                "palm": {"shapes": self._link_shapes(*bodies["palm"])}, "spread": spread,
                "fingers": out_fingers, "measured_joints": measured} | (
                    {"closing": self.side["closing"]} if self.side["closing"] != "breakaway" else {})   # the default
