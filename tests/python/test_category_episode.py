"""The category pipeline end to end on a small set of demonstrated grasps: generated from the
rules with a small budget, stored and loaded as data, planned on a held-out mug's view, executed."""
import json

import numpy as np
import pytest

from bayesgrasp.cli import main
from bayesgrasp.hand import Hand
from bayesgrasp.loop.category import (observe, plan_and_execute, register_models, see,
                                      training_models)
from bayesgrasp.loop.context import RunContext
from bayesgrasp.models.task_grasps import (TaskGraspSettings, generate_task_grasps, grasp_to_json,
                                           load_task_grasp_file)
from bayesgrasp.models.tasks import task_rule
from bayesgrasp.world import World
from bayesgrasp.io.grasp_schema import validate

SMALL = TaskGraspSettings(candidates=150, spreads=(0.0, float(np.radians(60))), lift_tests=6, keep=2)


@pytest.fixture(scope="module")
def grasp_file(tmp_path_factory):
    rule = task_rule("mug", "top")
    grasps = []
    for m in ("mug/1", "mug/2"):
        grasps += generate_task_grasps(m, rule, settings=SMALL)
    f = tmp_path_factory.mktemp("tg") / "grasps.json"
    f.write_text(json.dumps({"grasps": [grasp_to_json(g) for g in grasps]}))
    return f, grasps


def test_generation_reports_each_batch_before_it_runs():
    lines = []
    tiny = TaskGraspSettings(candidates=20, spreads=(0.0, float(np.radians(60))), lift_tests=1, keep=1)
    generate_task_grasps("mug/1", task_rule("mug", "top"), settings=tiny, say=lines.append)
    assert [x.split(": ", 1)[1] for x in lines[:2]] == ["closing 20 approaches at spread 0 deg (1/2)",
                                                         "closing 20 approaches at spread 60 deg (2/2)"]
    assert "candidates obey the rule" in lines[2] and len(lines) == 3


def test_generation_reports_its_lift_tests_and_keeps_their_verdicts(monkeypatch):
    """The candidates' lift tests run in batches that report progress, across spreads (the 27.5 s
    silence from an empty cache was 34 tests over several spreads, each spread's few tests one
    batch); the grasps kept are those of unbatched tests."""
    from bayesgrasp.models import training

    s = TaskGraspSettings(candidates=120, spreads=(float(np.radians(45)), float(np.radians(60))), lift_tests=8,
                          keep=8)
    whole = generate_task_grasps("mug/1", task_rule("mug", "top"), settings=s)
    assert len({g.spread for g in whole}) == 2   # tests at both spreads
    lines = []
    monkeypatch.setattr(training, "PROGRESS_EVERY", 0.0)
    monkeypatch.setattr(training, "lift_chunk", lambda: 5)   # more than either spread's tests
    chunked = generate_task_grasps("mug/1", task_rule("mug", "top"), settings=s, say=lines.append)
    assert [np.asarray(g.pose).tolist() for g in chunked] == [np.asarray(g.pose).tolist() for g in whole]
    progress = [x for x in lines if "lift tests:" in x]
    assert progress and all(" done, " in x for x in progress) and any("5/8 done, about" in x for x in progress)


def test_generated_grasps_obey_their_rule_and_the_lift_test(grasp_file):
    _, grasps = grasp_file
    assert grasps, "a mug has stable top grasps"
    rule = task_rule("mug", "top")
    for g in grasps:
        assert g.lifted and g.epsilon > 0 and g.task == "top"
        assert rule.approach_ok(g.pose[:3, 2][None])[0]      # the hand's +z is the approach direction
        w = World.single(g.model)
        r = w.grasp_pose(g.pose, spread=g.spread, lift=True)  # re-executed from the data: the same verdict
        assert r.lifted and rule.contacts_ok([c.part for c in r.contacts if not c.on_table])
        assert r.epsilon == pytest.approx(g.epsilon, abs=1e-9)


def test_roll_of_inverts_the_approach_pose():
    rng = np.random.default_rng(0)
    for _ in range(5):
        d = rng.normal(size=3)
        roll = rng.uniform(-np.pi, np.pi)
        T = Hand.approach_pose(d, roll, rng.normal(size=3))
        assert np.isclose(np.cos(Hand.approach_roll(T) - roll), 1.0, atol=1e-9)


def test_leave_one_out_training_sets():
    assert "mug/3" not in training_models("mug", ["mug/3"]) and len(training_models("mug", ["mug/3"])) == 6
    assert training_models("knife") == [f"hammer/{i}" for i in range(4)]
    with pytest.raises(ValueError, match="category"):
        training_models("spoon")


def test_a_held_out_mug_is_registered_planned_and_executed(grasp_file):
    _, grasps = grasp_file
    ep = see("mug/3", (0.02, -0.01, 1.0), "mug", exclude=("mug/3",), seed=3)
    assert len(ep.registrations) == 6 and any(r.success for r in ep.registrations)
    ctx = RunContext()
    for method in ("laplace", "baseline"):
        out = plan_and_execute(ep, "mug", "top", method, ctx, seed=1, grasps=grasps).to_dict()
        assert out["plan_ok"] and out["executed"]
        assert out["dominant_model"] in ("mug/1", "mug/2")
        assert sum(out["weights"].values()) == pytest.approx(1.0)
        assert out["success"] == (out["lifted"] and out["task_ok"])
        assert (out["failure"] is None) == out["success"]
    # models without demonstrated grasps: an explicit no-grasp result, never a silent grasp
    none = plan_and_execute(ep, "mug", "top", "laplace", ctx, grasps=[g for g in grasps if g.model == "mug/9"]).to_dict()
    assert not none["executed"] and "no demonstrated grasps" in none["reason"]


def test_the_complete_model_mode_registers_the_whole_surface():
    o = observe("mug/3", (0.0, 0.0, 0.5), complete=True)
    assert o.complete and len(o.cloud) == 3000
    regs = register_models(o, ["mug/1"])
    assert regs[0].success


def test_category_cli_json_and_png(grasp_file, tmp_path, capsys):
    f, _ = grasp_file
    png = tmp_path / "c.png"
    assert main(["category", "--category", "mug", "--task", "top", "--scene-object", "mug/3", "--object-pose", "-0.01,0.02,0.4",
                 "--method", "laplace", "--task-grasps", str(f), "--json", "--png", str(png)]) == 0
    out = capsys.readouterr().out
    doc = json.loads(out[:out.rindex("}") + 1])
    assert set(doc) >= {"grasp", "method", "models", "epsilon", "lifted", "task_ok", "success"}
    assert np.asarray(doc["grasp"]["pose"]).shape == (4, 4)
    validate(doc["grasp"])                                      # the one grasp schema
    assert [m["model"] for m in doc["models"]] == [f"mug/{i}" for i in (0, 1, 2, 4, 5, 6)]
    assert png.stat().st_size > 1000


@pytest.mark.parametrize("args, needle", [
    (["--category", "spoon", "--task", "top"], "spoon"),
    (["--category", "mug", "--task", "throw"], "throw"),
])
def test_category_cli_bad_input(args, needle, capsys):
    assert main(["category", *args, "--scene-object", "mug/3"]) == 2
    assert needle in capsys.readouterr().err


def test_task_grasp_files_are_validated(tmp_path):
    bad = tmp_path / "g.json"
    bad.write_text(json.dumps({"grasps": [{"model": "mug/1", "task": "top", "pose": np.eye(3).tolist(), "spread": 0}]}))
    with pytest.raises(ValueError, match="4x4"):
        load_task_grasp_file(bad)
    T = np.eye(4)
    T[:3, :3] *= 2
    bad.write_text(json.dumps({"grasps": [{"model": "mug/1", "task": "top", "pose": T.tolist(), "spread": 0}]}))
    with pytest.raises(ValueError, match="rigid"):
        load_task_grasp_file(bad)


@pytest.fixture(scope="module")
def scan(tmp_path_factory):
    """examples/make_scan.py, run as the README runs it: a mug seen 10 cm off the origin."""
    import subprocess
    import sys
    from pathlib import Path

    out = tmp_path_factory.mktemp("scan")
    root = Path(__file__).resolve().parents[2]
    p = subprocess.run([sys.executable, str(root / "examples" / "make_scan.py"), "--object", "mug/3", "--pose",
                        "0.1,-0.05,-1.0", "--out", str(out)], capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    return out


def test_category_cli_plans_on_a_camera_cloud_and_executes_on_the_stand_in(grasp_file, scan, capsys):
    f, _ = grasp_file
    base = ["category", "--category", "mug", "--task", "top", "--method", "laplace", "--task-grasps", str(f),
            "--exclude", "mug/3", "--json", "--cloud", str(scan / "cloud.ply"), "--extrinsic", str(scan / "extrinsic.json")]
    assert main(base) == 0                                  # plan only: no stand-in
    doc = json.loads(capsys.readouterr().out)
    assert doc["executed"] is False and doc["lifted"] is None and doc["success"] is None
    G = np.asarray(doc["grasp"]["pose"])
    assert np.hypot(G[0, 3] - 0.1, G[1, 3] + 0.05) < 0.08   # over the scanned mug, not the origin
    assert main(base + ["--scene-object", "mug/3", "--object-pose", "0.1,-0.05,-1.0"]) == 0
    done = json.loads(capsys.readouterr().out)
    assert done["executed"] is True and isinstance(done["lifted"], bool)
    np.testing.assert_allclose(done["planned_pose"], G)     # the same plan, now executed
    validate(done["grasp"])                                 # where the hand closed
    assert done["grasp"]["joint_positions"] != doc["grasp"]["joint_positions"]   # closed, not the open preshape
    ros = base[:base.index("--json")] + base[base.index("--json") + 1:] + ["--format", "ros"]
    assert main(ros) == 0                                   # plan only, as moveit_msgs/Grasp
    r = json.loads(capsys.readouterr().out)
    p = r["grasp_pose"]["pose"]["position"]
    np.testing.assert_allclose([p["x"], p["y"], p["z"]], G[:3, 3])
    assert r["pre_grasp_posture"]["joint_names"] == doc["grasp"]["joint_names"]
    assert main(base[:-4] + ["--complete", "--cloud", str(scan / "cloud.ply")]) == 2
    assert "--complete" in capsys.readouterr().err


def test_plan_cli_starts_its_belief_from_registering_the_mesh_to_a_depth_image(scan, tmp_path, capsys):
    from bayesgrasp.cli import main as cli

    args = ["plan", "--object", "mug/3", "--true-pose", "0.1,-0.05,-1.0", "--attempts", "1", "--json",
            "--depth", str(scan / "depth.png"), "--intrinsics", str(scan / "intrinsics.json"),
            "--extrinsic", str(scan / "extrinsic.json"), "--success", "epsilon",
            "--cache", str(tmp_path / "cache")]
    for k, v in {"n_samples": 300, "n_inducing": 40, "max_iter": 30, "n_calibration": 100, "n_pilot": 40,
                 "n_pilot_lifts": 10}.items():
        args += ["--set", f"models.{k}={v}"]
    assert cli(args) == 0
    doc = json.loads(capsys.readouterr().out)
    est, hw = np.asarray(doc["vision"]["estimate"]), np.asarray(doc["vision"]["half_width"])
    assert np.hypot(est[0] - 0.1, est[1] + 0.05) < 0.01
    np.testing.assert_allclose(doc["estimate"], est)
    assert 0.01 <= hw[0] <= 0.04 and np.radians(10) - 1e-9 <= hw[2] <= np.pi + 1e-9
    yaw_error = abs((est[2] + 1.0 + np.pi) % (2 * np.pi) - np.pi)
    assert yaw_error <= hw[2]                                # the initial belief covers the true yaw
    assert cli(args + ["--estimate", "0,0,0"]) == 2
    assert "--estimate" in capsys.readouterr().err
