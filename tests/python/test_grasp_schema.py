"""The one grasp schema (bayesgrasp/data/schema/grasp.schema.json) and its ROS shape."""
import json

import jsonschema
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from bayesgrasp.cli import main
from bayesgrasp.hand import Hand
from bayesgrasp.io.grasp_schema import grasp_record, hand_grasp_record, schema, validate


def cli_json(capsys, *argv):
    assert main(list(argv)) == 0
    return json.loads(capsys.readouterr().out)


def test_record_fields_agree_with_the_pose():
    T = Hand.approach_pose((1.0, 0.0, -1.0), 0.3, (0.05, 0.0, 0.1))
    hand = Hand.load("barrett_bh8")
    q = hand.coupled_joints(0.2, 0.5)
    rec = hand_grasp_record(hand, T, q, 0.2)
    validate(rec)
    np.testing.assert_allclose(rec["position"], T[:3, 3])
    np.testing.assert_allclose(Rotation.from_quat(rec["quaternion_xyzw"]).as_matrix(), T[:3, :3], atol=1e-12)
    assert rec["quaternion_xyzw"][3] >= 0
    np.testing.assert_allclose(rec["approach"], np.array([1.0, 0.0, -1.0]) / np.sqrt(2), atol=1e-12)
    P = np.array(rec["pregrasp"]["pose"])
    np.testing.assert_allclose(P[:3, 3], T[:3, 3] - 0.1 * np.array(rec["approach"]), atol=1e-12)
    np.testing.assert_allclose(rec["pregrasp"]["joint_positions"], hand.open_joints(0.2))
    assert rec["joint_names"] == hand.joint_names and rec["hand"] == hand.name


@pytest.mark.parametrize("drop", ["pose", "quaternion_xyzw", "approach", "pregrasp", "joint_names", "frame"])
def test_schema_rejects_a_record_without_a_field(drop):
    rec = grasp_record(np.eye(4), "h", ["a"], [0.1], 0.0)
    del rec[drop]
    with pytest.raises(jsonschema.ValidationError):
        validate(rec)


def test_schema_rejects_a_wrong_frame_and_a_3x4_pose():
    rec = grasp_record(np.eye(4), "h", ["a"], [0.1], 0.0)
    with pytest.raises(jsonschema.ValidationError):
        validate({**rec, "frame": "camera"})
    with pytest.raises(jsonschema.ValidationError):
        validate({**rec, "pose": rec["pose"][:3]})
    jsonschema.Draft202012Validator.check_schema(schema())


@pytest.mark.parametrize("bad, match", [(np.zeros((3, 4)), "4x4"), (np.diag([1.0, 1.0, -1.0, 1.0]), "rigid"),
                                        (np.full((4, 4), np.nan), "finite")])
def test_record_refuses_a_pose_that_is_not_rigid(bad, match):
    with pytest.raises(ValueError, match=match):
        grasp_record(bad, "h", ["a"], [0.1], 0.0)


def test_record_refuses_joint_count_mismatch():
    with pytest.raises(ValueError, match="joint_positions"):
        grasp_record(np.eye(4), "h", ["a", "b"], [0.1], 0.0)


def test_grasp_json_holds_a_valid_grasp_beside_its_outcome(capsys):
    d = cli_json(capsys, "grasp", "--object", "cylinder", "--top", "0,0,0.3", "--json")
    validate(d["grasp"])
    assert d["grasp"]["frame"] == "world"
    np.testing.assert_allclose(d["grasp"]["pose"], d["hand_pose"])
    np.testing.assert_allclose(d["grasp"]["joint_positions"], d["joint_angles"])
    assert d["grasp"]["approach"] == pytest.approx([0, 0, -1], abs=1e-12)   # a top grasp comes down
    assert "lifted" not in d["grasp"] and "epsilon" not in d["grasp"]     # outcomes sit beside it
    assert isinstance(d["lifted"], bool)


def test_grasp_format_ros_has_the_moveit_grasp_fields(capsys):
    d = cli_json(capsys, "grasp", "--object", "cylinder", "--top", "0,0,0.3", "--json")
    r = cli_json(capsys, "grasp", "--object", "cylinder", "--top", "0,0,0.3", "--format", "ros")
    for key in ("id", "pre_grasp_posture", "grasp_posture", "grasp_pose", "grasp_quality", "pre_grasp_approach",
                "post_grasp_retreat", "post_place_retreat", "max_contact_force", "allowed_touch_objects", "joint_state"):
        assert key in r
    g = d["grasp"]
    assert r["grasp_pose"]["header"]["frame_id"] == "world"
    p, o = r["grasp_pose"]["pose"]["position"], r["grasp_pose"]["pose"]["orientation"]
    assert [p["x"], p["y"], p["z"]] == g["position"]
    assert [o["x"], o["y"], o["z"], o["w"]] == g["quaternion_xyzw"]
    assert r["grasp_posture"]["joint_names"] == g["joint_names"] == r["joint_state"]["name"]
    assert r["grasp_posture"]["points"][0]["positions"] == g["joint_positions"] == r["joint_state"]["position"]
    assert r["pre_grasp_posture"]["points"][0]["positions"] == g["pregrasp"]["joint_positions"]
    assert r["pre_grasp_approach"]["desired_distance"] == g["pregrasp"]["distance"]
    assert r["post_grasp_retreat"]["direction"]["vector"] == {"x": 0.0, "y": 0.0, "z": 1.0}   # the lift
    assert r["grasp_quality"] == d["epsilon"]


def test_json_and_format_ros_together_is_an_error(capsys):
    assert main(["grasp", "--object", "cylinder", "--top", "0,0,0", "--json", "--format", "ros"]) == 2
    assert "--json: not with --format ros" in capsys.readouterr().err


SMALL = ["--set", "models.n_samples=300", "--set", "models.n_inducing=50", "--set", "models.max_iter=30",
         "--set", "models.n_lift_samples=150", "--set", "models.n_calibration=100", "--set", "models.n_pilot=40",
         "--set", "models.n_pilot_lifts=10"]


@pytest.fixture(scope="module")
def plan_cache(tmp_path_factory):
    return str(tmp_path_factory.mktemp("cache"))


def test_plan_json_has_a_valid_grasp_per_attempt(capsys, plan_cache):
    argv = ["plan", "--object", "cylinder", "--true-pose", "0.01,-0.01,0.4", "--attempts", "2", "--cache", plan_cache,
            *SMALL]
    d = cli_json(capsys, *argv, "--json")
    for a in d["attempts"]:
        g = a["grasp"]
        validate(g)
        x, y, yaw = a["top_grasp"]
        T = np.array(g["pose"])
        np.testing.assert_allclose(T[:2, 3], [x, y], atol=1e-9)   # the executed top grasp: down at (x, y)
        assert g["approach"] == pytest.approx([0, 0, -1], abs=1e-9) and T[2, 3] > 0
        assert len(g["joint_positions"]) == len(g["joint_names"])
    r = cli_json(capsys, *argv, "--format", "ros")
    assert len(r["attempts"]) == len(d["attempts"])
    for ros, a in zip(r["attempts"], d["attempts"]):
        p = ros["grasp_pose"]["pose"]["position"]
        assert [p["x"], p["y"], p["z"]] == a["grasp"]["position"]
        assert ros["grasp_posture"]["points"][0]["positions"] == a["grasp"]["joint_positions"]


def test_touch_format_ros_is_its_grasp(capsys):
    argv = ["touch", "--object", "cube", "--true-pose", "0.01,-0.01,0.3", "--estimate", "-0.01,0.005,0.45",
            "--budget", "50"]
    d = cli_json(capsys, *argv, "--json")
    r = cli_json(capsys, *argv, "--format", "ros")
    assert r["grasp_posture"]["points"][0]["positions"] == d["grasp"]["joint_positions"]
    o = r["grasp_pose"]["pose"]["orientation"]
    assert [o["x"], o["y"], o["z"], o["w"]] == d["grasp"]["quaternion_xyzw"]
