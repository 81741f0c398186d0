"""The arm: kinematics read from a URDF, batched IK and the reachability check (issue 57).

Oracles: a planar two-link arm (links 0.5 and 0.3 m) reaches exactly the annulus
0.2 <= r <= 0.8 about its base; with its elbow held to |q2| <= 0.5 rad it reaches only
r >= sqrt(l1^2 + l2^2 + 2 l1 l2 cos 0.5) (law of cosines); the KUKA's IK solutions are driven
through forward kinematics computed by yourdfpy from the URDF's own chain (testkit.urdf_fk),
not through our kinematics; a wall between the arm and the grasp, and a grasp under the table,
leave no configuration free of them.
"""
from pathlib import Path

import numpy as np
import pytest
import trimesh
from scipy.spatial.transform import Rotation

from bayesgrasp.arm import Arm, ReachOptions, check_reach, default_mount, palm_depth
from bayesgrasp.arm.ik import rotation_log
from bayesgrasp.hand import Hand
from testkit import urdf_fk

PLANAR = Path(__file__).resolve().parents[1] / "data" / "arms" / "planar_2link.urdf"
L1, L2, Z = 0.5, 0.3, 0.1


def planar_targets(radii, angles):
    """Palm poses in the planar arm's plane at (r cos a, r sin a, Z), the approach (palm z) pointing
    radially outwards, so that backing off stays in the plane."""
    P = np.tile(np.eye(4), (len(radii), 1, 1))
    for i, (r, a) in enumerate(zip(radii, angles)):
        out = np.array([np.cos(a), np.sin(a), 0.0])
        P[i, :3, :3] = np.column_stack([np.array([0.0, 0.0, 1.0]), np.cross(out, [0.0, 0.0, 1.0]), out])   # y = z x x
        P[i, :3, 3] = [r * np.cos(a), r * np.sin(a), Z]
    assert np.allclose(np.linalg.det(P[:, :3, :3]), 1.0)
    return P


def top_grasp(x, y, z, yaw=0.0):
    """A palm pose at (x, y, z) approaching straight down (palm z = -z of the table)."""
    T = np.eye(4)
    T[:3, :3] = Rotation.from_euler("z", yaw).as_matrix() @ np.diag([1.0, -1.0, -1.0])
    T[:3, 3] = [x, y, z]
    return T


PLANAR_OPTIONS = ReachOptions(position_only=True, pregrasp_distance=0.02, seeds=6)


def test_planar_arm_reaches_exactly_its_annulus():
    """Inside 0.2 < r < 0.8 (and the pre-grasp 0.02 m nearer the base still inside): reachable;
    inside the hole or beyond the outer circle: refused, "no IK solution"."""
    rng = np.random.default_rng(4)
    inside = np.array([0.25, 0.3, 0.45, 0.6, 0.72, 0.78])
    outside = np.array([0.05, 0.12, 0.17, 0.83, 0.9, 1.2])
    radii = np.r_[inside, outside]
    P = planar_targets(radii, rng.uniform(-np.pi, np.pi, radii.size))
    arm = Arm.load(PLANAR)
    res = check_reach(arm, P, options=PLANAR_OPTIONS)
    assert res.reachable.tolist() == [True] * inside.size + [False] * outside.size, (radii, res.reason)
    assert res.reason[inside.size:] == ["no IK solution"] * outside.size
    assert res.joint_names == ["shoulder", "elbow"]
    # the solution is an elbow angle given by the law of cosines: r^2 = l1^2 + l2^2 + 2 l1 l2 cos q2
    cos_q2 = (inside ** 2 - L1 ** 2 - L2 ** 2) / (2 * L1 * L2)
    assert np.allclose(np.cos(res.q[:inside.size, 1]), cos_q2, atol=1e-3)
    # the pre-grasp's elbow: 0.02 m nearer the base
    cos_pre = ((inside - 0.02) ** 2 - L1 ** 2 - L2 ** 2) / (2 * L1 * L2)
    assert np.allclose(np.cos(res.q_pre[:inside.size, 1]), cos_pre, atol=1e-3)


def test_planar_arm_held_at_its_elbow_names_the_joint_limits(tmp_path):
    """With the elbow limited to |q2| <= 0.5 rad the arm reaches only r >= r_min =
    sqrt(l1^2 + l2^2 + 2 l1 l2 cos 0.5) = 0.7767 m: r = 0.5 is "joint limits" (the angle it needs,
    2.21 rad, is outside them), r = 0.79 reachable, r = 0.9 still "no IK solution"."""
    elbow = 'lower="-3.14159" upper="3.14159" effort="10" velocity="1"/>\n    <parent link="upper"/>'
    text = PLANAR.read_text().replace(elbow, elbow.replace("-3.14159", "-0.5").replace('"3.14159"', '"0.5"'))
    assert text != PLANAR.read_text()
    urdf = tmp_path / "held.urdf"
    urdf.write_text(text)
    r_min = np.sqrt(L1 ** 2 + L2 ** 2 + 2 * L1 * L2 * np.cos(0.5))
    assert 0.776 < r_min < 0.777
    res = check_reach(Arm.load(urdf), planar_targets([0.5, 0.79, 0.9], [0.3, -1.0, 2.0]),
                      options=PLANAR_OPTIONS.with_(pregrasp_distance=0.0))
    assert res.reachable.tolist() == [False, True, False]
    assert res.reason == ["joint limits", "", "no IK solution"]
    assert np.all(np.abs(res.q[1]) <= [np.pi, 0.5])


def kuka(base=(-0.6, 0.0, 0.0, 0.0)):
    return Arm.load("kuka_lbr4", base=base, mount=default_mount(Hand.load("barrett_bh8")))


def test_the_default_mount_puts_the_barrett_palm_on_the_flange():
    """The BH8's palm box spans z in [-0.06, 0] of the hand frame: its back rests on the flange,
    the palm face 0.06 m out along the flange's z."""
    hand = Hand.load("barrett_bh8")
    assert palm_depth(hand) == pytest.approx(0.06)
    assert np.allclose(default_mount(hand), [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0.06], [0, 0, 0, 1]])


def test_kuka_solutions_drive_the_urdf_chain_to_the_palm_pose():
    """Palm poses made from random joint vectors (so they are reachable) at a yawed base; every
    solution, put through the URDF's chain by yourdfpy (plus base and mount), lands on its palm
    pose within 1 mm and 0.5 degrees, within the joint limits; the pre-grasp 0.1 m back along the
    approach likewise."""
    arm = kuka(base=(0.2, -0.4, 0.05, 0.8))
    rng = np.random.default_rng(11)
    q_true = rng.uniform(0.7 * arm.lower, 0.7 * arm.upper, (24, arm.dof))
    P = arm.palm_poses(q_true)
    res = check_reach(arm, P, options=ReachOptions(table=False))
    assert res.reachable.mean() >= 0.9, res.reason
    flange = arm.flange
    for i in np.flatnonzero(res.reachable):
        pre = P[i].copy()
        pre[:3, 3] -= 0.1 * P[i][:3, 2]                 # 0.1 m back along the approach (palm z)
        for q, target in ((res.q[i], P[i]), (res.q_pre[i], pre)):
            assert np.all((q >= arm.lower - 1e-12) & (q <= arm.upper + 1e-12))
            T = arm.base @ urdf_fk(arm.urdf, dict(zip(res.joint_names, q)))[flange] @ arm.mount
            assert np.linalg.norm(T[:3, 3] - target[:3, 3]) <= 1e-3
            angle = np.linalg.norm(Rotation.from_matrix(T[:3, :3] @ target[:3, :3].T).as_rotvec())
            assert np.degrees(angle) <= 0.5
    assert np.all(res.position_error[res.reachable] <= 1e-3)


def test_our_kinematics_match_pinocchio():
    """The batched forward kinematics against pinocchio's own on the same model."""
    import pinocchio as pin

    arm = kuka(base=(0.1, 0.2, 0.3, 0.7))
    q = np.random.default_rng(2).uniform(arm.lower, arm.upper, (5, arm.dof))
    F = arm.flange_poses(q)
    data = arm.model.createData()
    fid = arm.model.getFrameId(arm.flange)
    for i in range(5):
        pin.framesForwardKinematics(arm.model, data, arm.pin_q(q[i]))
        assert np.allclose(arm.base @ data.oMf[fid].homogeneous, F[i], atol=1e-12)


def test_the_nearest_start_of_a_library_pose_is_its_own_joint_vector():
    """A palm pose made from library entry j is at distance 0 from it: it comes first; the others
    follow nearest first (distance 0 is the minimum), and the library is the seed's."""
    from bayesgrasp.arm.starts import nearest_starts, start_library

    arm = kuka()
    q, R, p = start_library(arm, seed=3)
    j = [5, 100, 700]
    S = nearest_starts(arm, arm.palm_poses(q[j]), k=4, seed=3)
    assert S.shape == (3, 4, arm.dof) and np.allclose(S[:, 0], q[j])
    assert np.array_equal(start_library(arm, seed=3)[0], q) and not np.array_equal(start_library(arm, seed=4)[0], q)


def test_the_palm_jacobian_is_the_derivative_of_the_palm_pose():
    """Central differences of the palm's position and orientation (rotation vector of R(q+h) R(q-h)^T
    over 2h) against the Jacobian's columns, at random joint vectors."""
    arm = kuka(base=(0.1, 0.2, 0.3, 0.7))
    q = np.random.default_rng(8).uniform(arm.lower, arm.upper, (4, arm.dof))
    _, _, J = arm.palm_jacobian(q)
    h = 1e-6
    for k in range(arm.dof):
        dq = np.zeros(arm.dof)
        dq[k] = h
        Pp, Pm = arm.palm_poses(q + dq), arm.palm_poses(q - dq)
        v = (Pp[:, :3, 3] - Pm[:, :3, 3]) / (2 * h)
        w = Rotation.from_matrix(Pp[:, :3, :3] @ Pm[:, :3, :3].transpose(0, 2, 1)).as_rotvec() / (2 * h)
        assert np.allclose(J[:, :3, k], v, atol=1e-6) and np.allclose(J[:, 3:, k], w, atol=1e-6)


def test_rotation_log_matches_scipy_near_zero_and_near_half_a_turn():
    v = np.array([[1e-7, 0, 0], [0.3, -0.2, 0.1], [0, 0, np.pi - 1e-5], [0.0, np.pi - 0.5, 0.0]])
    assert np.allclose(rotation_log(Rotation.from_rotvec(v).as_matrix()), v, atol=1e-9)


def wall():
    """A wall 5 cm thick across the table at x in [-0.35, -0.30], 2 m wide and 1.6 m tall: higher
    and wider than the arm (1.24 m from base to palm) can reach over or around from x = -0.6."""
    w = trimesh.creation.box((0.05, 2.0, 1.6))
    w.apply_translation((-0.325, 0.0, 0.8))
    return w


def test_a_grasp_behind_a_wall_is_refused_with_its_reason():
    grasp = top_grasp(0.0, 0.0, 0.12)
    arm = kuka()
    free = check_reach(arm, grasp)
    assert free.reachable.tolist() == [True]        # the control: the same grasp with no wall
    res = check_reach(arm, grasp, object_mesh=wall())
    assert res.reachable.tolist() == [False]
    assert res.reason == ["arm hits object"]
    assert np.all(np.isnan(res.q)) and np.all(np.isnan(res.q_pre))


def test_a_grasp_under_the_table_is_refused_with_its_reason():
    """The palm 0.1 m under the table top, 0.6 m in front of the arm, approaching sideways (along
    +x): the arm standing on the table must put its wrist through the top."""
    grasp = np.eye(4)
    grasp[:3, :3] = [[0, 0, 1], [0, 1, 0], [-1, 0, 0]]   # palm z = +x
    grasp[:3, 3] = [0.0, 0.0, -0.1]
    arm = kuka()
    assert check_reach(arm, grasp, options=ReachOptions(table=False)).reachable.tolist() == [True]
    res = check_reach(arm, grasp)
    assert res.reachable.tolist() == [False]
    assert res.reason == ["arm hits table"]


def test_a_batch_keeps_each_grasps_own_answer():
    """One call on a mixed batch gives each grasp the answer it gets alone."""
    arm = kuka()
    P = np.stack([top_grasp(0.0, 0.0, 0.12), top_grasp(2.0, 0.0, 0.12), top_grasp(0.1, 0.2, 0.15, 1.0)])
    batch = check_reach(arm, P, object_mesh=wall())
    alone = [check_reach(arm, P[i], object_mesh=wall()) for i in range(3)]
    assert batch.reason == [a.reason[0] for a in alone]
    assert batch.reason[1] == "no IK solution"
    d = batch.to_dict()
    assert d["joint_names"] == arm.joint_names and len(d["q"]) == 3


def test_the_same_seed_gives_the_same_answer():
    arm = kuka()
    P = np.stack([top_grasp(x, y, 0.1, a) for x, y, a in [(0, 0, 0), (0.2, -0.1, 1.0), (-0.1, 0.3, 2.0)]])
    a, b = check_reach(arm, P), check_reach(arm, P)
    assert a.reason == b.reason and np.array_equal(a.q, b.q, equal_nan=True)


@pytest.mark.parametrize("call, match", [
    (lambda arm: check_reach(arm, np.eye(3)), "palm_poses"),
    (lambda arm: check_reach(arm, np.full((2, 4, 4), np.nan)), "palm_poses"),
    (lambda arm: check_reach(arm, np.diag([2.0, 1.0, 1.0, 1.0])), r"palm_poses\[0\]"),
    (lambda arm: check_reach(arm, np.eye(4), object_mesh=(np.zeros((3, 2)), [[0, 1, 2]])), "object_mesh"),
    (lambda arm: check_reach(arm, np.eye(4), object_mesh=(np.eye(3), [[0, 1, 5]])), "object_mesh"),
    (lambda arm: check_reach(arm, np.eye(4), options={"seeds": 3}), "options"),
    (lambda arm: arm.palm_poses(np.zeros((2, 3))), "q"),
    (lambda arm: arm.set_base((0.0, 0.0, 0.0)), "base"),
    (lambda arm: arm.set_mount(np.eye(3)), "mount"),
    (lambda arm: Arm.load("kuka_lbr4", flange="no_such_link"), "flange: the URDF has no link 'no_such_link'"),
    (lambda arm: Arm.load("no_such_arm"), "urdf"),
])
def test_bad_input_raises_an_error_naming_the_argument(call, match):
    with pytest.raises(ValueError, match=match):
        call(kuka())


@pytest.mark.parametrize("field, value", [("seeds", 0), ("iterations", -1), ("damping", 0.0), ("tol_position", np.nan),
                                          ("pregrasp_distance", -0.1), ("clearance", np.inf), ("approach_steps", 1.5),
                                          ("seed", -1)])
def test_bad_options_raise_naming_the_field(field, value):
    with pytest.raises(ValueError, match=field):
        ReachOptions(**{field: value})


# ---- the planners weigh only reachable actions (Eq. 3.1 over what the arm reaches) -------------------
@pytest.fixture(scope="module")
def tiny():
    """Two stability planners on the same tiny cube models, the same seed."""
    from testkit import tiny_planner

    return tiny_planner, tiny_planner()


def test_the_stability_search_never_chooses_an_unreachable_action_while_it_met_a_reachable_one(tiny):
    make, free = tiny
    a0 = free.plan().action
    p = make()
    seen = []

    def reach(models, X, pose):   # the arm reaches only actions 5 mm or more on the -x side of the free choice
        ok = X[:, 0] <= a0[0] - 0.005
        seen.append((X.copy(), ok))
        return ok

    p.reach = reach
    plan = p.plan()
    X = np.concatenate([x for x, _ in seen])
    ok = np.concatenate([k for _, k in seen])
    assert ok.any() and (~ok).any()                       # the search met both kinds
    assert plan.action[0] <= a0[0] - 0.005                # the chosen one is reachable
    b = p.belief
    es = p.tables["top"].expected_stability(X[ok], b.particles, b.weights, 1)
    assert plan.predicted_stability == pytest.approx(p.expected_stability(plan.action))
    assert plan.predicted_stability >= es.max() - 1e-9    # and the best reachable one the search met
    assert 0.0 <= plan.predicted_stability <= 1.0


def test_with_nothing_reachable_the_search_returns_what_it_would_without_an_arm(tiny):
    make, _ = tiny
    a, b = make(), make()
    b.reach = lambda models, X, pose: np.zeros(len(X), dtype=bool)
    pa, pb = a.plan(), b.plan()
    assert np.allclose(pa.action, pb.action) and pa.predicted_stability == pytest.approx(pb.predicted_stability)


def test_action_reach_puts_the_familys_grasp_on_the_arm(tiny):
    """The cube's top grasps at its pose: the palm comes down (palm z = -z) above the table; the
    KUKA beside the table reaches them, the same arm 5 m away reaches none."""
    from bayesgrasp.planners.reach import ActionReach

    _, p = tiny
    models = p.family_models["top"]
    pose = np.array([0.02, -0.01, 0.3])
    actions = np.array([[0.02, -0.01, 0.3], [0.03, -0.01, 1.0], [0.02, 0.0, -0.5]])
    near = ActionReach(kuka(), "cube", hand="barrett_bh8")
    P = near.palm_poses(models, actions, pose)
    assert np.allclose(P[:, :3, 2], [0.0, 0.0, -1.0], atol=1e-9) and np.all(P[:, 2, 3] > 0)
    assert near(models, actions, pose).tolist() == [True, True, True]
    far = ActionReach(kuka(base=(5.0, 0.0, 0.0, 0.0)), "cube", hand="barrett_bh8")
    assert far(models, actions, pose).tolist() == [False, False, False]


# ---- the command line: grasp --robot -------------------------------------------------------------------
def test_grasp_with_the_robot_gives_the_grasp_in_the_arms_terms(capsys):
    """A top grasp on the cube at the origin with the KUKA 0.6 m behind the table's origin: the grasp
    record's ``arm`` (schema-valid) holds the URDF's joints; their forward kinematics (yourdfpy)
    put the palm where the hand closed. The same arm 3 m away cannot reach it."""
    from bayesgrasp.io.grasp_schema import validate
    from testkit import cli_json

    d = cli_json(capsys, "grasp", "--object", "cube", "--top", "0,0,0", "--no-lift", "--robot", "kuka_lbr4", "--json")
    validate(d["grasp"])
    arm = d["grasp"]["arm"]
    assert arm["reachable"] is True and arm["reason"] == "" and arm["flange_link"] == "lbr4_link7"
    assert np.allclose(arm["mount"], default_mount(Hand.load("barrett_bh8")))
    T = np.asarray(arm["base"]) @ urdf_fk(arm["urdf"], dict(zip(arm["joint_names"], arm["joint_positions"])))[
        arm["flange_link"]] @ np.asarray(arm["mount"])
    assert np.linalg.norm(T[:3, 3] - np.asarray(d["hand_pose"])[:3, 3]) <= 1e-3
    far = cli_json(capsys, "grasp", "--object", "cube", "--top", "0,0,0", "--no-lift", "--robot", "kuka_lbr4",
                   "--robot-base", "3,0,0,0", "--json")["grasp"]
    validate(far)
    assert far["arm"]["reachable"] is False and far["arm"]["reason"] == "no IK solution"
    assert "joint_positions" not in far["arm"]


@pytest.mark.parametrize("extra, needle", [
    (["--robot", "kuka_lbr4", "--flange", "nope"], "--flange: the URDF has no link 'nope'"),
    (["--robot", "no_such_arm.urdf"], "--robot: no such file"),
    (["--robot", "kuka_lbr4", "--robot-base", "1,2"], "--robot-base: expected 4"),
    (["--robot", "kuka_lbr4", "--mount", "0,0,0.1"], "--mount: expected 6"),
    (["--flange", "lbr4_link7"], "--flange: only with --robot"),
])
def test_grasp_robot_options_name_themselves_in_errors(extra, needle, capsys):
    from bayesgrasp.cli import main

    code = main(["grasp", "--object", "cube", "--top", "0,0,0", "--no-lift", *extra])
    assert code != 0 and needle in capsys.readouterr().err


def test_plan_with_the_robot_plans_reachable_grasps_and_reports_them(capsys):
    """plan --robot: the stability planner searches the grasps the KUKA reaches; the executed grasp
    comes back with the arm's joints (schema-valid), reachable."""
    from bayesgrasp.io.grasp_schema import validate
    from testkit import cli_json

    d = cli_json(capsys, "plan", "--object", "mug", "--true-pose", "0.01,0,0.3", "--attempts", "1", "--method",
                 "stability", "--robot", "kuka_lbr4", "--json")
    g = d["attempts"][0]["grasp"]
    validate(g)
    assert g["arm"]["reachable"] is True and len(g["arm"]["joint_positions"]) == 7


def test_the_exploration_search_never_chooses_an_unreachable_action_while_it_met_a_reachable_one():
    """Eq. 3.2 (always exploring: threshold 1): reachable only on the -x side of the free choice."""
    from bayesgrasp.models import build_models
    from bayesgrasp.planners import PlannerSettings, make_planner
    from testkit import TINY

    models = build_models("cube", settings=TINY, cache_dir=None)
    settings = PlannerSettings(explore_threshold=1.0, entropy_samples=10, explore_pso_iter=4)

    def planner():
        return make_planner("explore", models, estimate=(0.0, 0.0, 0.0), settings=settings)

    free = planner().plan()
    assert free.kind == "explore"
    p, seen = planner(), []

    def reach(models, X, pose):
        ok = X[:, 0] <= free.action[0] - 0.005
        seen.append(ok)
        return ok

    p.reach = reach
    plan = p.plan()
    ok = np.concatenate(seen)
    assert plan.kind == "explore" and ok.any() and (~ok).any()
    assert plan.action[0] <= free.action[0] - 0.005


def test_grasp_with_the_robot_in_ros_terms_gives_the_arms_trajectory(capsys):
    """--format ros: beside the moveit_msgs/Grasp, a JointTrajectory of the arm's joints from the
    pre-grasp (0 s) to the grasp (1 s), the same values as the JSON's arm record."""
    from testkit import cli_json

    args = ["grasp", "--object", "cube", "--top", "0,0,0", "--no-lift", "--robot", "kuka_lbr4"]
    arm = cli_json(capsys, *args, "--json")["grasp"]["arm"]
    ros = cli_json(capsys, *args, "--format", "ros")
    t = ros["arm_trajectory"]
    assert t["joint_names"] == arm["joint_names"]
    assert [p["positions"] for p in t["points"]] == [arm["pregrasp_joint_positions"], arm["joint_positions"]]
    assert [p["time_from_start"]["sec"] for p in t["points"]] == [0, 1]


# ---- Eq. 4.1 takes reachability as a constraint --------------------------------------------------
@pytest.mark.parametrize("method", ["laplace", "regularised"])
def test_the_category_plan_is_a_grasp_the_arm_reaches(method):
    """One model, one task grasp: without an arm the plan is the mapped grasp itself (test_category);
    an arm that reaches only grasps 1 cm or more on the -x side of it moves the plan there, and an
    arm that reaches nothing leaves no grasp to send, with the reason."""
    from bayesgrasp.planners.category import CategoryPlanner, CategorySettings
    from bayesgrasp.vision import RegistrationResult
    from testkit import HAND, TOP, grasp, rz

    T = rz(0.4, (0.1, -0.05, 0.0))
    G = T @ TOP

    def planner():
        return CategoryPlanner(HAND, [grasp("a", TOP)], [RegistrationResult.known("a", T, phi=0.7)],
                               settings=CategorySettings(method=method), seed=1)

    free = planner().plan()
    np.testing.assert_allclose(free.pose, G, atol=1e-9)
    p, asked = planner(), []

    def reach(P):
        ok = P[:, 0, 3] <= G[0, 3] - 0.01
        asked.append(ok)
        return ok

    p.reach = reach
    plan = p.plan()
    ok = np.concatenate(asked)
    assert plan.ok and ok.any() and (~ok).any()
    assert plan.pose[0, 3] <= G[0, 3] - 0.01 and plan.mixture > 0
    nowhere = planner()
    nowhere.reach = lambda P: np.zeros(len(P), dtype=bool)
    none = nowhere.plan()
    assert not none.ok and "out of the arm's reach" in none.reason


def test_category_with_the_robot_sends_a_grasp_the_arm_reaches(capsys, cat_options):
    """category --robot (small models, two training mugs: the fixture cat_options): Eq. 4.1 planned
    over the grasps the KUKA reaches (table only: the new object's mesh is unknown while planning);
    the grasp sent comes back with the arm's joints, checked against the stand-in's mesh too."""
    from bayesgrasp.io.grasp_schema import validate
    from testkit import cli_json, without_set

    d = cli_json(capsys, "category", "--category", "mug", "--task", "top", "--scene-object", "mug/3",
                 "--object-pose", "0.01,0.02,0.7", *without_set(cat_options), "--robot", "kuka_lbr4", "--json")
    validate(d["grasp"])
    assert d["grasp"]["arm"]["reachable"] is True and len(d["grasp"]["arm"]["joint_positions"]) == 7


def test_the_fusion_plan_is_a_grasp_the_arm_reaches():
    """Eq. 4.6, one model at (0.02, 0.01, 0.3) with its task grasp at its origin: without an arm the
    plan is that grasp (test_fusion); an arm reaching only x <= 0.01 moves it there."""
    from bayesgrasp.planners.fusion import FusionPlanner, FusionSettings, ModelMixtureBelief
    from testkit import analytic

    def planner():
        belief = ModelMixtureBelief(["a"], [analytic(True)], [1.0], [[0.02, 0.01, 0.3]], FusionSettings(), seed=2)
        return FusionPlanner(belief, [np.array([[0.0, 0.0, 0.0]])], seed=3)

    free = planner().plan()
    np.testing.assert_allclose(free.action, [0.02, 0.01, 0.3], atol=2e-3)
    p, asked = planner(), []

    def reach(X):
        ok = X[:, 0] <= 0.01
        asked.append(ok)
        return ok

    p.reach = reach
    plan = p.plan()
    ok = np.concatenate(asked)
    assert ok.any() and (~ok).any()
    assert plan.action[0] <= 0.01 and plan.objective > 0


def test_fuse_with_the_robot_reports_every_round_in_the_arms_terms(capsys, cat_options):
    """fuse --robot (small models, two training mugs): Eq. 4.6 planned over the top grasps the KUKA
    reaches; every round's executed grasp carries the arm's verdict, schema-valid."""
    from bayesgrasp.io.grasp_schema import validate
    from testkit import cli_json

    d = cli_json(capsys, "fuse", "--category", "mug", "--task", "top", "--scene-object", "mug/3", "--object-pose",
                 "0.01,0.02,0.7", "--rounds", 1, *cat_options, "--robot", "kuka_lbr4", "--json")
    assert d["rounds"]
    for r in d["rounds"]:
        validate(r["grasp"])
        assert set(r["grasp"]["arm"]) >= {"reachable", "reason", "joint_names"}
    assert d["rounds"][-1]["grasp"]["arm"]["reachable"] is True     # the planned round: reachable
