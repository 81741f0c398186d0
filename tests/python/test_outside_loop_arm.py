"""`episode new --robot`: the episode plans over the grasps the arm reaches, each printed grasp
carries the arm's joints (their forward kinematics put the palm on the grasp), and the arm stored at
`new` is the one every later call re-opens."""
import json
import shutil

import numpy as np
import pytest

from bayesgrasp.arm import REASONS, ROBOTS_DIR, Arm, base_pose
from bayesgrasp.cli import main
from bayesgrasp.io.grasp_schema import validate
from bayesgrasp.loop.outside_loop_category import open_episode
from testkit import cli_json

SET = {"n_samples": 300, "n_inducing": 50, "max_iter": 30, "n_lift_samples": 150, "n_calibration": 100, "n_pilot": 40,
       "n_pilot_lifts": 10}
SMALL = [a for k, v in SET.items() for a in ("--set", f"models.{k}={v}")]
OBJ, EST = "cylinder", "0.02,-0.01,0.3"


@pytest.fixture(scope="module")
def cache(tmp_path_factory):
    return str(tmp_path_factory.mktemp("cache"))


def new(capsys, d, cache, *extra):
    return cli_json(capsys, "episode", "new", "--object", OBJ, "--estimate", EST, "--method", "stability",
                    "--attempts", "3", "--seed", "2", "--dir", d, "--cache", cache, *SMALL, *extra, "--json")


def fk_palm(arm_rec) -> np.ndarray:
    """The palm pose (4x4, table frame) the record's joint positions give through the arm's own
    forward kinematics, with the record's base, flange and mount."""
    arm = Arm.load(arm_rec["urdf"], flange=arm_rec["flange_link"], mount=np.asarray(arm_rec["mount"]),
                   base=np.asarray(arm_rec["base"]))
    return arm.palm_poses(np.asarray(arm_rec["joint_positions"]))[0]


def assert_reaches(grasp):
    validate(grasp)
    rec = grasp["arm"]
    assert rec["reachable"] is True and rec["reason"] == "" and len(rec["joint_positions"]) == 7
    T, G = fk_palm(rec), np.asarray(grasp["pose"])
    assert np.linalg.norm(T[:3, 3] - G[:3, 3]) <= 1e-3                    # within 1 mm
    angle = np.arccos(np.clip((np.trace(T[:3, :3].T @ G[:3, :3]) - 1) / 2, -1, 1))
    assert angle <= np.radians(0.5)


def test_the_next_grasp_carries_the_arm_s_joints_that_reach_it(capsys, tmp_path, cache):
    d = new(capsys, tmp_path / "ep", cache, "--robot", "kuka_lbr4")
    grasp = d["next"]["grasp"]
    assert_reaches(grasp)
    assert np.allclose(grasp["arm"]["base"], base_pose([-0.6, 0, 0, 0]))      # --robot-base's default
    state = json.loads((tmp_path / "ep" / "episode.json").read_text())["state"]
    assert state["arm"]["urdf"] == "kuka_lbr4" and state["arm"]["flange"] == "lbr4_link7"
    # the same episode without --robot stores no arm and prints no arm record
    free = new(capsys, tmp_path / "free", cache)
    assert "arm" not in free["next"]["grasp"]
    assert "arm" not in json.loads((tmp_path / "free" / "episode.json").read_text())["state"]


def test_with_nothing_reachable_the_planner_falls_back_and_the_grasp_says_why(capsys, tmp_path, cache):
    """An arm 5 m away reaches nothing: as the planner documents, it returns the grasp it would
    without an arm (the same top grasp, bit for bit), and the record says the arm cannot reach it."""
    far = new(capsys, tmp_path / "far", cache, "--robot", "kuka_lbr4", "--robot-base", "5,0,0,0")
    free = new(capsys, tmp_path / "free", cache)
    assert far["next"]["top_grasp"] == free["next"]["top_grasp"]
    rec = far["next"]["grasp"]["arm"]
    validate(far["next"]["grasp"])
    assert rec["reachable"] is False and rec["reason"] in REASONS and "joint_positions" not in rec
    main(["episode", "observe", str(tmp_path / "far"), "--joints", "0,1,1,1,1,1,1", "--lifted", "no"])
    assert f"arm: cannot reach this grasp ({rec['reason']})" in capsys.readouterr().out


def test_the_arm_survives_a_reopen_and_a_changed_urdf_is_refused(capsys, tmp_path, cache):
    """The arm from a URDF file at a base of its own: observe re-opens the episode (its replay plans
    with the same arm, or it would refuse) and the next grasp is reached from that base; once the
    URDF file changes, the episode refuses to open and is left as it was."""
    urdf = tmp_path / "my_arm.urdf"
    shutil.copy(ROBOTS_DIR / "kuka_lbr4.urdf", urdf)
    base = [-0.55, 0.1, 0.0, 0.2]
    d = tmp_path / "ep"
    first = new(capsys, d, cache, "--robot", str(urdf), "--robot-base", ",".join(map(str, base)))
    assert_reaches(first["next"]["grasp"])
    nxt = cli_json(capsys, "episode", "observe", d, "--joints", "0,1,1,1,1,1,1", "--lifted", "no", "--json")["next"]
    assert nxt["attempt"] == 2
    assert_reaches(nxt["grasp"])
    assert np.allclose(nxt["grasp"]["arm"]["base"], base_pose(base)) and nxt["grasp"]["arm"]["urdf"] == str(urdf)
    ep = open_episode(d, cache_dir=cache)
    assert np.allclose(ep.arm.base, base_pose(base)) and ep.planner.reach is not None
    before = (d / "episode.json").read_bytes()
    urdf.write_text(urdf.read_text().replace("<robot", "<!-- edited -->\n<robot", 1))
    code = main(["episode", "observe", str(d), "--joints", "0,1,1,1,1,1,1", "--lifted", "no"])
    err = capsys.readouterr().err
    assert code == 2 and "changed since the episode was started" in err and "Traceback" not in err
    assert (d / "episode.json").read_bytes() == before


@pytest.mark.parametrize("extra, needle", [
    (["--robot", "no_such_arm.urdf"], "--robot: no such file"),
    (["--robot", "kuka_lbr4", "--robot-base", "1,2"], "--robot-base: expected 4"),
    (["--flange", "lbr4_link7"], "--flange: only with --robot"),
])
def test_bad_robot_options_are_named_and_write_nothing(capsys, tmp_path, cache, extra, needle):
    code = main(["episode", "new", "--object", OBJ, "--estimate", EST, "--dir", str(tmp_path / "ep"), "--cache", cache,
                 *SMALL, *extra])
    assert code == 2 and needle in capsys.readouterr().err
    assert not (tmp_path / "ep" / "episode.json").exists()


# ---- the category kinds: Eq. 4.1 and Eq. 4.6 over what the arm reaches ----------------------------
CAT_SET = {"n_samples": 400, "n_inducing": 60, "max_iter": 40, "n_lift_samples": 200, "n_calibration": 150,
           "n_pilot": 60, "n_pilot_lifts": 15}
SCENE, SCENE_POSE = "mug/3", "0.01,0.02,0.7"


@pytest.fixture(scope="module")
def cat_options(tmp_path_factory):
    from testkit import task_grasp_options

    return task_grasp_options(tmp_path_factory.mktemp("cat"), ("mug/1", "mug/2"), 3, CAT_SET)


def test_a_category_task_episode_on_an_arm_plans_as_category_does(capsys, tmp_path, cat_options):
    """The task grasp is `category --robot`'s (the same reach hook), printed with the arm's joints."""
    from testkit import without_set

    opts = [*without_set(cat_options), "--robot", "kuka_lbr4"]
    inproc = cli_json(capsys, "category", "--category", "mug", "--task", "top", "--scene-object", SCENE,
                      "--object-pose", SCENE_POSE, *opts, "--json")
    doc = cli_json(capsys, "episode", "new", "--category", "mug", "--task", "top", "--object", SCENE, "--object-pose",
                   SCENE_POSE, "--dir", tmp_path / "ep", *opts, "--json")
    assert doc["next"]["planned_pose"] == inproc["planned_pose"]
    assert_reaches(doc["next"]["grasp"])
    assert open_episode(tmp_path / "ep").arm is not None


def test_a_fusion_episode_on_an_arm_prints_reachable_grasps_and_reopens_with_its_arm(capsys, tmp_path, cat_options):
    d = tmp_path / "ep"
    doc = cli_json(capsys, "episode", "new", "--category", "mug", "--task", "top", "--method", "fusion", "--object",
                   SCENE, "--object-pose", SCENE_POSE, "--attempts", 3, "--dir", d, *cat_options,
                   "--robot", "kuka_lbr4", "--robot-base", "-0.6,0.1,0,0", "--json")
    assert_reaches(doc["next"]["grasp"])
    nxt = cli_json(capsys, "episode", "observe", d, "--joints", "0,1,1,1,1,1,1", "--lifted", "no", "--json")["next"]
    assert_reaches(nxt["grasp"])
    assert np.allclose(nxt["grasp"]["arm"]["base"], base_pose([-0.6, 0.1, 0, 0]))
