"""Vision then touch end to end (small models and grasps): a held-out mug, two training mugs."""
import json

import numpy as np
import pytest

from bayesgrasp.cli import main
from bayesgrasp.experiments.tactile_fusion import transitions
from bayesgrasp.loop.context import RunContext
from bayesgrasp.loop.fusion_trial import FusionTrial, planar_top_grasps
from bayesgrasp.models import ModelSettings
from bayesgrasp.models.task_grasps import TaskGraspSettings, generate_task_grasps, grasp_to_json
from bayesgrasp.models.tasks import task_rule
from bayesgrasp.io.grasp_schema import validate

SMALL = ModelSettings(n_samples=400, n_inducing=60, max_iter=40, n_lift_samples=200, n_calibration=150, n_pilot=60,
                      n_pilot_lifts=15)
KEEP = ("mug/1", "mug/2")
EXCLUDE = tuple(f"mug/{i}" for i in range(7) if f"mug/{i}" not in KEEP)


@pytest.fixture(scope="module")
def grasps():
    out = []
    for m in KEEP:
        out += generate_task_grasps(m, task_rule("mug", "top"),
                                    settings=TaskGraspSettings(candidates=150, spreads=(0.0, float(np.radians(60))),
                                                               lift_tests=6, keep=2))
    return out


@pytest.fixture(scope="module")
def cache(tmp_path_factory):
    return str(tmp_path_factory.mktemp("models"))


def test_planar_top_grasps_of_palm_down_poses():
    from bayesgrasp.hand import Hand
    from bayesgrasp.models.tasks import TaskGrasp

    g = TaskGrasp("m", "top", Hand.top_grasp_pose(0.01, -0.02, 0.7, 0.1), 0.0, 0.1, True)
    np.testing.assert_allclose(planar_top_grasps([g])[0], [0.01, -0.02, 0.7], atol=1e-12)


@pytest.mark.parametrize("mode", ["random", "vision"])
def test_a_trial_runs_rounds_until_a_lift_with_normalised_weights(grasps, cache, mode):
    ctx = RunContext(cache_dir=cache, model_settings=SMALL)
    trial = FusionTrial("mug/3", (0.01, 0.02, 0.7), ctx, exclude=EXCLUDE, seed=3, grasps=grasps)
    assert trial.names == list(KEEP)
    r = trial.run(mode)
    rounds = r.to_dict()["rounds"]
    assert r.success == rounds[-1]["lifted"]
    assert 2 <= len(rounds) <= 4                    # round 1 is always made (the thesis's accounting)
    for k, x in enumerate(rounds):
        assert x["round"] == k and sum(x["weights"]) == pytest.approx(1.0)
        assert isinstance(x["lifted"], bool) and np.isfinite(x["epsilon"])
    # rounds 2 and 3 only while nothing was lifted
    for k in range(2, len(rounds)):
        assert not any(x["lifted"] for x in rounds[:k])


def test_the_accounting_of_transitions_by_hand():
    def trial(lifted, eps):
        return (None, {"rounds": [{"lifted": l, "epsilon": e} for l, e in zip(lifted, eps)],
                       "vision_only": {"lifted": lifted[0]}})
    res = [trial([False, True], [0.0, 0.1]),            # unstable -> stable: better
           trial([True, False], [0.2, 0.0]),            # stable -> unstable: worse
           trial([False, False, False, True], [0.0, 0.0, 0.0, 0.1]),   # same, stable in round 3
           trial([False, False, True], [0.0, 0.0, 0.2])]               # same, stable in round 2
    t = transitions(res)
    assert (t.better, t.worse, t.same_both_unstable) == (1, 1, 2)
    assert (t.unstable_to_stable, t.stable_to_unstable) == (1, 1)
    assert t.still_unstable_after_round_1 == 2
    assert (t.became_stable_round_2, t.became_stable_round_3) == (1, 1)
    assert t.cumulative_success_by_round == [1, 2, 3, 4] and t.vision_only_success == 1


def small_models_and_grasps(grasps, tmp_path) -> list:
    """The CLI options for SMALL models and the given task grasps (written to a file)."""
    args = []
    for k, v in {"n_samples": 400, "n_inducing": 60, "max_iter": 40, "n_lift_samples": 200, "n_calibration": 150,
                 "n_pilot": 60, "n_pilot_lifts": 15}.items():
        args += ["--set", f"models.{k}={v}"]
    f = tmp_path / "g.json"
    f.write_text(json.dumps({"grasps": [grasp_to_json(g) for g in grasps]}))
    return args + ["--task-grasps", str(f)]


def test_fuse_cli(grasps, cache, tmp_path, capsys):
    png = tmp_path / "f.png"
    args = ["fuse", "--scene-object", "mug/3", "--object-pose", "0.01,0.02,0.7", "--exclude", *EXCLUDE, "mug/3",
            "--cache", cache, "--rounds", "2", "--json", "--png", str(png)]
    assert main(args + small_models_and_grasps(grasps, tmp_path)) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["rounds"] and set(doc["rounds"][0]) >= {"grasp", "top_grasp", "weights", "poses", "epsilon", "lifted"}
    for r in doc["rounds"]:
        validate(r["grasp"])                                    # the one grasp schema
        np.testing.assert_allclose(np.array(r["grasp"]["pose"])[:2, 3], r["top_grasp"][:2], atol=1e-9)
    # it grasps until a grasp is lifted, and its outcome is the last grasp's
    assert doc["success"] == doc["rounds"][-1]["lifted"] == any(r["lifted"] for r in doc["rounds"])
    assert not any(r["lifted"] for r in doc["rounds"][:-1])
    assert png.stat().st_size > 1000
    assert main(["fuse", "--scene-object", "mug/3", "--set", "models.n_samples=x"]) == 2
    assert "--set" in capsys.readouterr().err


def test_fuse_cli_sees_a_camera_cloud(grasps, cache, tmp_path, capsys):
    """The vision step from a scan file: the scan shows the mug 5 cm away from the stand-in, and
    the first round's model poses follow the scan, not the stand-in."""
    import subprocess
    import sys
    from pathlib import Path

    scan = tmp_path / "scan"
    root = Path(__file__).resolve().parents[2]
    subprocess.run([sys.executable, str(root / "examples" / "make_scan.py"), "--object", "mug/3", "--pose",
                    "0.05,-0.03,0.7", "--out", str(scan)], check=True, capture_output=True)
    args = ["fuse", "--scene-object", "mug/3", "--object-pose", "0.01,0.02,0.7", "--exclude", *EXCLUDE, "mug/3",
            "--cache", cache, "--rounds", "1", "--json", "--cloud", str(scan / "cloud.ply"),
            "--extrinsic", str(scan / "extrinsic.json")]
    assert main(args + small_models_and_grasps(grasps, tmp_path)) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["scene"] == str(scan / "cloud.ply")
    poses = np.array(list(doc["rounds"][0]["poses"].values()))
    assert np.all(np.hypot(poses[:, 0] - 0.05, poses[:, 1] + 0.03) < 0.02)


def test_fuse_format_ros_has_one_grasp_per_round(grasps, cache, tmp_path, capsys):
    args = ["fuse", "--scene-object", "mug/3", "--object-pose", "0.01,0.02,0.7", "--exclude", *EXCLUDE, "mug/3",
            "--cache", cache, "--rounds", "1"] + small_models_and_grasps(grasps, tmp_path)
    assert main(args + ["--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert main(args + ["--format", "ros"]) == 0
    ros = json.loads(capsys.readouterr().out)
    assert [r["grasp_posture"]["points"][0]["positions"] for r in ros["rounds"]] == \
        [r["grasp"]["joint_positions"] for r in doc["rounds"]]
    assert all(r["grasp_pose"]["header"]["frame_id"] == "world" for r in ros["rounds"])
