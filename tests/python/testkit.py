"""Helpers shared by several test files (imported as ``from testkit import ...``); shared
fixtures live in conftest.py."""
import json
import socket
import subprocess
import sys

import numpy as np

from bayesgrasp import _core
from bayesgrasp.cli import main
from bayesgrasp.hand import Hand
from bayesgrasp.models import ModelSettings, ModelTable, build_models
from bayesgrasp.planners.category import TaskGrasp


# ---- the command line ---------------------------------------------------------------------------
def run_cli(*args):
    p = subprocess.run([sys.executable, "-m", "bayesgrasp.cli", *args], capture_output=True, text=True)
    return p.returncode, p.stdout, p.stderr


def without_set(options):
    """The options without their --set pairs: the category commands read no model settings (and
    refuse them; fuse and the pose planners take them)."""
    out, skip = [], False
    for a in options:
        if skip:
            skip = False
        elif a == "--set":
            skip = True
        else:
            out.append(a)
    return out


SET = {"n_samples": 300, "n_inducing": 50, "max_iter": 30, "n_lift_samples": 150, "n_calibration": 100, "n_pilot": 40,
       "n_pilot_lifts": 10}
KEEP = ("mug/1", "mug/2")


def small(cache) -> list:
    return ["--cache", str(cache)] + [a for k, v in SET.items() for a in ("--set", f"models.{k}={v}")]


def task_grasp_options(d, keep=KEEP, seed=3, settings=None) -> list:
    """Category options on small models (``settings``: model settings; default SET) with a few
    demonstrated top grasps of the training mugs ``keep`` written to ``d``/grasps.json; the
    other mugs excluded."""
    from bayesgrasp.models.task_grasps import TaskGraspSettings, generate_task_grasps, grasp_to_json
    from bayesgrasp.models.tasks import task_rule

    grasps = []
    for m in keep:
        grasps += generate_task_grasps(m, task_rule("mug", "top"),
                                       settings=TaskGraspSettings(candidates=150, spreads=(0.0, float(np.radians(60))),
                                                                  lift_tests=6, keep=2))
    f = d / "grasps.json"
    f.write_text(json.dumps({"grasps": [grasp_to_json(g) for g in grasps]}))
    exclude = [f"mug/{i}" for i in range(7) if f"mug/{i}" not in keep]
    sets = [a for k, v in (settings or SET).items() for a in ("--set", f"models.{k}={v}")]
    return ["--cache", str(d / "models"), "--task-grasps", str(f), "--exclude", *exclude, "--seed", str(seed), *sets]


def cli_json(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    assert code == 0, err
    return json.loads(out)


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def port_free(port: int) -> bool:
    with socket.socket() as s:
        s.settimeout(1.0)
        return s.connect_ex(("127.0.0.1", port)) != 0


def served_nodes(scene) -> dict:
    """The scene's nodes by name (through viser's scene API), the server stopped after."""
    from bayesgrasp.viewer import serve
    from bayesgrasp.viewer.serve import stop

    port = free_port()
    server, view = serve(scene, port=port)
    try:
        return dict(server.scene._handle_from_node_name), view
    finally:
        stop(server)
        assert port_free(port)


# ---- category planner: synthetic task grasps ----------------------------------------------------
def rz(yaw, t=(0, 0, 0)):
    T = np.eye(4)
    c, s = np.cos(yaw), np.sin(yaw)
    T[:2, :2] = [[c, -s], [s, c]]
    T[:3, 3] = t
    return T


HAND = Hand.load("barrett_bh8")
# a palm-down grasp 30 cm above the model's origin: far from the table, nothing else around
TOP = Hand.top_grasp_pose(0.0, 0.0, 0.0, 0.3)


def grasp(model, pose, eps=0.2, spread=0.5):
    return TaskGrasp(model=model, task="top", pose=pose, spread=spread, epsilon=eps, lifted=True)


# ---- fusion: models with analytic tables --------------------------------------------------------
R = 0.06


class TableModels:
    """The planners' view of GraspModels: n_joints and a ModelTable."""

    def __init__(self, table, k=2):
        self._table, self.n_joints = table, k

    def table(self):
        return self._table


def analytic(informative: bool):
    xs = np.linspace(-R, R, 25)
    yaws = -np.pi + 2 * np.pi * np.arange(36) / 36
    X, Y, T = np.meshgrid(xs, xs, yaws, indexing="ij")
    x, y = X.ravel(), Y.ravel()
    ps = np.exp(-(x ** 2 + y ** 2) / (2 * 0.01 ** 2))                   # stable when centred
    if informative:
        mean = np.column_stack([10 * x, 10 * y])
    else:
        mean = np.full((len(x), 2), 0.3)
    var = np.full((len(x), 2), 0.0025)
    grid = _core.belief.RelativePoseGrid(np.array([-R, -R]), np.array([R, R]), 25, 25, 36,
                                         np.column_stack([ps, mean, var]), np.array([0.0] + [np.nan] * 4))
    return TableModels(ModelTable(grid, 2, np.array([[-R, -R], [R, R]]), np.zeros((1, 3))))


TRUE = np.array([0.01, -0.005, 0.0])


def measurement(grasp):
    rel = np.asarray(grasp) - TRUE   # yaw 0: the relative grasp is the difference
    return np.array([10 * rel[0], 10 * rel[1]])


# ---- a small planner ----------------------------------------------------------------------------
def tiny_planner():
    """A stability planner on the cube's models built with TINY settings (seconds)."""
    from bayesgrasp.planners import make_planner

    models = build_models("cube", settings=TINY, cache_dir=None)
    return make_planner("stability", models, estimate=(0.0, 0.0, 0.0))


TINY = ModelSettings(n_samples=120, n_inducing=20, xy_range=0.03, max_iter=10, seed=5, n_lift_samples=20,
                     n_calibration=0, n_pilot=20, spread=0.0)


def urdf_fk(urdf: str, values: dict) -> dict:
    """Every link's pose in the URDF's root frame with the joints at ``values`` (name -> rad or m):
    the URDF's own chain (origin, then the joint's motion about or along its axis), read with
    yourdfpy; independent of our conversion."""
    import yourdfpy
    from scipy.spatial.transform import Rotation

    robot = yourdfpy.URDF.load(urdf, build_scene_graph=False, load_meshes=False).robot
    parent = {j.child: j for j in robot.joints}

    def pose(link):
        if link not in parent:
            return np.eye(4)
        j = parent[link]
        T = pose(j.parent) @ (np.eye(4) if j.origin is None else np.asarray(j.origin, float))
        M = np.eye(4)
        if j.type in ("revolute", "continuous"):
            M[:3, :3] = Rotation.from_rotvec(np.asarray(j.axis, float) * values.get(j.name, 0.0)).as_matrix()
        elif j.type == "prismatic":
            M[:3, 3] = np.asarray(j.axis, float) * values.get(j.name, 0.0)
        return T @ M
    return {l.name: pose(l.name) for l in robot.links}
