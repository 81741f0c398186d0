"""Grasp families (top and side): the side family's features and samples, its models, the
planners searching both families and updating with the executed family's models, and the
episode / CLI records."""
import json
from dataclasses import replace

import numpy as np
import pytest

from bayesgrasp.cli import main
from bayesgrasp.experiments import EpisodeSettings, RunContext, run_episode
from bayesgrasp.models import FAMILIES, ModelSettings, Variant, parse_families
from bayesgrasp.planners import ExplorationPlanner, Reading, StabilityPlanner, get_models
from bayesgrasp.planners.pose_results import Observation
from bayesgrasp.world import World

SMALL = dict(n_samples=400, n_inducing=60, max_iter=40, seed=3, n_lift_samples=300, n_calibration=200,
             n_pilot=100, n_pilot_lifts=20)


def test_parse_families_orders_and_refuses():
    assert parse_families("side,top") == FAMILIES
    assert parse_families(" side ") == ("side",)
    assert parse_families(["top"]) == ("top",)
    for bad in ("", "front", "top,,side"):
        with pytest.raises(ValueError, match="families"):
            parse_families(bad)
    with pytest.raises(ValueError, match="family"):
        Variant(family="front")
    with pytest.raises(ValueError, match="family"):
        ModelSettings(family="front")


def test_side_features_depend_on_the_line_only():
    v = Variant("side", spread=0.0, height=0.1)
    rng = np.random.default_rng(0)
    rel = np.column_stack([rng.uniform(-0.1, 0.1, 20), rng.uniform(-0.1, 0.1, 20), rng.uniform(-np.pi, np.pi, 20)])
    t = rng.uniform(-0.3, 0.3, 20)[:, None]
    slid = rel.copy()
    slid[:, :2] += t * np.column_stack([np.cos(rel[:, 2]), np.sin(rel[:, 2])])   # along the approach line
    np.testing.assert_allclose(v.features(rel), v.features(slid), atol=1e-12)
    assert v.features(rel).shape == (20, 3) and v.n_features == 3
    # across the line, the offset d changes by exactly the step
    across = rel.copy()
    across[:, :2] += 0.01 * np.column_stack([-np.sin(rel[:, 2]), np.cos(rel[:, 2])])
    np.testing.assert_allclose(v.features(across)[:, 0] - v.features(rel)[:, 0], 0.01, atol=1e-12)
    box = np.array([[-0.05, -0.05], [0.05, 0.05]])
    s = v.sample(rng, 500, box)
    assert np.all(np.abs(v.features(s)[:, 0]) <= 0.5 * np.hypot(0.1, 0.1) + 1e-12)
    assert Variant().features(rel).shape == (20, 4)


def test_side_grasp_comes_in_horizontally_at_the_variant_height():
    world = World.single("cylinder", pose=(0.0, 0.0, 0.0))
    v = Variant("side", spread=0.0, height=0.06, roll=0.0)
    g = v.grasp(world, (0.0, 0.0, 0.0), lift=True)
    b = v.simulate(world, np.array([[0.0, 0.0, 0.0]]), lift=True)
    # one grasp and the batch agree: same joint angles, same lift outcome
    np.testing.assert_allclose(np.asarray(g.joint_angles), np.asarray(b.joint_angles)[0], atol=1e-9)
    assert bool(g.lifted) == bool(np.asarray(b.lifted)[0])
    assert len(g.contacts) >= 2
    # the contacts sit around the variant's height, not on the cylinder's top face
    z = np.array([c.point[2] for c in g.contacts if not c.on_table])
    assert len(z) >= 2 and np.all(z < 0.12 - 0.005)   # the cylinder is 12 cm tall


@pytest.fixture(scope="module")
def cylinder(tmp_path_factory):
    cache = str(tmp_path_factory.mktemp("models"))
    return {f: get_models("cylinder", settings=ModelSettings(**SMALL, family=f), cache_dir=cache) for f in FAMILIES}


def test_side_models_record_their_variant(cylinder):
    side = cylinder["side"]
    assert side.family == "side" and side.variant.family == "side"
    assert 0.0 < side.variant.height < 0.2 and side.variant.roll in (0.0, float(np.pi / 2))
    assert cylinder["top"].variant.family == "top" and cylinder["top"].variant.height == 0.0


def test_planner_picks_the_better_family_and_updates_with_its_models(cylinder):
    est = (0.01, -0.01, 0.2)
    both = StabilityPlanner(cylinder, estimate=est, seed=1)
    assert both.families == FAMILIES
    plan = both.plan()
    assert plan.family in FAMILIES
    # the combined plan is as good as the better single-family plan from the same belief, and
    # takes that family when the two differ clearly
    alone = {f: StabilityPlanner(cylinder[f], estimate=est, seed=1).plan().predicted_stability for f in FAMILIES}
    assert plan.predicted_stability >= max(alone.values()) - 0.03
    if abs(alone["top"] - alone["side"]) > 0.1:
        assert plan.family == max(alone, key=alone.get)
    assert both.expected_stability(plan.action, plan.family) == pytest.approx(plan.predicted_stability, abs=1e-9)
    with pytest.raises(ValueError, match="family"):
        both.observe(plan.action, Reading(np.full(cylinder["side"].n_joints, 0.5), held=False))   # which family?
    with pytest.raises(ValueError, match="family"):
        both.observe(replace(plan, family="front"), Reading(np.full(cylinder["side"].n_joints, 0.5), held=False))
    # observing a side grasp weights the particles by the side models' likelihood, not the top's
    m = np.full(cylinder["side"].n_joints, 0.6)
    side_only = StabilityPlanner(cylinder["side"], estimate=est, seed=1)
    both2 = StabilityPlanner(cylinder, estimate=est, seed=1)
    side_obs, top_obs = (Observation(np.array(plan.action), m, False, f) for f in ("side", "top"))
    P = both2.belief.particles
    np.testing.assert_allclose(both2.log_likelihood(P, side_obs), side_only.log_likelihood(P, side_obs))
    assert not np.allclose(both2.log_likelihood(P, side_obs), both2.log_likelihood(P, top_obs))
    both2.observe(replace(plan, family="side"), Reading(m, held=False))
    assert both2.history[-1].observation.family == "side"
    # exploration searches both families too
    ex = ExplorationPlanner(cylinder, estimate=est, seed=2)
    assert ex.plan().family in FAMILIES


def test_mismatched_family_models_are_refused(cylinder):
    with pytest.raises(ValueError, match="models"):
        StabilityPlanner({"side": cylinder["top"]}, estimate=(0, 0, 0))
    with pytest.raises(ValueError, match="models"):
        StabilityPlanner({"front": cylinder["top"]}, estimate=(0, 0, 0))


def test_episode_executes_the_planned_family(cylinder):
    ctx = RunContext(families="top,side")
    r = run_episode("cylinder", (0.02, -0.01, 0.4), EpisodeSettings(method="stability", attempts=2), ctx, seed=0,
                    models=cylinder)
    for a in r.to_dict()["attempts"]:
        assert a["family"] in FAMILIES and a["variant"]["family"] == a["family"]
        assert a["lifted"] is not None and a["success"] == a["lifted"]


def test_plan_cli_reports_family_and_full_pose(capsys, tmp_path):
    assert main(["plan", "--object", "cube", "--true-pose", "0,0,0", "--families", "top,front"]) == 2
    assert "families" in capsys.readouterr().err
    args = ["plan", "--object", "cylinder", "--true-pose", "0.02,-0.01,0.4", "--families", "top,side", "--json",
            "--method", "stability", "--cache", str(tmp_path / "cache")]
    for k, v in SMALL.items():
        args += ["--set", f"models.{k}={v}"]
    assert main(args) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["attempts"]
    for a in doc["attempts"]:
        assert a["family"] in FAMILIES and a["variant"]["family"] == a["family"] and len(a["action"]) == 3
        g = a["grasp"]
        T = np.asarray(g["pose"])
        assert T.shape == (4, 4) and len(g["quaternion_xyzw"]) == 4 and len(g["joint_positions"]) == len(g["joint_names"])
        if a["family"] == "side":   # comes in horizontally at the variant's height
            assert a["top_grasp"] is None and abs(g["approach"][2]) < 1e-6
            assert g["spread"] == pytest.approx(a["variant"]["spread"])
        else:                       # comes down
            assert a["top_grasp"] == a["action"] and g["approach"][2] < -0.99

WIDE = dict(kind="cylinder", radius=0.07, height=0.2, segments=64, density=700.0)


def test_side_grasp_is_planned_when_no_top_grasp_can_lift(tmp_path):
    # A standing cylinder 14 cm across: from above, the open hand's fingers land on its flat top
    # face (they sit within 5 cm of the palm's centre), so closing presses them into the face and
    # nothing can hold it - checked here on 150 random top grasps at both spreads. From the side
    # the palm meets the wall and the fingers wrap round it.
    from bayesgrasp.objects.library import generate

    obj = generate(WIDE, name="wide_cylinder")
    world = World.single(obj, pose=(0.0, 0.0, 0.0))
    rng = np.random.default_rng(0)
    box = np.array([[-0.07, -0.07], [0.07, 0.07]])
    for spread in (0.0, np.pi / 2):
        top = Variant("top", spread=spread)
        assert not np.any(top.simulate(world, top.sample(rng, 150, box), lift=True).lifted)
    models = {f: get_models(obj, settings=ModelSettings(**SMALL, family=f), cache_dir=str(tmp_path)) for f in FAMILIES}
    ctx = RunContext(families="top,side")
    r = run_episode(obj, (0.01, 0.02, 0.3), EpisodeSettings(method="stability"), ctx, seed=0, models=models)
    assert all(a.plan.family == "side" for a in r.attempts)
    assert r.success and r.attempts[-1].lifted
