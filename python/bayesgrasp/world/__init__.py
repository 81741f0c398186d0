"""The robot's world: a hand, a table-top scene, the contact simulator, grasp quality and the
lift test, in one object.

Grasps are given in the object frame (see :mod:`bayesgrasp.objects.scene`) unless
``frame="world"``. Three kinds:

* top grasps (x, y, yaw): the hand, palm down at (x, y) with yaw relative to the object's yaw,
  descends along -z to the first contact and closes;
* approaches (direction, target, roll): the open hand moves along the direction (its +z) on the
  line through the target until the first contact with the object or the table, backs off by
  the stand-off along the direction and closes. Roll is a right-handed turn about -direction:
  the palm-down top-grasp hand at yaw = roll, tilted by the smallest rotation taking -z onto the
  direction (:meth:`bayesgrasp.hand.Hand.approach_pose`); the top grasp at (x, y, yaw) is the
  approach along -z with roll = yaw through (x, y, any z);
* hand poses (4x4): the hand closes where it is.

::

    world = World.single("mug", pose=(0.1, 0.0, 0.3))
    g = world.grasp(0.0, 0.0, 0.0)                         # a WorldGrasp (joints, contacts, epsilon, ...)
    b = world.grasp_batch(xyyaw, threads=0)                # N top grasps: a WorldGraspBatch of arrays
    s = world.approach([1, 0, 0], [0, 0, 0.05], roll=0.0)  # a side grasp
    a = world.approach_batch(directions, targets, rolls)   # N approaches
    p = world.grasp_poses(hand_poses)                      # N 4x4 hand poses

Bad input is a ValueError naming the argument: a direction of zero length or not finite, a
target below the table or off the table (its (x, y) outside the scene's table grown by
TABLE_MARGIN on every side), a 4x4 that is not a rigid transform. A hand that starts in the table
or the object is reported (``collision_at_start``), not an error.

Pictures of a grasp are in :mod:`bayesgrasp.viz` (``viz.plot_grasp(world, g, path)``).
"""
from __future__ import annotations

from typing import Optional, Sequence, Tuple, Union

import numpy as np

from ..belief import absolute_planar_pose
from .. import physics, quality
from .. import DEFAULT_HAND
from ..hand import Hand
from ..objects import ObjectModel, Scene
from ..objects.mass import moved
from ..objects.scene import planar_pose_matrix
from ..sim import GraspSimulator
from .results import ContactRecord, WorldGrasp, WorldGraspBatch

__all__ = ["World", "WorldGrasp", "WorldGraspBatch", "ContactRecord", "DEFAULT_FRICTION", "TABLE_MARGIN", "FRAMES"]

DEFAULT_FRICTION = quality.DEFAULT_FRICTION
TABLE_MARGIN = 0.25  # m: approach targets may lie this far outside the table's rectangle
FRAMES = ("object", "world")


class World:
    """One object of a scene, a hand and everything needed to try grasps on it.

    Args:
        scene: the table-top scene; ``object_index`` selects the object to grasp (the
            simulator sees only that object; the others are not obstacles).
        hand: a :class:`Hand`, a built-in hand name or a hand file path.
        mu: friction coefficient for the quality metric and the lift test.
        spread: default finger spread (rad); None = the hand's default.
        standoff: how far the palm backs off from the first contact before closing (m).
        table: whether the table (z = 0) is there for the hand and in the lift test. False
            presents the object held off the table at its scene pose (on a holder the simulator
            does not model, as objects float in GraspIt!): the hand may come from any side and
            an object the hand does not hold falls.
    """

    def __init__(self, scene: Scene, hand: Union[Hand, str] = DEFAULT_HAND, object_index: int = 0,
                 mu: float = DEFAULT_FRICTION, spread: Optional[float] = None, standoff: float = 0.0,
                 table: bool = True):
        if not (np.isfinite(mu) and mu >= 0):
            raise ValueError(f"mu: must be finite and >= 0, got {mu}")
        if not (np.isfinite(standoff) and standoff >= 0):
            raise ValueError(f"standoff: must be finite and >= 0, got {standoff}")
        self.scene = scene
        self.hand = hand if isinstance(hand, Hand) else Hand.load(hand)
        self.object_index = object_index
        self.mu = float(mu)
        self.spread = float(self.hand.core.spread_default if spread is None else spread)
        self.standoff = float(standoff)
        self.table = bool(table)
        self._rebuild()

    @classmethod
    def single(cls, obj: Union[str, ObjectModel], pose: Sequence[float] = (0.0, 0.0, 0.0),
               keep_origin: bool = False, **kwargs) -> "World":
        """A world with one object (built-in name, mesh path or ObjectModel) at pose (x, y, yaw)."""
        scene = Scene()
        scene.add_object(obj, *pose, keep_origin=keep_origin)
        return cls(scene, **kwargs)

    def _rebuild(self) -> None:
        V, F = self.scene.object_mesh_world(self.object_index)
        self.vertices, self.faces = V, F
        self.sim = GraspSimulator(self.hand, V, F, table=self.table)
        mp = self.scene.object_mass_properties_world(self.object_index)
        self.com = np.asarray(mp["com"], dtype=float)
        self.torque_scale = self.object.max_radius_from_com  # rigid motion keeps it
        self._lift = None

    def set_object_pose(self, x: float, y: float, yaw: float) -> None:
        """Moves the object (the simulator is rebuilt for the new pose)."""
        self.scene.set_pose(self.object_index, x, y, yaw)
        self._rebuild()

    @property
    def object(self) -> ObjectModel:
        return self.scene.canonical_object(self.object_index)

    def _planar(self, frame: str) -> Tuple[float, float, float]:
        """(x, y, yaw) of the grasp frame in the world: the object's planar pose or the world's."""
        if frame not in FRAMES:
            raise ValueError(f"frame: must be one of {', '.join(FRAMES)}, got {frame!r}")
        return self.scene.planar_pose(self.object_index) if frame == "object" else (0.0, 0.0, 0.0)

    def _frame_pose(self, frame: str) -> np.ndarray:
        """4x4 transform from the grasp frame to the world."""
        return planar_pose_matrix(*self._planar(frame))

    def to_world(self, xyyaw) -> np.ndarray:
        """(N, 3) top grasps (x, y, yaw) in the object frame -> world frame."""
        g = np.atleast_2d(np.asarray(xyyaw, dtype=float))
        if g.ndim != 2 or g.shape[1] != 3:
            raise ValueError(f"grasps: expected shape (N, 3) of (x, y, yaw), got {np.shape(xyyaw)}")
        if not np.all(np.isfinite(g)):
            raise ValueError("grasps: contain NaN or infinity")
        return absolute_planar_pose(g, np.asarray(self.scene.planar_pose(self.object_index), dtype=float))

    def _approaches_to_world(self, directions, targets, rolls, frame: str, names: Tuple[str, str]):
        """(N, 3) directions and targets and (N,) rolls (a number or (N,)) in `frame` -> world;
        the targets' (x, y) must lie on the table grown by TABLE_MARGIN (`names` in errors)."""
        D, P = (_rows3(a, n) for a, n in zip((directions, targets), names))
        if len(P) != len(D):
            raise ValueError(f"{names[1]}: need one per direction ({len(D)}), got {len(P)}")
        r = np.broadcast_to(np.asarray(rolls, dtype=float), (len(D),)) if np.ndim(rolls) == 0 else \
            np.asarray(rolls, dtype=float)
        if r.shape != (len(D),):
            raise ValueError(f"rolls: need a number or one per approach ({len(D)}), got shape {r.shape}")
        pose = np.asarray(self._planar(frame), dtype=float)
        Dw, Pw, rw = D, P, r
        if frame == "object":  # rows (x, y, yaw, z) placed by the object's planar pose, as top grasps
            Dw = _placed(np.c_[D[:, :2], np.zeros(len(D)), D[:, 2]], pose * [0, 0, 1])[:, [0, 1, 3]]
            finite_r = np.isfinite(r)
            placed = _placed(np.c_[P[:, :2], np.where(finite_r, r, 0.0), P[:, 2]], pose)
            Pw, rw = placed[:, [0, 1, 3]], np.where(finite_r, placed[:, 2], r)
        hx, hy = self.scene.table_size[0] / 2 + TABLE_MARGIN, self.scene.table_size[1] / 2 + TABLE_MARGIN
        off = np.flatnonzero((np.abs(Pw[:, 0]) > hx) | (np.abs(Pw[:, 1]) > hy))
        if len(off):
            i = int(off[0])
            where = names[1] if names[1] == "target" else f"{names[1]}[{i}]"
            raise ValueError(f"{where}: off the table: world (x, y) = ({Pw[i, 0]:.3f}, {Pw[i, 1]:.3f}) m is outside "
                             f"[-{hx:g}, {hx:g}] x [-{hy:g}, {hy:g}] (the table grown by {TABLE_MARGIN} m)")
        return Dw, Pw, (float(rw[0]) if np.ndim(rolls) == 0 and len(rw) else rw)

    # ---- grasps -------------------------------------------------------------------------
    def grasp(self, x: float, y: float, yaw: float, spread: Optional[float] = None,
              lift: bool = False) -> WorldGrasp:
        """One top grasp at (x, y, yaw) in the object frame: simulate, score, optionally lift."""
        return self._one(self.grasp_batch([[x, y, yaw]], spread=spread, lift=lift))

    def grasp_batch(self, xyyaw, spread: Optional[float] = None, lift: bool = False,
                    threads: int = 0, quality: bool = True) -> WorldGraspBatch:
        """N top grasps ((N, 3) rows x, y, yaw in the object frame) in C++ threads: the
        simulator's batch plus ``epsilon`` and ``volume`` (0 when the hand started in
        collision; NaN without ``quality``, see :meth:`epsilon_of`), and ``lifted`` /
        ``lift_displacement`` when ``lift`` is set (else None)."""
        world = self.to_world(xyyaw)
        b = self.sim.top_grasp_batch(world, spread=self._spread(spread), standoff=self.standoff, threads=threads)
        return self._score(b, b.contacts, np.diff(b.contacts.offsets), lift, threads, quality)

    def approach(self, direction, target, roll: float = 0.0, spread: Optional[float] = None,
                 standoff: Optional[float] = None, frame: str = "object", lift: bool = False) -> WorldGrasp:
        """One approach (see the module docs) in ``frame`` ('object' or 'world'): the hand moves
        along ``direction`` (3,) on the line through ``target`` (3,) with ``roll`` (rad), backs
        off by ``standoff`` (default: the world's) and closes; scored and optionally lifted."""
        if np.ndim(roll) != 0:
            raise ValueError(f"roll: expected a number, got shape {np.shape(roll)}")
        D, P, r = self._approaches_to_world(_vec3(direction, "direction"), _vec3(target, "target"), roll, frame,
                                            ("direction", "target"))
        g = self.sim.approach(D[0], P[0], r, spread=self._spread(spread), standoff=self._standoff(standoff))
        return self._one(self._score(_BatchOfOne(g), g.contacts, [g.num_contacts], lift, 1))

    def approach_batch(self, directions, targets, rolls=0.0, spread: Optional[float] = None,
                       standoff: Optional[float] = None, frame: str = "object", lift: bool = False,
                       threads: int = 0, quality: bool = True) -> WorldGraspBatch:
        """N approaches: ``directions`` and ``targets`` (N, 3), ``rolls`` a number or (N,), in
        ``frame``, in C++ threads; a WorldGraspBatch (errors name the entry, e.g. ``directions[2]``).
        Without ``quality`` epsilon and volume are NaN (:meth:`epsilon_of` computes them for chosen rows)."""
        D, P, r = self._approaches_to_world(directions, targets, rolls, frame, ("directions", "targets"))
        b = self.sim.approach_batch(D, P, r, spread=self._spread(spread), standoff=self._standoff(standoff),
                                    threads=threads)
        return self._score(b, b.contacts, np.diff(b.contacts.offsets), lift, threads, quality)

    def epsilon_of(self, batch: WorldGraspBatch, rows, threads: int = 1) -> np.ndarray:
        """GWS epsilon of the grasps ``rows`` of ``batch`` (made by this world), on their object
        contacts; 0 where the hand started in collision."""
        rows = np.asarray(rows, dtype=np.int64).ravel()
        grasps, back = np.unique(rows, return_inverse=True)
        c = batch.contacts
        grasp_of = np.repeat(np.arange(len(batch.epsilon)), np.diff(np.asarray(c.offsets, dtype=np.int64)))
        keep = ~np.asarray(c.on_table, dtype=bool) & np.isin(grasp_of, grasps)
        eps, _ = self._quality(c, keep, np.searchsorted(grasps, grasp_of[keep]), len(grasps), threads, volume=False)
        eps[np.asarray(batch.collision_at_start, dtype=bool)[grasps]] = 0.0
        return eps[back]

    def _quality(self, contacts, keep, grasp_of, n: int, threads: int, volume: bool = True):
        """Epsilon and volume of ``n`` grasps from the contacts selected by ``keep`` (the object's),
        ``grasp_of`` the grasp (0..n-1) of each selected contact, in one C++ batch call."""
        eps, vol = quality.epsilon_volume_batch(contacts.point[keep], contacts.normal[keep], self.com,
                                                self.torque_scale, mu=self.mu,
                                                counts=np.bincount(grasp_of, minlength=n), volume=volume,
                                                threads=threads)
        return np.array(eps, dtype=float), np.array(vol, dtype=float)

    def grasp_pose(self, hand_pose, spread: Optional[float] = None, frame: str = "object",
                   lift: bool = False) -> WorldGrasp:
        """The hand closed at one 4x4 ``hand_pose`` in ``frame`` (no approach); a start in
        collision is reported (``collision_at_start``); a pose that is not a rigid transform is a
        ValueError naming ``hand_pose``."""
        H = np.asarray(hand_pose, dtype=float)
        if H.shape != (4, 4):
            raise ValueError(f"hand_pose: expected shape (4, 4), got {H.shape}")
        g = self.sim.close(self._frame_pose(frame) @ H, self._spread(spread))
        return self._one(self._score(_BatchOfOne(g), g.contacts, [g.num_contacts], lift, 1))

    def grasp_poses(self, hand_poses, spread: Optional[float] = None, frame: str = "object",
                    lift: bool = False, threads: int = 0) -> WorldGraspBatch:
        """The hand closed at N 4x4 poses ((N, 4, 4) in ``frame``) in C++ threads; errors name the
        pose (``hand_poses[i]``)."""
        H = np.asarray(hand_poses, dtype=float)
        if H.ndim != 3 or H.shape[1:] != (4, 4):
            raise ValueError(f"hand_poses: expected shape (N, 4, 4), got {H.shape}")
        b = self.sim.close_batch(self._frame_pose(frame) @ H, self._spread(spread), threads=threads)
        return self._score(b, b.contacts, np.diff(b.contacts.offsets), lift, threads)

    def _spread(self, spread: Optional[float]) -> float:
        return self.spread if spread is None else float(spread)

    def _standoff(self, standoff: Optional[float]) -> float:
        return self.standoff if standoff is None else float(standoff)

    def _score(self, b, contacts, counts, lift: bool, threads: int, with_quality: bool = True) -> WorldGraspBatch:
        """The simulated grasps `b` (a GraspBatch or _BatchOfOne, with its contacts and their
        number per grasp) with epsilon and volume (0 when the hand started in collision), the
        object-frame poses, the contacts' parts and, when `lift` is set, the lift test."""
        c = contacts
        on_obj = ~np.asarray(c.on_table, dtype=bool)
        counts = np.asarray(counts, dtype=np.int64)
        # Quality on object contacts only, grasp by grasp in one C++ batch call.
        grasp_of = np.repeat(np.arange(len(counts)), counts)
        if with_quality:
            eps, vol = self._quality(c, on_obj, grasp_of[on_obj], len(counts), threads)
        else:
            eps, vol = np.full(len(counts), np.nan), np.full(len(counts), np.nan)
        start = np.asarray(b.collision_at_start, dtype=bool)
        eps[start], vol[start] = 0.0, 0.0
        lifted = displacement = None
        if lift:
            r = self.lift_tester().run_batch(b.hand_pose, b.joint_angles, threads=threads)
            lifted, displacement = r.lifted & ~start, np.array(r.displacement, dtype=float)
        parts = None
        obj = self.object
        if obj.parts is not None:
            parts = np.full(len(on_obj), None, dtype=object)
            parts[on_obj] = obj.part_of_faces(np.asarray(c.triangle)[on_obj])
        return WorldGraspBatch(b.joint_angles, c, eps, vol, start, b.hand_pose, b.link_contact, b.table_contact,
                               b.distance_queries, lifted, displacement, np.asarray(b.stopped_by_table, dtype=bool),
                               _rigid_inverse(self._frame_pose("object")) @ b.hand_pose,
                               tuple(self.hand.joint_names), parts)

    def _one(self, b: WorldGraspBatch) -> WorldGrasp:
        """Grasp 0 of a batch of one as a WorldGrasp."""
        return WorldGrasp(b.joint_angles[0], b.contact_records(0, self.hand.links), float(b.epsilon[0]), float(b.volume[0]),
                          bool(b.collision_at_start[0]), b.hand_pose[0],
                          None if b.lifted is None else bool(b.lifted[0]),
                          None if b.lifted is None else float(b.lift_displacement[0]),
                          bool(b.stopped_by_table[0]), b.hand_pose_object[0], b.joint_names)

    def lift_tester(self) -> physics.LiftTester:
        """The object's lift tests (prepared once per pose). A closed mesh of its own density
        weighs what its world-frame mesh integrates to (the core computes it); an open scan or a
        weighed object takes the ObjectModel's mass properties, placed in the world."""
        if self._lift is None:
            obj, T = self.object, self.scene.object_pose(self.object_index)
            given = obj.mass_method != "mesh" or obj.given_mass is not None
            mass = moved(obj.mass_properties_core, T) if given else None

            def pieces():   # when a grasp first needs them: the object-frame mesh's (cached across poses), placed
                own = obj.lift_pieces()
                if own is None:
                    own = physics.convex_decomposition(obj.vertices, obj.faces, name=obj.name)
                return [p @ T[:3, :3].T + T[:3, 3] for p in own]
            self._lift = physics.LiftTester(self.hand.core, self.vertices, self.faces, convex_pieces=pieces,
                                            mass_properties=mass, mu=self.mu, density=self.object.density,
                                            table=self.table)
        return self._lift


class _BatchOfOne:
    """A simulator GraspResult seen as a batch of one (the fields World._score reads)."""

    def __init__(self, g):
        self.joint_angles = g.joint_angles[None]
        self.collision_at_start = np.array([g.collision_at_start])
        self.stopped_by_table = np.array([g.stopped_by_table])
        self.hand_pose = g.hand_pose[None]
        self.link_contact = g.link_contact[None]
        self.table_contact = g.table_contact[None]
        self.distance_queries = np.array([g.distance_queries], dtype=np.int32)


def _placed(rows: np.ndarray, pose: np.ndarray) -> np.ndarray:
    """Rows (x, y, yaw, extra...) placed by the planar pose (absolute_planar_pose); rows with a
    non-finite entry stay as they are (the simulator names the argument)."""
    out = rows.copy()
    ok = np.isfinite(rows).all(axis=1)
    if ok.any():
        out[ok] = absolute_planar_pose(rows[ok], pose)
    return out


def _floats(a, name: str) -> np.ndarray:
    try:
        return np.asarray(a, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"{name}: expected numbers, got {a!r}") from None


def _rows3(a, name: str) -> np.ndarray:
    """An (N, 3) float array (the simulator checks the values)."""
    A = _floats(a, name)
    if A.ndim != 2 or A.shape[1] != 3:
        raise ValueError(f"{name}: expected shape (N, 3), got {A.shape}")
    return A


def _vec3(a, name: str) -> np.ndarray:
    """A (3,) float array as one (1, 3) row."""
    A = _floats(a, name)
    if A.shape != (3,):
        raise ValueError(f"{name}: expected 3 numbers, got shape {A.shape}")
    return A[None]


def _rigid_inverse(T: np.ndarray) -> np.ndarray:
    out = np.eye(4)
    out[:3, :3] = T[:3, :3].T
    out[:3, 3] = -T[:3, :3].T @ T[:3, 3]
    return out
