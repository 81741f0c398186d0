"""The parallel-jaw gripper (issue 31): prismatic jaws with convex mesh fingers from a URDF,
through the closing simulation (a derivable oracle), the lift test (it presses with the jaw's
force), grasp, plan, category and the viewer, with its own models (small settings)."""
import json

import numpy as np
import pytest
import trimesh

from bayesgrasp import physics
from bayesgrasp.hand import Hand
from bayesgrasp.io.grasp_schema import validate
from bayesgrasp.models.task_grasps import TaskGraspSettings, generate_task_grasps, grasp_to_json
from bayesgrasp.models.tasks import task_rule
from bayesgrasp.objects import load_object
from bayesgrasp.sim import GraspSimulator
from testkit import cli_json, small

JAW = "parallel_jaw.urdf"


@pytest.fixture(scope="module")
def jaw():
    return Hand.load(JAW)


def test_the_jaw_hand_is_two_prismatic_fingers_measured_by_their_travel(jaw):
    assert jaw.num_fingers == 2 and jaw.num_joints == 3 and jaw.spread_limits == (0.0, 0.0)
    assert list(jaw.prismatic_joints) == [False, True, True]
    np.testing.assert_allclose(jaw.joint_limits[1:], [[0.0, 0.04], [0.0, 0.04]])
    assert list(jaw.measured_joints) == [1, 2]
    np.testing.assert_allclose(jaw.measurement_scale, [0.05, 0.05])
    shapes = jaw.link_shapes()
    assert [s.type for s in shapes[1]] == ["convex"] and shapes[1][0].vertices.shape == (8, 3)
    np.testing.assert_allclose(jaw.joint_torques[1:], [70.0, 70.0])   # N: the jaws' force


@pytest.mark.parametrize("width", [0.02, 0.05, 0.07])
def test_each_jaw_stops_at_the_box_face(jaw, width):
    """A tall box of width w between the jaws (the palm lands on its top). Square on, each jaw
    travels 0.04 - w / 2 to the face; turned by yaw, the pad's corner (10.5 mm off its centre)
    meets the face first: travel 0.04 - (w / 2 + 0.0105 sin yaw) / cos yaw. Within the contact
    tolerance."""
    post = trimesh.creation.box(extents=[0.04, width, 0.1])   # its faces wider than the pads
    post.apply_translation([0, 0, 0.05])
    sim = GraspSimulator(jaw, post.vertices, post.faces, table=False)
    for yaw in (0.0, 0.1, 0.2):
        g = sim.top_grasp(0.0, 0.0, yaw, spread=0.0)   # yaw 0: the jaws close along the world's y
        expected = 0.04 - (0.5 * width + 0.0105 * np.sin(yaw)) / np.cos(yaw)
        got = np.asarray(g.joint_angles[1:])
        assert np.all(got <= expected + 1e-9) and np.all(got >= expected - sim.options.contact_tolerance - 1e-9), \
            (yaw, got, expected)
        links = np.asarray(g.contacts.link)[~np.asarray(g.contacts.on_table, bool)]
        assert {1, 2} <= set(links.tolist())


def test_the_lift_test_presses_with_the_jaw_force(jaw):
    """Metamorphic on a fixed grasp set of the cylinder: the held count does not fall as the jaw
    force rises (5, 20, 70 N) and does not rise as the object gets 8 times heavier."""
    cyl = load_object("cylinder")
    rng = np.random.default_rng(0)
    lo, hi = cyl.bounds
    xy = np.c_[rng.uniform(lo[0], hi[0], 40), rng.uniform(lo[1], hi[1], 40), rng.uniform(-np.pi, np.pi, 40)]
    b = GraspSimulator(jaw, cyl.vertices, cyl.faces).top_grasp_batch(xy, spread=0.0)
    poses, q = np.asarray(b.hand_pose), np.asarray(b.joint_angles)
    held = [int(np.sum(physics.LiftTester(jaw, cyl.vertices, cyl.faces, finger_torque=f * 0.05)
                       .run_batch(poses, q).lifted)) for f in (5.0, 20.0, 70.0)]
    assert held[0] <= held[1] <= held[2] and held[2] >= 3, held
    heavy = int(np.sum(physics.LiftTester(jaw, cyl.vertices, cyl.faces, finger_torque=3.5, density=8 * 1000.0)
                       .run_batch(poses, q).lifted))
    light = int(np.sum(physics.LiftTester(jaw, cyl.vertices, cyl.faces, finger_torque=3.5, density=1000.0)
                       .run_batch(poses, q).lifted))
    assert heavy <= light


def test_grasp_command_with_the_jaw(capsys):
    doc = cli_json(capsys, "grasp", "--object", "cube", "--top", "0,0,0", "--hand", JAW, "--json")
    validate(doc["grasp"])                                   # the one grasp schema
    assert doc["hand"].startswith("Parallel-jaw") and doc["lifted"] is True
    q = doc["grasp"]["joint_positions"]
    assert len(q) == 3 and abs(q[1] - 0.01) < 5e-4 and abs(q[2] - 0.01) < 5e-4   # a 6 cm cube: 1 cm of travel each


def test_plan_category_and_view_with_the_jaw(capsys, tmp_path):
    from testkit import served_nodes

    from bayesgrasp.viewer import scene_from_result

    plan = cli_json(capsys, "plan", "--object", "cube", "--true-pose", "0.02,-0.01,0.4", "--attempts", 2,
                    "--hand", JAW, *small(tmp_path / "m"), "--json")
    for a in plan["attempts"]:
        assert len(a["joint_angles"]) == 2 and all(0.0 <= x <= 0.04 + 1e-9 for x in a["joint_angles"])
    models = json.loads(next(f for f in (tmp_path / "m").glob("*.json") if "joint_index" in f.read_text()).read_text())
    assert models["joint_index"] == [1, 2] and models["measurement_scale"] == [0.05, 0.05]
    grasps = []
    for m in ("mug/1", "mug/2"):
        grasps += generate_task_grasps(m, task_rule("mug", "top"), hand=JAW,
                                       settings=TaskGraspSettings(candidates=150, spreads=(0.0,), lift_tests=6, keep=2))
    assert grasps and all(g.lifted for g in grasps)
    f = tmp_path / "grasps.json"
    f.write_text(json.dumps({"grasps": [grasp_to_json(g) for g in grasps]}))
    excluded = [f"mug/{i}" for i in range(7) if i not in (1, 2)]
    cat = cli_json(capsys, "category", "--category", "mug", "--task", "top", "--scene-object", "mug/3", "--object-pose",
                   "0.01,0.02,0.7", "--hand", JAW, "--task-grasps", f, "--exclude", *excluded,
                   "--seed", 3, "--json")
    assert cat["executed"] and cat["success"] == (cat["lifted"] and cat["task_ok"])
    for doc in (plan, cat):
        nodes, _ = served_nodes(scene_from_result(doc))
        assert any("/hand/left_jaw" in n for n in nodes) and any("/hand/right_jaw" in n for n in nodes)
