"""The robot's world: a hand, a table-top scene, the contact simulator, grasp quality and the
lift test, in one object.

A top grasp is given relative to the object frame (see :mod:`bayesgrasp.objects.scene`): the
hand, palm down, at (x, y) in the object frame with yaw relative to the object's yaw, descends
along -z to the first contact and closes. Results come back as numpy arrays::

    world = World.single("mug", pose=(0.1, 0.0, 0.3))
    g = world.grasp(0.0, 0.0, 0.0)                # one grasp: dict with joints, contacts, epsilon, ...
    b = world.grasp_batch(xyyaw, threads=0)       # N grasps: dict of arrays
"""
from __future__ import annotations

from typing import Optional, Sequence, Union

import numpy as np

from . import physics, quality
from .hand import Hand
from .objects import ObjectModel, Scene
from .sim import GraspSimulator

__all__ = ["World", "DEFAULT_FRICTION"]

DEFAULT_FRICTION = quality.DEFAULT_FRICTION


class World:
    """One object of a scene, a hand and everything needed to try grasps on it.

    Args:
        scene: the table-top scene; ``object_index`` selects the object to grasp (all objects
            other than that one are ignored by the simulator for now).
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
        ox, oy, oyaw = self.scene.planar_pose(self.object_index)
        c, s = np.cos(oyaw), np.sin(oyaw)
        out = np.empty_like(g)
        out[:, 0] = ox + c * g[:, 0] - s * g[:, 1]
        out[:, 1] = oy + s * g[:, 0] + c * g[:, 1]
        out[:, 2] = g[:, 2] + oyaw
        return out

    # ---- grasps -------------------------------------------------------------------------
    def grasp(self, x: float, y: float, yaw: float, spread: Optional[float] = None,
              lift: bool = False) -> dict:
        """One top grasp at (x, y, yaw) in the object frame: simulate, score, optionally lift.

        Returns a dict with ``joint_angles`` (J,), ``contacts`` (list of dicts with point,
        normal, link, link_name, penetration, on_table), ``epsilon``, ``volume``,
        ``collision_at_start``, ``hand_pose`` (4, 4) and ``lifted`` (None unless ``lift``).
        """
        b = self.grasp_batch([[x, y, yaw]], spread=spread, lift=lift)
        names = self.hand.core.link_names
        c = b["contacts"]
        contacts = [{"point": c["point"][k].tolist(), "normal": c["normal"][k].tolist(),
                     "link": int(c["link"][k]), "link_name": names[int(c["link"][k])],
                     "penetration": float(c["penetration"][k]), "on_table": bool(c["on_table"][k])}
                    for k in range(len(c["link"]))]
        return {"joint_angles": b["joint_angles"][0], "contacts": contacts,
                "epsilon": float(b["epsilon"][0]), "volume": float(b["volume"][0]),
                "collision_at_start": bool(b["collision_at_start"][0]), "hand_pose": b["hand_pose"][0],
                "lifted": None if b["lifted"] is None else bool(b["lifted"][0]),
                "lift_displacement": None if b["lifted"] is None else float(b["lift_displacement"][0])}

    def grasp_batch(self, xyyaw, spread: Optional[float] = None, lift: bool = False,
                    threads: int = 0) -> dict:
        """N top grasps ((N, 3) rows x, y, yaw in the object frame) in C++ threads.

        Returns the simulator's batch dict plus ``epsilon`` and ``volume`` (N,) (0 when the hand
        started in collision), and ``lifted`` / ``lift_displacement`` (N,) when ``lift`` is set
        (else None).
        """
        world = self.to_world(xyyaw)
        spread = self.spread if spread is None else float(spread)
        b = self.sim.top_grasp_batch(world, spread=spread, standoff=self.standoff, threads=threads)
        c = b["contacts"]
        on_obj = ~np.asarray(c["on_table"], dtype=bool)
        counts = np.diff(c["offsets"])
        # Quality on object contacts only, grasp by grasp in one C++ batch call.
        grasp_of = np.repeat(np.arange(len(counts)), counts)
        obj_counts = np.bincount(grasp_of[on_obj], minlength=len(counts))
        eps, vol = quality.epsilon_volume_batch(c["point"][on_obj], c["normal"][on_obj], self.com,
                                                self.torque_scale, mu=self.mu, counts=obj_counts,
                                                threads=threads)
        eps, vol = np.asarray(eps, dtype=float), np.asarray(vol, dtype=float)
        start = np.asarray(b["collision_at_start"], dtype=bool)
        eps[start], vol[start] = 0.0, 0.0
        b["epsilon"], b["volume"] = eps, vol
        b["lifted"], b["lift_displacement"] = None, None
        if lift:
            r = self.lift_tester().run_batch(b["hand_pose"], b["joint_angles"], threads=threads)
            lifted = np.asarray(r["lifted"], dtype=bool) & ~start
            b["lifted"], b["lift_displacement"] = lifted, np.asarray(r["displacement"], dtype=float)
        return b

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

    # ---- pictures -----------------------------------------------------------------------
    def hand_meshes(self, joint_angles, hand_pose, color="tab:gray", alpha: float = 1.0) -> list:
        """The hand's collision shapes as ``(V, F, color, alpha)`` meshes for :mod:`bayesgrasp.viz`."""
        from . import viz

        items = []
        for s in self.hand.link_geometry(joint_angles, hand_pose):
            if s["type"] == "capsule":
                V, F = viz.capsule_mesh(s["p0"], s["p1"], s["radius"])
            else:
                T = np.eye(4)
                T[:3, :3], T[:3, 3] = s["rotation"], s["center"]
                V, F = viz.box_mesh(T, s["half_extents"])
            items.append((V, F, color, alpha))
        return items

    def plot_grasp(self, grasp: dict, path, title: Optional[str] = None):
        """PNG of the scene with the hand closed as in ``grasp`` (a :meth:`grasp` result) and
        its object contacts marked."""
        from . import viz

        pts = np.array([c["point"] for c in grasp["contacts"] if not c["on_table"]]).reshape(-1, 3)
        return viz.plot_scene(
            self.scene, path, title=title,
            extra_meshes=self.hand_meshes(grasp["joint_angles"], grasp["hand_pose"], alpha=0.9),
            extra=(lambda ax: viz.draw_points(ax, pts, color="red", size=25)) if len(pts) else None)
