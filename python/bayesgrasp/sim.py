"""Contact simulation: a hand closing on a static object on a table (the C++ core, FCL).

Fingers close from the open preshape by conservative advancement with FCL distance queries;
each phalanx stops within ``contact_tolerance`` (0.2 mm) of the object or the table, with
breakaway (a stopped phalanx freezes itself and the earlier phalanges of its finger; the later
ones keep closing). Top grasps approach palm-down along -z until the first contact of any
link, rise by ``standoff`` (default 0) and close::

    hand = Hand.load("barrett_bh8")
    sim = GraspSimulator(hand, vertices, faces)            # table at z = 0 by default
    g = sim.top_grasp(0.0, 0.0, 0.3, spread=np.pi / 2)      # -> GraspResult
    b = sim.top_grasp_batch(xyyaw, spread=0.5, threads=0)  # -> dict of arrays (N rows)

Batch dicts: ``joint_angles`` (N, J), ``link_contact`` / ``table_contact`` (N, L),
``collision_at_start`` (N,), ``hand_pose`` (N, 4, 4), ``distance_queries`` (N,), and
``contacts`` with ``point``/``normal`` (K, 3), ``link``, ``penetration``, ``on_table``,
``grasp`` (K,) and ``offsets`` (N + 1,). Normals are the object's outward surface normals
(+z for the table): what :mod:`bayesgrasp.quality` consumes.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from bayesgrasp import _core
from bayesgrasp.hand import Hand

__all__ = ["GraspSimulator", "GraspResult"]


@dataclass
class GraspResult:
    """One simulated grasp."""

    joint_angles: np.ndarray          # (J,) rad, hand layout
    contact_points: np.ndarray        # (K, 3) on the object (or table) surface, world
    contact_normals: np.ndarray       # (K, 3) outward object normal (+z for the table)
    contact_links: np.ndarray         # (K,) link index (0 = palm)
    contact_penetration: np.ndarray   # (K,) >= 0 (m)
    contact_on_table: np.ndarray      # (K,) bool
    link_contact: np.ndarray          # (L,) bool: the link touches the object
    table_contact: np.ndarray         # (L,) bool: the link touches the table
    collision_at_start: bool          # the open hand penetrated the object or the table
    hand_pose: np.ndarray             # (4, 4) world pose of the hand (where a top grasp stopped)
    distance_queries: int = 0         # FCL distance calls spent
    extra: dict = field(default_factory=dict)

    @classmethod
    def from_dict(cls, d: dict) -> "GraspResult":
        c = d["contacts"]
        return cls(np.asarray(d["joint_angles"]), c["point"], c["normal"], c["link"], c["penetration"],
                   c["on_table"], d["link_contact"], d["table_contact"], bool(d["collision_at_start"]),
                   d["hand_pose"], int(d["distance_queries"]))

    @property
    def num_contacts(self) -> int:
        return int(len(self.contact_links))

    def object_contacts(self) -> tuple[np.ndarray, np.ndarray]:
        """(points, normals) of the contacts with the object (not the table), for quality metrics."""
        keep = ~np.asarray(self.contact_on_table, dtype=bool)
        return self.contact_points[keep], self.contact_normals[keep]


def _hand(hand) -> _core.hand.Hand:
    if isinstance(hand, Hand):
        return hand.core
    if isinstance(hand, _core.hand.Hand):
        return hand
    if isinstance(hand, str):
        return Hand.load(hand).core
    raise ValueError(f"hand: expected a Hand, a hand name or path, got {type(hand).__name__}")


class GraspSimulator:
    """Auto-grasp of a hand on one static triangle-mesh object (world frame, z up)."""

    def __init__(self, hand, vertices, faces, table: bool = True, contact_tolerance: float = 2e-4,
                 table_clearance: float = 0.005):
        self.hand = hand if isinstance(hand, Hand) else Hand(_hand(hand))
        try:
            V = np.asarray(vertices, dtype=float)
            F = np.asarray(faces)
        except (TypeError, ValueError) as e:
            raise ValueError(f"vertices/faces: not numeric arrays ({e})") from None
        if F.dtype.kind not in "iu":
            if F.size and not np.all(np.equal(np.mod(F, 1), 0)):
                raise ValueError("faces: must be integer vertex indices")
        self.vertices, self.faces = V, F.astype(np.int32)
        self.core = _core.sim.GraspSimulator(self.hand.core, V, self.faces, bool(table), float(contact_tolerance),
                                             float(table_clearance))

    @classmethod
    def from_mesh(cls, hand, mesh, **kwargs) -> "GraspSimulator":
        """From any object with ``vertices`` and ``faces`` (e.g. a trimesh.Trimesh)."""
        return cls(hand, mesh.vertices, mesh.faces, **kwargs)

    def _spread(self, spread):
        return float(self.hand.core.spread_default if spread is None else spread)

    def close(self, hand_pose, spread: float | None = None) -> GraspResult:
        """Auto-grasp from a 4x4 world hand pose at `spread` (rad; default: the hand's default)."""
        return GraspResult.from_dict(self.core.close(np.asarray(hand_pose, dtype=float), self._spread(spread)))

    def close_fixed_step(self, hand_pose, spread: float | None = None, step: float = 0.01) -> GraspResult:
        """The same closing GraspIt!-style (fixed actuator steps + collision checks); for comparison."""
        return GraspResult.from_dict(self.core.close_fixed_step(np.asarray(hand_pose, dtype=float),
                                                                self._spread(spread), float(step)))

    def top_grasp(self, x: float, y: float, yaw: float, spread: float | None = None,
                  standoff: float = 0.0) -> GraspResult:
        """Palm-down approach at (x, y, yaw) to the first contact, rise by `standoff` (m), close."""
        return GraspResult.from_dict(self.core.top_grasp(float(x), float(y), float(yaw), self._spread(spread),
                                                         float(standoff)))

    def close_batch(self, hand_poses, spreads=None, threads: int = 1) -> dict:
        """N hand poses (N, 4, 4); spreads a number or (N,); threads 0 = all cores. Dict of arrays."""
        spreads = self._spread(None) if spreads is None else spreads
        if not np.isscalar(spreads):
            spreads = np.asarray(spreads, dtype=float)
        else:
            spreads = float(spreads)
        return self.core.close_batch(np.asarray(hand_poses, dtype=float), spreads, int(threads))

    def top_grasp_batch(self, xyyaw, spread: float | None = None, standoff: float = 0.0,
                        threads: int = 1) -> dict:
        """Top grasps at the rows (x, y, yaw) of an (N, 3) array. Dict of arrays."""
        return self.core.top_grasp_batch(np.asarray(xyyaw, dtype=float), self._spread(spread), float(standoff),
                                         int(threads))

    def link_object_distance(self, hand_pose, q, link: int) -> float:
        """Exact distance from one link to the object (m), <= 0 when penetrating."""
        return self.core.link_object_distance(np.asarray(hand_pose, dtype=float), np.asarray(q, dtype=float),
                                              int(link))

    @staticmethod
    def split_contacts(batch: dict) -> list[dict]:
        """The batch's contacts as one dict of arrays per grasp."""
        c, off = batch["contacts"], batch["contacts"]["offsets"]
        keys = ["point", "normal", "link", "penetration", "on_table"]
        return [{k: c[k][off[i]:off[i + 1]] for k in keys} for i in range(len(off) - 1)]
