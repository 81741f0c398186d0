"""The category pipeline end to end on a small set of demonstrated grasps: generated from the
rules with a small budget, stored and loaded as data, planned on a held-out mug's view, executed."""
import json

import numpy as np
import pytest

from bayesgrasp.cli import main
from bayesgrasp.experiments.category import (observe, plan_and_execute, register_models, roll_of, see,
                                             training_models)
from bayesgrasp.experiments.context import RunContext
from bayesgrasp.hand import Hand
from bayesgrasp.models.task_grasps import (TaskGraspSettings, generate_task_grasps, grasp_to_json,
                                           load_task_grasp_file)
from bayesgrasp.models.tasks import task_rule
from bayesgrasp.world import World

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
        assert np.isclose(np.cos(roll_of(T) - roll), 1.0, atol=1e-9)


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
        out = plan_and_execute(ep, "mug", "top", method, ctx, seed=1, grasps=grasps)
        assert out["plan_ok"] and out["executed"]
        assert out["dominant_model"] in ("mug/1", "mug/2")
        assert sum(out["weights"].values()) == pytest.approx(1.0)
        assert out["success"] == (out["lifted"] and out["task_ok"])
        assert (out["failure"] is None) == out["success"]
    # models without demonstrated grasps: an explicit no-grasp result, never a silent grasp
    none = plan_and_execute(ep, "mug", "top", "laplace", ctx, grasps=[g for g in grasps if g.model == "mug/9"])
    assert not none["executed"] and "no demonstrated grasps" in none["reason"]


def test_the_complete_model_mode_registers_the_whole_surface():
    o = observe("mug/3", (0.0, 0.0, 0.5), complete=True)
    assert o.complete and len(o.cloud) == 3000
    regs = register_models(o, ["mug/1"])
    assert regs[0].success


def test_category_cli_json_and_png(grasp_file, tmp_path, capsys):
    f, _ = grasp_file
    png = tmp_path / "c.png"
    assert main(["category", "--category", "mug", "--task", "top", "--scene-object", "mug/3", "--pose", "-0.01,0.02,0.4",
                 "--method", "laplace", "--task-grasps", str(f), "--json", "--png", str(png)]) == 0
    out = capsys.readouterr().out
    doc = json.loads(out[:out.rindex("}") + 1])
    assert set(doc) >= {"grasp", "method", "models", "epsilon", "lifted", "task_ok", "success"}
    assert np.asarray(doc["grasp"]["pose"]).shape == (4, 4)
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
