"""The robot's world: a hand, a table-top scene, the contact simulator, grasp quality and the
lift test, in one object.

A top grasp is given relative to the object frame (see :mod:`bayesgrasp.objects.scene`): the
hand, palm down, at (x, y) in the object frame with yaw relative to the object's yaw, descends
along -z to the first contact and closes::

    world = World.single("mug", pose=(0.1, 0.0, 0.3))
    g = world.grasp(0.0, 0.0, 0.0)                # one grasp: a WorldGrasp (joints, contacts, epsilon, ...)
    b = world.grasp_batch(xyyaw, threads=0)       # N grasps: a WorldGraspBatch of arrays

Pictures of a grasp are in :mod:`bayesgrasp.viz` (``viz.plot_grasp(world, g, path)``).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import List, Optional, Sequence, Union

import numpy as np

from .belief import absolute_planar_pose
from . import physics, quality
from .hand import Hand
from .objects import ObjectModel, Scene
from .sim import GraspSimulator

__all__ = ["World", "WorldGrasp", "WorldGraspBatch", "ContactRecord", "DEFAULT_FRICTION"]

DEFAULT_FRICTION = quality.DEFAULT_FRICTION


@dataclass(frozen=True)
class ContactRecord:
    """One contact of a :class:`WorldGrasp` (plain Python values, world frame)."""

    point: List[float]     # on the object's (or the table's) surface (m)
    normal: List[float]    # the object's outward unit normal (+z for the table)
    link: int              # hand link index (0 = palm)
    link_name: str
    penetration: float     # >= 0 (m)
    on_table: bool

    def to_dict(self) -> dict:
        return {"point": self.point, "normal": self.normal, "link": self.link, "link_name": self.link_name,
                "penetration": self.penetration, "on_table": self.on_table}


@dataclass(frozen=True)
class WorldGrasp:
    """One grasp tried in a :class:`World` (see :meth:`World.grasp`)."""

    joint_angles: np.ndarray          # (J,) closed joint angles (rad)
    contacts: List[ContactRecord]
    epsilon: float                    # GWS epsilon on the object contacts (0 when collision_at_start)
    volume: float                     # GWS volume
    collision_at_start: bool          # the open hand started in collision (no grasp)
    hand_pose: np.ndarray             # (4, 4) world pose where the hand stopped
    lifted: Optional[bool] = None     # lift-test verdict (None unless lifted)
    lift_displacement: Optional[float] = None  # m, the lift test's displacement

    def to_dict(self) -> dict:
        """The grasp as a dict of these fields (contacts as dicts)."""
        return {"joint_angles": self.joint_angles, "contacts": [c.to_dict() for c in self.contacts],
                "epsilon": self.epsilon, "volume": self.volume, "collision_at_start": self.collision_at_start,
                "hand_pose": self.hand_pose, "lifted": self.lifted, "lift_displacement": self.lift_displacement}


@dataclass(frozen=True)
class WorldGraspBatch:
    """N grasps tried in a :class:`World` (see :meth:`World.grasp_batch`); row i = grasp i."""

    joint_angles: np.ndarray        # (N, J)
    contacts: object                # sim BatchContacts: point, normal, link, penetration, on_table, grasp, offsets
    epsilon: np.ndarray             # (N,) GWS epsilon (0 when collision_at_start)
    volume: np.ndarray              # (N,) GWS volume
    collision_at_start: np.ndarray  # (N,) bool
    hand_pose: np.ndarray           # (N, 4, 4)
    link_contact: np.ndarray        # (N, L) bool
    table_contact: np.ndarray       # (N, L) bool
    distance_queries: np.ndarray    # (N,) FCL distance calls
    lifted: Optional[np.ndarray] = None             # (N,) bool when lift-tested, else None
    lift_displacement: Optional[np.ndarray] = None  # (N,) m when lift-tested, else None

    def __len__(self) -> int:
        return len(self.epsilon)


class World:
    """One object of a scene, a hand and everything needed to try grasps on it.

    Args:
        scene: the table-top scene; ``object_index`` selects the object to grasp (the
            simulator sees only that object; the others are not obstacles).
        hand: a :class:`Hand`, a built-in hand name or a hand file path.
        mu: friction coefficient for the quality metric and the lift test.
        spread: default finger spread (rad); None = the hand's default.
        standoff: how far the palm backs off from the first contact before closing (m).
    """

    def __init__(self, scene: Scene, hand: Union[Hand, str] = "barrett_bh8", object_index: int = 0,
                 mu: float = DEFAULT_FRICTION, spread: Optional[float] = None, standoff: float = 0.0):
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
        self.sim = GraspSimulator(self.hand, V, F)
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

    def to_world(self, xyyaw) -> np.ndarray:
        """(N, 3) top grasps (x, y, yaw) in the object frame -> world frame."""
        g = np.atleast_2d(np.asarray(xyyaw, dtype=float))
        if g.ndim != 2 or g.shape[1] != 3:
            raise ValueError(f"grasps: expected shape (N, 3) of (x, y, yaw), got {np.shape(xyyaw)}")
        if not np.all(np.isfinite(g)):
            raise ValueError("grasps: contain NaN or infinity")
        return absolute_planar_pose(g, np.asarray(self.scene.planar_pose(self.object_index), dtype=float))

    # ---- grasps -------------------------------------------------------------------------
    def grasp(self, x: float, y: float, yaw: float, spread: Optional[float] = None,
              lift: bool = False) -> WorldGrasp:
        """One top grasp at (x, y, yaw) in the object frame: simulate, score, optionally lift."""
        b = self.grasp_batch([[x, y, yaw]], spread=spread, lift=lift)
        names = self.hand.core.link_names
        c = b.contacts
        contacts = [ContactRecord(c.point[k].tolist(), c.normal[k].tolist(), int(c.link[k]), names[int(c.link[k])],
                                  float(c.penetration[k]), bool(c.on_table[k]))
                    for k in range(len(c.link))]
        return WorldGrasp(b.joint_angles[0], contacts, float(b.epsilon[0]), float(b.volume[0]),
                          bool(b.collision_at_start[0]), b.hand_pose[0],
                          None if b.lifted is None else bool(b.lifted[0]),
                          None if b.lifted is None else float(b.lift_displacement[0]))

    def grasp_batch(self, xyyaw, spread: Optional[float] = None, lift: bool = False,
                    threads: int = 0) -> WorldGraspBatch:
        """N top grasps ((N, 3) rows x, y, yaw in the object frame) in C++ threads: the
        simulator's batch plus ``epsilon`` and ``volume`` (0 when the hand started in
        collision), and ``lifted`` / ``lift_displacement`` when ``lift`` is set (else None)."""
        world = self.to_world(xyyaw)
        spread = self.spread if spread is None else float(spread)
        b = self.sim.top_grasp_batch(world, spread=spread, standoff=self.standoff, threads=threads)
        c = b.contacts
        on_obj = ~c.on_table
        counts = np.diff(c.offsets)
        # Quality on object contacts only, grasp by grasp in one C++ batch call.
        grasp_of = np.repeat(np.arange(len(counts)), counts)
        obj_counts = np.bincount(grasp_of[on_obj], minlength=len(counts))
        eps, vol = quality.epsilon_volume_batch(c.point[on_obj], c.normal[on_obj], self.com,
                                                self.torque_scale, mu=self.mu, counts=obj_counts,
                                                threads=threads)
        eps, vol = np.array(eps, dtype=float), np.array(vol, dtype=float)
        start = b.collision_at_start
        eps[start], vol[start] = 0.0, 0.0
        lifted = displacement = None
        if lift:
            r = self.lift_tester().run_batch(b.hand_pose, b.joint_angles, threads=threads)
            lifted, displacement = r.lifted & ~start, np.array(r.displacement, dtype=float)
        return WorldGraspBatch(b.joint_angles, c, eps, vol, start, b.hand_pose, b.link_contact, b.table_contact,
                               b.distance_queries, lifted, displacement)

    def lift_tester(self) -> physics.LiftTester:
        if self._lift is None:
            pieces = None
            if physics.is_concave(self.vertices, self.faces, self.hand.path):
                # Decompose the object-frame mesh (cached across poses), then place the pieces.
                obj, T = self.object, self.scene.object_pose(self.object_index)
                pieces = [p @ T[:3, :3].T + T[:3, 3] for p in physics.convex_decomposition(obj.vertices, obj.faces)]
            self._lift = physics.LiftTester(self.hand.path, self.vertices, self.faces, convex_pieces=pieces,
                                            mu=self.mu, density=self.object.density)
        return self._lift
