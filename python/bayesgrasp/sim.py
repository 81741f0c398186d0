"""Contact simulation: a hand closing on a static object on a table (the C++ core, FCL).

Fingers close from the open preshape by conservative advancement with FCL distance queries;
each phalanx stops within ``contact_tolerance`` (0.2 mm) of the object or the table, with
breakaway (a stopped phalanx freezes itself and the earlier phalanges of its finger; the later
ones keep closing). An approach moves the open hand along a direction (its +z) on the line
through a target point, from clear of the object and the table, until the first contact of any
link with the object or with the table (when moving down onto it), backs off by ``standoff``
(default 0) along the direction and closes; the roll turns the hand about -direction
(:meth:`Hand.approach_pose`). Top grasps are the approach along -z with roll = yaw::

    hand = Hand.load("barrett_bh8")
    sim = GraspSimulator(hand, vertices, faces)            # table at z = 0 by default
    g = sim.top_grasp(0.0, 0.0, 0.3, spread=np.pi / 2)      # -> GraspResult
    b = sim.top_grasp_batch(xyyaw, spread=0.5, threads=0)  # -> GraspBatch (N rows)
    s = sim.approach([1, 0, 0], [0, 0, 0.05], roll=0.0)     # a side grasp
    a = sim.approach_batch(directions, targets, rolls, threads=0)

Results are the core's classes (:class:`GraspResult`, :class:`GraspBatch`); their array fields
are read-only numpy views: ``joint_angles``, ``link_contact`` / ``table_contact``,
``collision_at_start``, ``stopped_by_table``, ``hand_pose``, ``distance_queries`` and
``contacts`` with ``point``/``normal`` (K, 3), ``link``, ``penetration``, ``on_table``,
``triangle`` (the object's triangle, -1 for the table) (and, for batches, ``grasp`` (K,) and
``offsets`` (N + 1,)). Normals are the object's outward surface normals (+z for the
table): what :mod:`bayesgrasp.quality` consumes. Options are a :class:`SimOptions`.
"""
from __future__ import annotations

from bayesgrasp._args import c_int, c_seed
import numpy as np

from bayesgrasp import _core
from bayesgrasp.hand import Hand

__all__ = ["GraspSimulator", "GraspResult", "GraspBatch", "SimOptions", "make_options", "set_fields"]

GraspResult = _core.sim.GraspResult
GraspBatch = _core.sim.GraspBatch
SimOptions = _core.sim.SimOptions


def set_fields(options, fields: dict, what: str):
    """Sets the attributes ``fields`` on an options object; ValueError for a name it does not have."""
    for k, v in fields.items():
        if k.startswith("_") or not hasattr(options, k):
            raise ValueError(f"{k}: not a {what} option")
        default = getattr(options, k)
        if isinstance(default, int) and not isinstance(default, bool):
            v = c_seed(v, k) if k == "seed" else c_int(v, k)
        setattr(options, k, v)
    return options


def make_options(**fields) -> SimOptions:
    """SimOptions from keyword arguments (names as the SimOptions attributes). A larger
    ``contact_tolerance`` raises ``box_skip`` (unless given) to 2.5 times it, as the bound must
    exceed the tolerance."""
    o = set_fields(SimOptions(), fields, "simulator")
    if "contact_tolerance" in fields and "box_skip" not in fields:
        o.box_skip = max(o.box_skip, 2.5 * o.contact_tolerance)
    return o


def _hand(hand) -> _core.hand.Hand:
    if isinstance(hand, Hand):
        return hand.core
    if isinstance(hand, _core.hand.Hand):
        return hand
    if isinstance(hand, str):
        return Hand.load(hand).core
    raise ValueError(f"hand: expected a Hand, a hand name or path, got {type(hand).__name__}")


class GraspSimulator:
    """Auto-grasp of a hand on one static triangle-mesh object (world frame, z up).

    Args:
        hand: a :class:`Hand`, a built-in hand name or a hand file path.
        vertices: (N, 3) float vertices (m). faces: (M, 3) int triangles.
        options: a :class:`SimOptions` (None: defaults).
        **fields: SimOptions fields set on top of ``options`` (e.g. ``table=False``,
            ``contact_tolerance=5e-4``, ``table_clearance=-1.0``).
    """

    def __init__(self, hand, vertices, faces, options: SimOptions | None = None, **fields):
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
        o = make_options(**fields) if options is None else set_fields(options, fields, "simulator")
        self.core = _core.sim.GraspSimulator(self.hand.core, V, self.faces, o)

    @classmethod
    def from_mesh(cls, hand, mesh, **kwargs) -> "GraspSimulator":
        """From any object with ``vertices`` and ``faces`` (e.g. a trimesh.Trimesh)."""
        return cls(hand, mesh.vertices, mesh.faces, **kwargs)

    @property
    def options(self) -> SimOptions:
        return self.core.options

    def _spread(self, spread):
        return float(self.hand.core.spread_default if spread is None else spread)

    def close(self, hand_pose, spread: float | None = None) -> GraspResult:
        """Auto-grasp from a 4x4 world hand pose at `spread` (rad; default: the hand's default)."""
        return self.core.close(np.asarray(hand_pose, dtype=float), self._spread(spread))

    def close_fixed_step(self, hand_pose, spread: float | None = None, step: float = 0.01) -> GraspResult:
        """The same closing GraspIt!-style (fixed actuator steps + collision checks); for comparison."""
        return self.core.close_fixed_step(np.asarray(hand_pose, dtype=float), self._spread(spread), float(step))

    def top_grasp(self, x: float, y: float, yaw: float, spread: float | None = None,
                  standoff: float = 0.0) -> GraspResult:
        """Palm-down approach at (x, y, yaw) to the first contact, rise by `standoff` (m), close."""
        return self.core.top_grasp(float(x), float(y), float(yaw), self._spread(spread), float(standoff))

    def close_batch(self, hand_poses, spreads=None, threads: int = 1) -> GraspBatch:
        """N hand poses (N, 4, 4); spreads a number or (N,); threads 0 = all cores."""
        spreads = self._spread(None) if spreads is None else spreads
        spreads = float(spreads) if np.isscalar(spreads) else np.asarray(spreads, dtype=float)
        return self.core.close_batch(np.asarray(hand_poses, dtype=float), spreads, c_int(threads, "threads"))

    def top_grasp_batch(self, xyyaw, spread: float | None = None, standoff: float = 0.0,
                        threads: int = 1) -> GraspBatch:
        """Top grasps at the rows (x, y, yaw) of an (N, 3) array."""
        return self.core.top_grasp_batch(np.asarray(xyyaw, dtype=float), self._spread(spread), float(standoff),
                                         c_int(threads, "threads"))

    def approach(self, direction, target, roll: float = 0.0, spread: float | None = None,
                 standoff: float = 0.0) -> GraspResult:
        """Approach along ``direction`` (3,) on the line through ``target`` (3,) with ``roll``
        (world frame; see :meth:`bayesgrasp.hand.Hand.approach_pose`), stop at the first contact
        with the object or the table, back off by ``standoff`` (m) along the direction, close."""
        return self.core.approach(np.asarray(direction, dtype=float), np.asarray(target, dtype=float), float(roll),
                                  self._spread(spread), float(standoff))

    def approach_batch(self, directions, targets, rolls=0.0, spread: float | None = None, standoff: float = 0.0,
                       threads: int = 1) -> GraspBatch:
        """N approaches: directions and targets (N, 3), rolls a number or (N,)."""
        rolls = float(rolls) if np.isscalar(rolls) else np.asarray(rolls, dtype=float)
        return self.core.approach_batch(np.asarray(directions, dtype=float), np.asarray(targets, dtype=float), rolls,
                                        self._spread(spread), float(standoff), c_int(threads, "threads"))

    def link_object_distance(self, hand_pose, q, link: int) -> float:
        """Exact distance from one link to the object (m), <= 0 when penetrating."""
        return self.core.link_object_distance(np.asarray(hand_pose, dtype=float), np.asarray(q, dtype=float),
                                              int(link))
