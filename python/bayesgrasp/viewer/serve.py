"""A :class:`~.scene.ResultScene` in the browser (viser): the nodes, a slider over the steps and a
toggle per layer. Node names (the tests check them through viser's scene API):

``/table``, ``/object/<part>``, ``/cloud``, and per step k ``/steps/k/hand/<link>-<i>``,
``/steps/k/pregrasp/<link>-<i>``, ``/steps/k/approach``, ``/steps/k/contacts``,
``/steps/k/normals``, ``/steps/k/models/<name>``, ``/steps/k/particles`` (one point per particle,
coloured by weight), ``/steps/k/particle_copies`` (the heaviest as faint copies of the object),
``/steps/k/lift_trace`` (the object's path in the hand) and ``/steps/k/lift_end`` (the object where
the lift left it, relative to the hand). A grasp record with a reachable ``arm`` adds the arm's
moving collision shapes at the grasp, ``/steps/k/arm/<shape>-<i>`` (each a mesh in the shape's own
frame, the node posed by the arm's forward kinematics), its base and palm frames
``/steps/k/arm/base`` and ``/steps/k/arm/palm``, and the same shapes faint at the pre-grasp,
``/steps/k/arm_pregrasp/<shape>-<i>`` (the "pregrasp" toggle); an unreachable one draws no arm and
its reason is in the step's text.
"""
from __future__ import annotations

import contextlib
import io
import sys
from functools import lru_cache
from typing import Dict, List, Optional, Tuple

import numpy as np

from ..hand import Hand, builtin_hands
from ..viz import shape_mesh
from .arm import arm_view, link_meshes, stick_points
from .scene import ResultScene, Step, planar_transform

LAYERS = ("object", "hand", "arm", "pregrasp", "approach", "contacts", "models", "particles", "lift trace", "cloud")
MAX_COPIES = 15       # the heaviest particles drawn as faint copies of the object
PART_COLOURS = [(230, 150, 60), (70, 140, 220), (90, 180, 90), (200, 80, 160), (160, 160, 60), (90, 200, 200)]
HAND_COLOUR, PREGRASP_COLOUR, CONTACT_COLOUR = (120, 120, 130), (180, 180, 200), (230, 30, 30)
ARM_COLOUR = (235, 120, 40)
TABLE_HALF = 0.25     # m, half side of the drawn table square


def weight_colours(w) -> np.ndarray:
    """(N, 3) uint8 colours for weights (viridis over w / max w: dark = light weight)."""
    from matplotlib import colormaps

    w = np.asarray(w, float)
    return (255 * colormaps["viridis"](w / w.max() if w.size and w.max() > 0 else w)[:, :3]).astype(np.uint8)


def _wxyz(R) -> np.ndarray:
    from scipy.spatial.transform import Rotation

    x, y, z, w = Rotation.from_matrix(R).as_quat().T
    return np.stack([w, x, y, z], axis=-1)


def _rgb(weight: float, base=(70, 140, 220)) -> Tuple[int, int, int]:
    return tuple(int(c) for c in np.asarray(base) * (0.4 + 0.6 * float(np.clip(weight, 0, 1))))


def _placed(V: np.ndarray, T: np.ndarray) -> np.ndarray:
    return V @ T[:3, :3].T + T[:3, 3]


def hand_link_meshes(hand: Hand, q, pose) -> List[Tuple[str, np.ndarray, np.ndarray]]:
    """The hand's collision shapes at joints ``q`` and 4x4 ``pose`` as (name, V, F) meshes."""
    out, count = [], {}
    for s in hand.link_geometry(np.asarray(q, float), np.asarray(pose, float)):
        V, F = shape_mesh(s)
        i = count[s.name] = count.get(s.name, -1) + 1
        out.append((f"{s.name.replace('/', '_')}-{i}", np.asarray(V, float), np.asarray(F, np.int32)))
    return out


@lru_cache(maxsize=32)
def _model_mesh(name: str) -> Tuple[np.ndarray, np.ndarray]:
    from ..objects import load_object

    m = load_object(name)
    return np.asarray(m.vertices, float), np.asarray(m.faces, np.int32)


@lru_cache(maxsize=8)
def hand_named(name: str) -> Hand:
    """The hand a grasp record names: a built-in hand's file name, its display name, or a hand file."""
    for builtin in builtin_hands():
        hand = Hand.load(builtin)
        if name in (builtin, hand.name):
            return hand
    return Hand.load(name)


class SceneView:
    """The scene's nodes on a viser server, with the GUI (slider, layer toggles)."""

    def __init__(self, server, scene: ResultScene):
        self.server, self.scene = server, scene
        self.layers: Dict[Tuple[Optional[int], str], list] = {}
        self.arm_notes: Dict[int, str] = {}        # per step: the arm drawn, or why none is
        self._arm_points: List[np.ndarray] = []    # the arms' stick figures, for the camera
        self._add_static()
        for k, step in enumerate(scene.steps):
            self._add_step(k, step)
        self._add_gui()
        self.frame_camera()
        self.show(len(scene.steps) - 1 if scene.steps else 0)

    # ---- nodes ----
    def _keep(self, k: Optional[int], layer: str, handle) -> None:
        self.layers.setdefault((k, layer), []).append(handle)

    def _add_static(self) -> None:
        sc, add = self.scene, self.server.scene
        h = TABLE_HALF
        add.add_box("/table", color=(200, 190, 170), dimensions=(2 * h, 2 * h, 0.01), position=(0.0, 0.0, -0.005))
        if sc.object is not None and sc.object_pose is not None:
            T = planar_transform(sc.object_pose)
            V = _placed(sc.object.vertices, T)
            F = np.asarray(sc.object.faces, np.int32)
            parts = sc.object.parts
            names = sc.object.part_names or ("body",)
            ids = np.zeros(len(F), int) if parts is None else np.asarray(parts)
            for i in np.unique(ids):
                name = names[i] if i < len(names) else f"part{i}"
                self._keep(None, "object", add.add_mesh_simple(f"/object/{name}", V, F[ids == i],
                                                               color=PART_COLOURS[i % len(PART_COLOURS)]))
        if sc.cloud is not None and len(sc.cloud):
            self._keep(None, "cloud", add.add_point_cloud("/cloud", np.asarray(sc.cloud, np.float32),
                                                          colors=(40, 40, 40), point_size=0.003))

    def _add_step(self, k: int, step: Step) -> None:
        add, base = self.server.scene, f"/steps/{k}"
        g = step.grasp
        if g is not None:
            hand = hand_named(g["hand"])
            for name, V, F in hand_link_meshes(hand, g["joint_positions"], g["pose"]):
                self._keep(k, "hand", add.add_mesh_simple(f"{base}/hand/{name}", V, F, color=HAND_COLOUR))
            pre = g["pregrasp"]
            for name, V, F in hand_link_meshes(hand, pre["joint_positions"], pre["pose"]):
                self._keep(k, "pregrasp", add.add_mesh_simple(f"{base}/pregrasp/{name}", V, F, color=PREGRASP_COLOUR,
                                                              opacity=0.25))
            p0 = np.asarray(pre["pose"], float)[:3, 3]
            p1 = np.asarray(g["position"], float)
            self._keep(k, "approach", add.add_arrows(f"{base}/approach", np.array([[p0, p1]]), colors=(20, 20, 20),
                                                     shaft_radius=0.002, head_radius=0.006, head_length=0.012))
            self._add_arm(k, g)
        if step.contacts:
            P = np.array([c.point for c in step.contacts])
            N = np.array([c.normal for c in step.contacts])
            self._keep(k, "contacts", add.add_point_cloud(f"{base}/contacts", P.astype(np.float32),
                                                          colors=CONTACT_COLOUR, point_size=0.008,
                                                          point_shape="circle"))
            self._keep(k, "contacts", add.add_arrows(f"{base}/normals", np.stack([P, P + 0.03 * N], axis=1),
                                                     colors=CONTACT_COLOUR, shaft_radius=0.001, head_radius=0.003,
                                                     head_length=0.006))
        for name, T, weight in step.models:
            if T is None:
                continue
            m = _model_mesh(name)
            self._keep(k, "models", add.add_mesh_simple(f"{base}/models/{name.replace('/', '_')}", _placed(m[0], T),
                                                        m[1], color=_rgb(weight),
                                                        opacity=0.15 + 0.5 * float(np.clip(weight, 0, 1))))
        if step.belief:
            self._add_particles(k, step.belief)
        if step.trace and g is not None:
            self._add_trace(k, step.trace)

    def _add_arm(self, k: int, g: dict) -> None:
        """The arm of grasp record ``g`` at the grasp ("arm") and faint at the pre-grasp ("pregrasp"),
        each shape's mesh posed by T_joint(q) M_shape; no arm and a note when it is unreachable."""
        view = arm_view(g)
        if view is None:
            return
        self.arm_notes[k] = view.note
        if view.arm is None:
            return
        add, base, arm = self.server.scene, f"/steps/{k}", view.arm
        for name, V, F, T in link_meshes(arm, view.q):
            self._keep(k, "arm", add.add_mesh_simple(f"{base}/arm/{name}", V, F, color=ARM_COLOUR,
                                                     wxyz=_wxyz(T[:3, :3]), position=T[:3, 3]))
        for name, T in (("base", arm.base), ("palm", arm.palm_poses(view.q)[0])):
            self._keep(k, "arm", add.add_frame(f"{base}/arm/{name}", axes_length=0.08, axes_radius=0.004,
                                               wxyz=_wxyz(T[:3, :3]), position=T[:3, 3]))
        self._arm_points.append(stick_points(arm, view.q))
        if view.q_pre is not None:
            for name, V, F, T in link_meshes(arm, view.q_pre):
                self._keep(k, "pregrasp", add.add_mesh_simple(f"{base}/arm_pregrasp/{name}", V, F, color=ARM_COLOUR,
                                                              opacity=0.25, wxyz=_wxyz(T[:3, :3]), position=T[:3, 3]))

    def _add_particles(self, k: int, belief: dict) -> None:
        """The belief's particles: a point each (on the table, coloured by weight) and the heaviest
        as faint copies of the object."""
        add, base = self.server.scene, f"/steps/{k}"
        X, w = np.asarray(belief["particles"], float).reshape(-1, 3), np.asarray(belief["weights"], float)
        if not len(X):
            return
        colours = weight_colours(w)
        P = np.column_stack([X[:, :2], np.full(len(X), 0.002)]).astype(np.float32)
        self._keep(k, "particles", add.add_point_cloud(f"{base}/particles", P, colors=colours, point_size=0.004,
                                                       point_shape="circle"))
        obj = self.scene.object
        if obj is None:
            return
        top = np.argsort(-w, kind="stable")[:MAX_COPIES]
        R = np.array([planar_transform(x)[:3, :3] for x in X[top]])
        pos = np.column_stack([X[top, :2], np.zeros(len(top))])
        self._keep(k, "particles", add.add_batched_meshes_simple(
            f"{base}/particle_copies", np.asarray(obj.vertices, np.float32), np.asarray(obj.faces, np.int32),
            batched_wxyzs=_wxyz(R), batched_positions=pos, batched_colors=colours[top],
            batched_opacities=0.04 + 0.12 * w[top] / w.max(), cast_shadow=False, receive_shadow=False))

    def _add_trace(self, k: int, trace: dict) -> None:
        """The lift test's trace: the object's path in the hand, and the object where it ended."""
        add, base = self.server.scene, f"/steps/{k}"
        path = np.asarray(trace["path"], float).reshape(-1, 3)
        if len(path) >= 2:
            seg = np.stack([path[:-1], path[1:]], axis=1).astype(np.float32)
            self._keep(k, "lift trace", add.add_line_segments(f"{base}/lift_trace", seg, colors=(250, 120, 0),
                                                              thickness=3.0, thickness_units="screen"))
        sc = self.scene
        if sc.object is not None and sc.object_pose is not None and trace.get("slip") is not None:
            T = np.asarray(trace["slip"], float) @ planar_transform(sc.object_pose)
            self._keep(k, "lift trace", add.add_mesh_simple(f"{base}/lift_end", _placed(sc.object.vertices, T),
                                                            np.asarray(sc.object.faces, np.int32), color=(250, 120, 0),
                                                            opacity=0.3))

    def frame_camera(self) -> None:
        """The initial camera: looking at the object (or the grasps) from the front, above."""
        sc = self.scene
        if sc.object is not None and sc.object_pose is not None:
            V = _placed(sc.object.vertices, planar_transform(sc.object_pose))
        else:
            V = np.array([g.grasp["position"] for g in sc.steps if g.grasp] or [[0.0, 0.0, 0.05]])
        if self._arm_points:                       # the arms too, from their bases to the palms
            V = np.vstack([V, *self._arm_points])
        centre = 0.5 * (V.min(axis=0) + V.max(axis=0))
        r = max(float(np.linalg.norm(V.max(axis=0) - V.min(axis=0))), 0.1)
        cam = self.server.initial_camera
        cam.look_at = tuple(centre)
        cam.position = tuple(centre + r * np.array([1.0, -1.3, 0.9]))
        cam.up = (0.0, 0.0, 1.0)

    # ---- GUI ----
    def _add_gui(self) -> None:
        gui = self.server.gui
        gui.add_markdown(f"**{self.scene.title}**")
        n = len(self.scene.steps)
        self.slider = gui.add_slider("step", min=0, max=max(n - 1, 1), step=1, initial_value=max(n - 1, 0),
                                     disabled=n < 2)
        self.label = gui.add_markdown("")
        self.toggles = {layer: gui.add_checkbox(layer, initial_value=layer != "pregrasp") for layer in LAYERS}
        if self.scene.steps and any(s.belief for s in self.scene.steps):
            gui.add_markdown("particles: viridis by weight (yellow = heaviest)")
        self.slider.on_update(lambda _: self.show(int(self.slider.value)))
        for t in self.toggles.values():
            t.on_update(lambda _: self.show(int(self.slider.value)))

    def show(self, k: int) -> None:
        """Step ``k`` with the toggled layers; the other steps hidden."""
        self.current = k
        for (step, layer), handles in self.layers.items():
            on = (step is None or step == k) and self.toggles[layer].value
            for h in handles:
                h.visible = on
        if self.scene.steps:
            s = self.scene.steps[k]
            self.label.content = f"{s.label}: {s.outcome}" + (
                "; " + ", ".join(f"{m} {w:.2f}" for m, _, w in s.models) if s.models else "") + (
                "; " + self.arm_notes[k] if k in self.arm_notes else "")


def serve(scene: ResultScene, port: int = 8080, host: str = "127.0.0.1", say=None):
    """A viser server on ``host`` showing the scene (the next free port if ``port`` is busy).
    Returns (server, view); ``server.stop()`` ends it."""
    import viser

    say = say or (lambda m: print(m, file=sys.stderr))
    with contextlib.redirect_stdout(io.StringIO()):      # viser's banner: the caller prints the URL
        server = viser.ViserServer(host=host, port=port, verbose=False)
    if server.get_port() != port:
        say(f"port {port} is in use; serving on {server.get_port()}")
    server.scene.set_up_direction("+z")
    return server, SceneView(server, scene)


def stop(server) -> None:
    """Stops the server without viser's line on stdout (stdout may be a command's JSON)."""
    with contextlib.redirect_stdout(io.StringIO()):
        server.stop()
