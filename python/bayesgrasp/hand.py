"""Hands described by data files: the Barrett BH8 (the thesis's hand) and others.

A hand file (JSON) gives the palm, the fingers as chains of phalanges, their collision
shapes (boxes and capsules) and the closing scheme (coupled joints with breakaway). Built-in
files live in ``bayesgrasp/data/hands/``::

    hand = Hand.load("barrett_bh8")           # or Hand.load("path/to/my_hand.json")
    q = hand.open_joints(spread=np.pi / 2)     # open preshape
    poses = hand.link_poses(q, hand_pose)      # (L, 4, 4)
    parts = hand.link_geometry(q, hand_pose)   # world-frame shapes (ShapeGeometry), for plotting

Joint vector q (radians): [spread, finger 0 phalanx 0, finger 0 phalanx 1, ..., finger 1
phalanx 0, ...]; phalanx angles are relative to the previous phalanx. The hand frame has its
origin at the centre of the palm face and +z along the approach direction.
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import List, Optional, Tuple

import numpy as np

from bayesgrasp import DEFAULT_HAND, _core

__all__ = ["Hand", "HANDS_DIR", "ShapeGeometry", "builtin_hands"]

HANDS_DIR = Path(__file__).parent / "data" / "hands"

#: m per rad: a jaw (prismatic finger) is driven and measured like a fingertip this far from a
#: joint (cpp/bayesgrasp/physics/squeeze_model.hpp, kJawLever).
JAW_LEVER = 0.05


def builtin_hands() -> list[str]:
    """Names of the built-in hands: hand files by name (without ``.json``) and URDF hands by file
    name (``barrett_bh8.urdf``; each has its sidecar ``NAME.hand.json``)."""
    files = [p.stem for p in HANDS_DIR.glob("*.json") if not p.name.endswith(".hand.json")]
    return sorted(files) + sorted(p.name for p in HANDS_DIR.glob("*.urdf"))


def resolve_hand(name_or_path: str | Path) -> Path:
    """The file behind a hand name or path: an existing path, a built-in name (``barrett_bh8``)
    or a built-in URDF's file name (``barrett_bh8.urdf``). Raises ValueError naming what exists."""
    p = Path(name_or_path)
    if p.exists():
        return p
    for cand in (HANDS_DIR / p.name, HANDS_DIR / f"{p.name}.json"):
        if p.parent == Path(".") and cand.is_file() and not cand.name.endswith(".hand.json"):
            return cand
    raise ValueError(f"name_or_path: no built-in hand '{name_or_path}' (available: {', '.join(builtin_hands())}) "
                     "and no such file")


def _pose(hand_pose):
    if hand_pose is None:
        return None
    return np.asarray(hand_pose, dtype=float)


@dataclass(frozen=True)
class ShapeGeometry:
    """One collision shape of a hand link in the world frame (see :meth:`Hand.link_geometry`).

    A ``'capsule'`` has ``p0``, ``p1`` (3,) and ``radius``; a ``'box'`` has ``center`` (3,),
    ``rotation`` (3, 3) (columns = box axes) and ``half_extents`` (3,); a ``'convex'`` shape has
    ``vertices`` (N, 3) and ``faces`` (M, 3); the other fields are None.
    """

    link: int                               # link index
    name: str                               # link name
    type: str                               # 'capsule', 'box' or 'convex'
    p0: Optional[np.ndarray] = None
    p1: Optional[np.ndarray] = None
    radius: Optional[float] = None
    center: Optional[np.ndarray] = None
    rotation: Optional[np.ndarray] = None
    half_extents: Optional[np.ndarray] = None
    vertices: Optional[np.ndarray] = None
    faces: Optional[np.ndarray] = None



class Hand:
    """A hand model (wraps :class:`bayesgrasp._core.hand.Hand`)."""

    def __init__(self, core: _core.hand.Hand, source: str = "", text: str = ""):
        if not isinstance(core, _core.hand.Hand):
            raise ValueError("core: expected a bayesgrasp._core.hand.Hand; use Hand.load(...)")
        self.core = core
        self.source = source
        self._text = text
        #: a URDF hand's joints as functions of ours (hand_urdf's joint map), else None
        self.urdf_joint_map: Optional[list] = None

    @classmethod
    def load(cls, name_or_path: str | Path = DEFAULT_HAND) -> "Hand":
        """A built-in hand by name (see :func:`builtin_hands`), a hand file (JSON) by path, or a
        URDF (``NAME.urdf`` with its sidecar ``NAME.hand.json`` beside it; see
        :mod:`bayesgrasp.hand_urdf`)."""
        p = resolve_hand(name_or_path)
        if p.suffix.lower() == ".urdf":
            return cls.from_urdf(p)
        if p.name.endswith(".hand.json"):
            raise ValueError(f"name_or_path: {p} is a URDF hand's sidecar; load the URDF it names")
        text = p.read_text()
        return cls(_core.hand.Hand.from_file(str(p)), str(p), text)

    @classmethod
    def from_urdf(cls, urdf: str | Path, sidecar: str | Path | None = None) -> "Hand":
        """A hand from a URDF and its sidecar (default: ``NAME.hand.json`` beside ``NAME.urdf``),
        converted to a hand file's model (:func:`bayesgrasp.hand_urdf.hand_json_from_urdf`)."""
        from .hand_urdf import hand_json_from_urdf

        text, joint_map = hand_json_from_urdf(urdf, sidecar, with_joint_map=True)
        hand = cls(_core.hand.Hand.from_json(text), str(urdf), text)
        hand.urdf_joint_map = joint_map
        return hand

    def urdf_joints(self, q) -> Optional[Tuple[List[str], np.ndarray]]:
        """A URDF hand's joint vector ``q`` (ours: ``joint_names``' order) in the URDF's own terms:
        (the URDF's moving joint names, in the URDF's order, mimic joints included; their values
        in the URDF's units and zero), or None for a hand file. Each value is
        scale * q[index] + offset from the conversion: a revolute phalanx is the URDF's angle plus
        its angle at the URDF's zero, a jaw is the URDF's upper limit minus its value."""
        if self.urdf_joint_map is None:
            return None
        q = np.asarray(q, dtype=float).ravel()
        if q.size != self.num_joints:
            raise ValueError(f"q: {q.size} values for a hand of {self.num_joints} joints")
        return ([m["name"] for m in self.urdf_joint_map],
                np.array([m["scale"] * q[m["index"]] + m["offset"] for m in self.urdf_joint_map]))

    #: rad (m for a jaw): how far two URDF joints that read the same joint of ours (a spread on two
    #: fingers, a mimic) may disagree in a reading given in the URDF's terms.
    URDF_READING_TOL = 0.05

    def joints_from_urdf(self, values) -> np.ndarray:
        """The inverse of :meth:`urdf_joints`: a reading in the URDF's terms (its moving joints in the
        order of ``urdf_joints``' names, its units) as our joint vector. Where several URDF joints
        read one of ours, their mean is taken; one of ours that no URDF joint reads keeps its open
        preshape's value; ValueError if they disagree by more than
        URDF_READING_TOL, naming them, or if the count is wrong."""
        if self.urdf_joint_map is None:
            raise ValueError(f"{self.source}: not a URDF hand; its readings are in joint_names' terms")
        v = np.asarray(values, dtype=float).ravel()
        names = [m["name"] for m in self.urdf_joint_map]
        if v.size != len(names):
            raise ValueError(f"{v.size} values for the URDF's {len(names)} moving joints ({', '.join(names)})")
        q = self.open_joints()   # a joint of ours with no URDF joint (a jaw's fixed spread) keeps its preshape
        for i in range(self.num_joints):
            rows = [(m["name"], (v[k] - m["offset"]) / m["scale"]) for k, m in enumerate(self.urdf_joint_map)
                    if m["index"] == i and m["scale"] != 0]
            if not rows:
                continue
            vals = np.array([r[1] for r in rows])
            if np.ptp(vals) > self.URDF_READING_TOL:
                raise ValueError(f"the URDF joints {', '.join(r[0] for r in rows)} read joint {self.joint_names[i]!r} "
                                 f"as {', '.join(f'{x:.4g}' for x in vals)}: they disagree by more than "
                                 f"{self.URDF_READING_TOL}")
            q[i] = vals.mean()
        return q

    @classmethod
    def from_json(cls, text: str) -> "Hand":
        """A hand from the JSON text of a hand file."""
        return cls(_core.hand.Hand.from_json(text), "<json>", text)

    @property
    def path(self) -> str:
        """The hand file or URDF this hand was loaded from ('<json>' when built from text)."""
        return self.source

    @property
    def text(self) -> str:
        """The hand-file text (JSON) the model was built from (for a URDF hand, its conversion):
        everything that shapes a result, for cache keys."""
        return self._text

    @property
    def prismatic_joints(self) -> np.ndarray:
        """(J,) bool: the entries of q that are a jaw's travel (m) rather than an angle (rad)."""
        return np.asarray(self.core.prismatic_joints, dtype=bool)

    @property
    def measurement_scale(self) -> np.ndarray:
        """Per measured joint, the unit of "a radian" of measurement noise: 1 for an angle, and
        for a jaw's travel the 5 cm lever its motor is modelled with (0.05 m; the lift test's
        kJawLever)."""
        return np.where(self.prismatic_joints[self.measured_joints], JAW_LEVER, 1.0)

    @property
    def measured_joints(self) -> np.ndarray:
        """Indices into q of the joints the "fingers read" measurement uses."""
        return np.asarray(self.core.measured_joints, dtype=int)

    # ---- structure ----
    name = property(lambda self: self.core.name, doc="The hand's name.")
    num_joints = property(lambda self: self.core.num_joints, doc="Length of the joint vector q.")
    num_links = property(lambda self: self.core.num_links, doc="Number of links (0 is the palm).")
    num_fingers = property(lambda self: self.core.num_fingers, doc="Number of fingers.")
    links = property(lambda self: list(self.core.link_names), doc="Link names.")
    joint_names = property(lambda self: list(self.core.joint_names), doc="Names of the entries of q.")
    joint_limits = property(lambda self: self.core.joint_limits, doc="(J, 2) joint limits (rad).")
    spread_limits = property(lambda self: tuple(self.core.spread_limits), doc="(lower, upper) spread (rad).")
    joint_torques = property(lambda self: self.core.joint_torques,
                             doc="(J,) N m, each finger joint's motor torque limit while driven (the hand file's "
                                 "torque_nm, its published strength; 0 for the spread).")
    phalanx_links = property(lambda self: self.core.phalanx_links,
                             doc="Per finger, the link indices of its phalanges (base to tip).")

    def __repr__(self) -> str:
        return f"Hand({self.name!r}, fingers={self.num_fingers}, joints={self.num_joints})"

    # ---- kinematics ----
    def coupled_joints(self, spread: float, t=0.0) -> np.ndarray:
        """Joint vector at `spread` with every finger at actuator parameter t (number or per finger)."""
        t = float(t) if np.isscalar(t) else np.asarray(t, dtype=float)
        return self.core.coupled_joints(float(spread), t)

    def open_joints(self, spread: float | None = None) -> np.ndarray:
        """The open preshape (actuator t = 0) at `spread` (default: the hand's default spread)."""
        return self.coupled_joints(self.core.spread_default if spread is None else spread, 0.0)

    def link_poses(self, q, hand_pose=None) -> np.ndarray:
        """(L, 4, 4) link poses for joint vector q, in the frame of hand_pose (default: hand frame)."""
        return self.core.link_poses(np.asarray(q, dtype=float), _pose(hand_pose))

    def fingertips(self, q, hand_pose=None) -> np.ndarray:
        """(F, 3) fingertip positions."""
        return self.core.fingertips(np.asarray(q, dtype=float), _pose(hand_pose))

    @staticmethod
    def top_grasp_pose(x: float, y: float, yaw: float, z: float) -> np.ndarray:
        """4x4 pose of a palm-down hand at (x, y, yaw), palm face at height z."""
        return _core.hand.Hand.top_grasp_pose(float(x), float(y), float(yaw), float(z))

    @staticmethod
    def approach_pose(direction, roll: float, palm) -> np.ndarray:
        """4x4 pose of a hand approaching along ``direction`` (its +z; normalised) with ``roll``,
        palm centre at ``palm``. Roll convention: the palm-down top-grasp hand at yaw = roll,
        tilted by the smallest rotation taking world -z onto the direction (a right-handed turn
        about -direction); ``approach_pose((0, 0, -1), yaw, (x, y, z)) == top_grasp_pose(x, y,
        yaw, z)``. For direction +z the tilt is a half turn about world x."""
        return _core.hand.Hand.approach_pose(np.asarray(direction, dtype=float), float(roll),
                                             np.asarray(palm, dtype=float))

    @staticmethod
    def approach_roll(pose) -> float:
        """The roll of a 4x4 hand pose about its approach (its +z): the inverse of
        :meth:`approach_pose`, ``approach_roll(approach_pose(d, r, p)) == r`` (mod 2 pi)."""
        T = np.asarray(pose, dtype=float)
        d = T[:3, 2]
        x0 = Hand.approach_pose(d, 0.0, T[:3, 3])[:3, 0]
        return float(np.arctan2(np.cross(x0, T[:3, 0]) @ (-d), x0 @ T[:3, 0]))

    def link_shapes(self) -> list:
        """Per link, its collision shapes (``_core.hand.Shape``: type, center, half_extents, p0,
        p1, radius, vertices, faces) in the link frame."""
        return self.core.link_shapes()

    def link_geometry(self, q=None, hand_pose=None) -> list[ShapeGeometry]:
        """World-frame geometry of every shape, for plotting: one :class:`ShapeGeometry` per
        shape. q defaults to the open preshape at the default spread; hand_pose to identity."""
        q = self.open_joints() if q is None else np.asarray(q, dtype=float)
        poses = self.link_poses(q, hand_pose)
        out = []
        for li, (shapes, T) in enumerate(zip(self.link_shapes(), poses)):
            R, t = T[:3, :3], T[:3, 3]
            for s in shapes:
                if s.type == "capsule":
                    out.append(ShapeGeometry(li, self.links[li], "capsule", p0=R @ s.p0 + t, p1=R @ s.p1 + t,
                                             radius=float(s.radius)))
                elif s.type == "convex":
                    out.append(ShapeGeometry(li, self.links[li], "convex", vertices=np.asarray(s.vertices) @ R.T + t,
                                             faces=np.asarray(s.faces)))
                else:
                    out.append(ShapeGeometry(li, self.links[li], "box", center=R @ s.center + t, rotation=R.copy(),
                                             half_extents=np.asarray(s.half_extents, dtype=float)))
        return out
