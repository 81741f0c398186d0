"""One planner interface (planners.protocol): plan() -> a plan with .action and .to_dict(),
observe(grasp, measurement) -> an update with .to_dict(), .belief; for the pose, category, fusion
and touch planners, each checked on what its observe changes."""
import json

import numpy as np
import pytest

from bayesgrasp.belief import absolute_planar_pose
from bayesgrasp.belief.model_mixture import ModelMixtureBelief
from bayesgrasp.models import build_models
from bayesgrasp.planners import PLANNERS, GraspPlanner, Reading
from bayesgrasp.planners import touch as T
from bayesgrasp.planners.category import CategoryPlanner, CategorySettings
from bayesgrasp.planners.fusion import FusionPlanner
from bayesgrasp.vision import RegistrationResult
from testkit import HAND, TINY, TOP, analytic, grasp, measurement, rz, tiny_planner


def _round_trip(result) -> dict:
    d = result.to_dict()
    assert json.loads(json.dumps(d)) == d      # JSON-ready as it is
    return d


def test_the_pose_planner_has_the_interface():
    p = tiny_planner()
    assert isinstance(p, GraspPlanner)
    plan = p.plan()
    assert _round_trip(plan)["action"] == plan.action.tolist()
    w0, P0 = p.belief.weights.copy(), p.belief.particles.copy()
    up = p.observe(plan, Reading(np.full(p.models.n_joints, 0.5), held=False))
    assert len(p.observations) == 1 and p.observations[0].stable is False and p.observations[0].family == plan.family
    # the reading moved the belief (re-weighted, or resampled and jittered)
    assert not np.allclose(p.belief.weights, w0) or not np.array_equal(p.belief.particles, P0)
    assert _round_trip(up)["ess"] == pytest.approx(p.belief.ess())


def test_the_fusion_planner_observes_through_its_belief_and_then_weighs_stability():
    belief = ModelMixtureBelief(["a", "b"], [analytic(True), analytic(False)], [0.5, 0.5], [[0, 0, 0], [0, 0, 0]])
    planner = FusionPlanner(belief, [np.array([[0.0, 0.0, 0.0]])] * 2, seed=3)
    assert isinstance(planner, GraspPlanner) and planner.belief is belief
    first = planner.plan()
    assert first.round == 1 and first.objective == pytest.approx(first.task, rel=1e-9)   # the task term alone
    up = planner.observe(first, Reading(measurement(first.action)))
    assert _round_trip(up)["weights"] == belief.weights.tolist() and belief.weights[0] > 0.5
    second = planner.plan()
    assert second.round == 2 and second.objective == pytest.approx(second.task * second.stability, rel=1e-9)
    assert _round_trip(second)["round"] == 2
    with pytest.raises(ValueError, match="measurement"):
        planner.observe(second, [0.1])
    assert planner.observations == 1


def test_a_grasp_observed_before_the_first_plan_makes_that_plan_weigh_stability():
    belief = ModelMixtureBelief(["a"], [analytic(True)], [1.0], [[0, 0, 0]])
    planner = FusionPlanner(belief, [np.array([[0.0, 0.0, 0.0]])], seed=3)
    planner.observe([0.01, 0.0, 0.0], measurement([0.01, 0.0, 0.0]))     # joint angles alone
    plan = planner.plan()
    assert plan.round == 2 and plan.objective == pytest.approx(plan.task * plan.stability, rel=1e-9)


def test_a_category_grasp_that_did_not_hold_is_not_planned_again():
    # two models, each with one task grasp 5 cm apart: the heavier one's is planned first
    regs = [RegistrationResult.known("a", rz(0.0), phi=0.9), RegistrationResult.known("b", rz(0.0, (0.05, 0, 0)), phi=0.6)]
    planner = CategoryPlanner(HAND, [grasp("a", TOP), grasp("b", TOP)], regs, settings=CategorySettings(), seed=1)
    assert isinstance(planner, GraspPlanner) and planner.belief == pytest.approx({"a": 0.6, "b": 0.4})
    first = planner.plan()
    assert first.dominant_model == "a" and _round_trip(first)["pose"] == first.action.tolist()
    held = planner.observe(first, Reading([0.5, 0.5], held=True))          # held: nothing to change
    assert held.weight_after == held.weight_before and planner.plan().dominant_model == "a"
    failed = planner.observe(first, Reading([0.5, 0.5], held=False))
    assert _round_trip(failed)["held"] is False and failed.weight_after < failed.weight_before
    second = planner.plan()
    assert second.dominant_model == "b"
    assert np.linalg.norm(second.pose[:3, 3] - first.pose[:3, 3]) > 0.04
    with pytest.raises(ValueError, match="4x4"):
        planner.observe(np.eye(3), Reading([0.5], held=False))
    assert len(planner.failed) == 1                                          # nothing changed by the failed call


def test_the_touch_planner_touches_without_models_and_grasps_with_them():
    truth, guess = np.array([0.01, -0.01, 0.2]), np.array([0.0, 0.0, 0.3])
    planner = T.TouchPlanner("cube", guess, T.TouchSettings(budget=300, seed=2))
    assert isinstance(planner, GraspPlanner) and np.array_equal(planner.belief, np.append(guess, 1.0))
    plan = planner.plan()
    assert plan.kind == "touch" and np.allclose(plan.action, guess) and _round_trip(plan)["kind"] == "touch"
    r = planner.observe(plan, T.read(T.touch_world("cube", truth), plan.touch))
    assert r.fitness <= r.initial_fitness and np.array_equal(planner.belief, r.state)
    d = _round_trip(r)
    assert d["status"] == "estimated" and d["state"] == planner.belief.tolist() and d["fitness"] == r.fitness
    assert d["trace"]["evaluations"] == list(r.trace_evaluations) and d["fitness_terms"]["joint"] == r.joint_term
    with pytest.raises(TypeError, match="measurement: expected the hand's TouchReadings"):
        planner.observe(plan, np.zeros(4))
    assert len(planner.results) == 1
    models = build_models("cube", settings=TINY, cache_dir=None)
    grasping = T.TouchPlanner("cube", planner.belief, models=models).plan()
    best = models.table().best_relative_grasps(1)[0]
    assert grasping.kind == "stability" and grasping.touch.spread == pytest.approx(models.spread)
    np.testing.assert_allclose(grasping.action, absolute_planar_pose(best[None], planner.belief[None, :3])[0])


@pytest.mark.parametrize("cls", [*PLANNERS.values(), FusionPlanner, CategoryPlanner, T.TouchPlanner])
def test_every_planner_names_the_protocols_arguments(cls):
    """observe(grasp, measurement), plan() without arguments, as GraspPlanner declares them (an
    isinstance check sees only that the names exist)."""
    import inspect

    assert list(inspect.signature(cls.observe).parameters) == ["self", "grasp", "measurement"]
    assert list(inspect.signature(cls.plan).parameters) == ["self"]
