"""Vision + touch fusion (Eqs. 4.4-4.6) on models with analytic tables: a model whose joint
angles follow the relative grasp linearly, and one that predicts the same angles everywhere."""
import numpy as np
import pytest

from bayesgrasp.belief.model_mixture import ModelMixtureBelief
from bayesgrasp.planners.fusion import FusionPlanner, FusionSettings
from testkit import TRUE, analytic, measurement


@pytest.mark.parametrize("kind", ["map", "particles"])
def test_one_touch_moves_the_true_models_pose_towards_the_truth_and_raises_its_weight(kind):
    belief = ModelMixtureBelief(["a", "b"], [analytic(True), analytic(False)], [0.5, 0.5], [[0, 0, 0], [0, 0, 0]],
                                FusionSettings(belief=kind, particles_per_model=400), seed=1)
    g = np.array([0.0, 0.0, 0.0])
    up = belief.update(g, measurement(g))
    assert not up.underflow
    assert up.weights[0] > 0.9 and up.weights.sum() == pytest.approx(1.0)
    err0 = np.hypot(*TRUE[:2])
    assert np.hypot(*(up.poses[0, :2] - TRUE[:2])) < 0.6 * err0
    if kind == "map":
        # Eq. 4.4 with a Gaussian likelihood of sd 0.05 / 10 = 5 mm per axis and a 15 mm prior:
        # the mode is the truth shrunk by 15^2 / (15^2 + 5^2) = 0.9
        np.testing.assert_allclose(up.poses[0, :2], 0.9 * TRUE[:2], atol=5e-4)
        # the uninformative model's pose has nothing to move it
        np.testing.assert_allclose(up.poses[1], [0, 0, 0], atol=1e-6)


def test_weights_eq45_forget_or_recurse():
    a, b = analytic(True), analytic(True)
    plain = ModelMixtureBelief(["a", "b"], [a, b], [0.9, 0.1], [[0, 0, 0], [0, 0, 0]], FusionSettings())
    rec = ModelMixtureBelief(["a", "b"], [a, b], [0.9, 0.1], [[0, 0, 0], [0, 0, 0]], FusionSettings(recursive=True))
    g = np.zeros(3)
    assert plain.update(g, measurement(g)).weights == pytest.approx([0.5, 0.5])   # identical models
    assert rec.update(g, measurement(g)).weights == pytest.approx([0.9, 0.1])


def test_round_one_uses_the_task_term_and_later_rounds_stability_times_task():
    belief = ModelMixtureBelief(["a"], [analytic(True)], [1.0], [[0.02, 0.01, 0.3]], FusionSettings(), seed=2)
    planner = FusionPlanner(belief, [np.array([[0.0, 0.0, 0.0]])], seed=3)
    p1 = planner.plan()
    # the task grasp at the model's origin, placed by its pose: (0.02, 0.01, 0.3)
    np.testing.assert_allclose(p1.action, [0.02, 0.01, 0.3], atol=2e-3)
    assert p1.round == 1 and p1.objective == pytest.approx(p1.task, rel=1e-9)
    p2 = planner.plan()
    assert p2.round == 2 and p2.objective == pytest.approx(p2.task * p2.stability, rel=1e-9)
    assert p2.stability > 0.9   # centred on the model: the analytic P(S) is ~1


def test_bad_input_is_named():
    belief = ModelMixtureBelief(["a"], [analytic(True)], [1.0], [[0, 0, 0]])
    with pytest.raises(ValueError, match="measurement"):
        belief.update([0, 0, 0], [0.1])
    with pytest.raises(ValueError, match="measurement"):
        belief.update([0, 0, 0], [np.nan, 0.1])
    with pytest.raises(ValueError, match="grasp"):
        belief.update([0, 0], [0.1, 0.1])
    with pytest.raises(ValueError, match="weights"):
        ModelMixtureBelief(["a"], [analytic(True)], [0.0], [[0, 0, 0]])
    with pytest.raises(ValueError, match="task_grasps"):
        FusionPlanner(belief, [np.zeros((0, 3))])
    with pytest.raises(ValueError, match="belief"):
        FusionSettings(belief="kalman")


def test_every_likelihood_underflowing_keeps_the_weights_and_says_so():
    belief = ModelMixtureBelief(["a", "b"], [analytic(True), analytic(True)], [0.7, 0.3], [[0, 0, 0], [0, 0, 0]])
    up = belief.update([0, 0, 0], [1e6, -1e6])   # absurd angles: zero likelihood everywhere
    assert up.underflow and up.weights == pytest.approx([0.7, 0.3])


def test_an_impossible_measurement_moves_nothing_in_the_particle_belief_either():
    belief = ModelMixtureBelief(["a", "b"], [analytic(True), analytic(True)], [0.7, 0.3], [[0, 0, 0], [0, 0, 0]],
                                FusionSettings(belief="particles"), seed=4)
    before = belief.poses.copy()
    up = belief.update([0, 0, 0], [1e6, -1e6])
    assert up.underflow and up.weights == pytest.approx([0.7, 0.3])
    np.testing.assert_allclose(up.poses, before, atol=1e-12)


def _avoiding(failed_translation: float, start=TRUE, avoid: bool = True):
    s = FusionSettings(avoid_failed=avoid, failed_translation=failed_translation)
    belief = ModelMixtureBelief(["a"], [analytic(True)], [1.0], [start], s, seed=2)
    return FusionPlanner(belief, [np.array([[0.0, 0.0, 0.0]])], seed=3)


def test_a_failed_grasps_neighbourhood_is_avoided_until_the_belief_moves_away():
    """The belief already at the truth: the first plan F (the task grasp there) does not hold and
    the touch leaves the belief where it is. Eq. 4.6 is then multiplied by 1 - exp(-(|dxy| / b_t +
    |dyaw| / b_yaw)) around F (0 at F itself): the next plan leaves F, where a planner without
    avoid_failed plans F again. Once a touch has moved the belief's object by more than b_t (from
    (0, 0, 0) Eq. 4.4 moves it 0.9 x (10, -5) mm = 10.1 mm > 5 mm) F is forgotten; a grasp that
    held is not remembered."""
    from bayesgrasp.planners.protocol import Reading

    planner, blind = _avoiding(0.02), _avoiding(0.02, avoid=False)
    F = planner.plan().action
    np.testing.assert_allclose(F, TRUE, atol=2e-3)
    for p in (planner, blind):
        p.observe(F, Reading(measurement(F), held=False))
    assert np.hypot(*(planner.belief.poses[0, :2] - TRUE[:2])) < 1e-3       # the belief did not move
    G = F + np.array([[0.0, 0.0, 0.0], [0.01, 0.0, 0.0], [0.0, 0.0, np.radians(20)]])
    np.testing.assert_allclose(planner.failure_factor(G), [0.0, 1 - np.exp(-0.5), 1 - np.exp(-1.0)], atol=1e-12)
    p2 = planner.plan()
    assert p2.objective == pytest.approx(p2.task * p2.stability * planner.failure_factor(p2.action[None])[0], rel=1e-9)
    assert planner.failure_factor(p2.action[None])[0] > 0.3
    assert planner.failure_factor(blind.plan().action[None])[0] < 0.05       # planned again next to F

    forgets = _avoiding(0.005, start=[0.0, 0.0, 0.0])
    forgets.observe(F, Reading(measurement(F), held=False))
    assert np.hypot(*forgets.belief.poses[0, :2]) == pytest.approx(0.9 * np.hypot(*TRUE[:2]), rel=0.05)
    assert len(forgets.failed) == 1 and forgets.failure_factor(G).tolist() == [1.0, 1.0, 1.0]
    held = _avoiding(0.02)
    held.observe(F, Reading(measurement(F), held=True))
    assert held.failed == [] and held.failure_factor(G).tolist() == [1.0, 1.0, 1.0]
    assert blind.failure_factor(G).tolist() == [1.0, 1.0, 1.0]
    with pytest.raises(ValueError, match="failed_translation"):
        FusionSettings(failed_translation=0.0)
