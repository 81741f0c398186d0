"""One touch (Pub. I) through the Python layer: the touch model on the library's objects against the
world simulated in the world frame, symmetric objects' flat yaw, a small fixed-seed version of the
thesis's findings, bad input, and the pub1 report on a few runs."""
import numpy as np
import pytest

from bayesgrasp.experiments import single_touch as S
from bayesgrasp.experiments.registry import get_experiment
from bayesgrasp.experiments.runner import RunKey, run_seed
from bayesgrasp.planners import touch as T


@pytest.fixture(scope="module")
def cube():
    return T.TouchModel("cube")


def _touch(obj, truth, guess, scale=1.0, spread=0.0):
    grasp = T.top_grasp(guess[0], guess[1], guess[2], spread)
    return grasp, T.read(T.touch_world(obj, truth, scale), grasp)


@pytest.mark.parametrize("obj", ["mug", "hammer/0"])
def test_the_truth_predicts_the_measured_readings(obj):
    model = T.TouchModel(obj)
    truth = np.array([0.02, -0.01, 0.8])
    grasp, readings = _touch(obj, truth, truth + [0.01, 0.005, -0.2])
    assert readings.contact_count > 0
    p = model.predict(grasp, truth[None, :], readings)
    # the same grasp up to the simulator's resolution (0.2 mm of contact tolerance on a phalanx)
    np.testing.assert_allclose(p.joints[0], readings.joints, atol=4e-3)
    np.testing.assert_array_equal(p.contact[0], readings.contact)
    assert p.hand_height[0] == pytest.approx(readings.hand_pose[2, 3], abs=1e-9)
    for term in ("flags", "surface"):
        f = model.fitness(grasp, readings, truth[None, :], contact_term=term)
        assert f.total[0] < 0.01 and f.contact[0] == 0.0
    # and a state 5 mm off fits clearly worse
    assert model.fitness(grasp, readings, (truth + [0.005, 0, 0])[None, :]).total[0] > 0.1


def test_batch_equals_one_by_one(cube):
    grasp, readings = _touch("cube", (0.0, 0.01, 0.3), (0.01, 0.0, 0.2))
    states = np.array([[0.0, 0.01, 0.3, 1.0], [0.01, 0.0, 0.1, 1.1], [-0.01, 0.02, 0.5, 0.9]])
    batch = cube.predict(grasp, states, readings, threads=2)
    for i, s in enumerate(states):
        one = cube.predict(grasp, s[None, :], readings)
        np.testing.assert_array_equal(batch.joints[i], one.joints[0])
        np.testing.assert_array_equal(batch.contact[i], one.contact[0])
        np.testing.assert_array_equal(batch.surface_distance[i], one.surface_distance[0])
    f = cube.fitness(grasp, readings, states, threads=2).total
    np.testing.assert_array_equal(f, [cube.fitness(grasp, readings, s[None, :]).total[0] for s in states])


def test_a_body_of_revolution_is_flat_in_yaw_and_reported_undefined():
    model = T.TouchModel("cylinder")
    truth = np.array([0.01, 0.0, 0.3])
    grasp, readings = _touch("cylinder", truth, (0.0, 0.0, 0.2))
    yaws = np.linspace(-np.pi, np.pi, 13)
    f = model.fitness(grasp, readings, np.column_stack([np.full(13, 0.01), np.zeros(13), yaws])).total
    off = model.fitness(grasp, readings, [[0.013, 0.0, 0.3]]).total[0]
    assert f.max() < 0.01 < 0.1 < off
    assert T.symmetry_order("cylinder") is None and T.symmetry_order("bottle/0") is None
    assert T.orientation_error(1.0, 0.0, None) is None


def test_orientation_errors_modulo_symmetry():
    assert T.symmetry_order("cube") == 4 and T.symmetry_order("mug") == 1
    assert T.orientation_error(np.pi / 2 + 0.1, 0.0, 4) == pytest.approx(0.1)
    assert T.orientation_error(-np.pi / 2 - 0.1, 0.0, 4) == pytest.approx(0.1)
    assert T.orientation_error(np.pi - 0.1, -np.pi + 0.1, 1) == pytest.approx(0.2)


def test_on_the_cube_most_3dof_estimates_are_closer_than_the_guess(cube):
    # the thesis's "position comes out well", small and seeded: 8 truth / guess pairs
    rng = np.random.default_rng(5)
    closer = 0
    for k in range(8):
        truth, guess = S.problem("pose", rng)
        planner = T.TouchPlanner(cube, guess, T.TouchSettings(budget=2000, seed=k))
        grasp = planner.plan().touch
        r = planner.observe(grasp, T.read(T.touch_world("cube", truth[:3]), grasp))
        assert r.fitness <= r.initial_fitness
        closer += np.hypot(*(planner.estimate - truth)[:2]) < np.hypot(*(guess - truth)[:2])
    assert closer >= 6


def test_given_the_position_the_mug_orientation_is_found():
    model = T.TouchModel("mug")
    truth = np.array([0.01, -0.02, 0.4])
    guess = np.array([0.01, -0.02, 0.4 + np.radians(25)])
    grasp, readings = _touch("mug", truth, guess)
    r = model.estimate(grasp, readings, guess, unknowns="orientation", budget=200)
    assert r.state[0] == 0.01 and r.state[1] == -0.02
    assert abs(r.state[2] - truth[2]) < np.radians(2.0) < abs(guess[2] - truth[2])


def test_the_size_is_estimated(cube):
    truth, guess = np.array([0.0, 0.0, 0.3]), np.array([0.01, -0.01, 0.45])
    grasp, readings = _touch("cube", truth, guess, scale=1.15)
    r = cube.estimate(grasp, readings, guess, unknowns="pose_and_scale", budget=1000)
    assert abs(r.state[3] - 1.15) < 0.02 < abs(1.0 - 1.15)


def test_the_stop_level_ends_the_search_early_and_changes_nothing_at_zero(cube):
    truth, guess = np.array([0.005, 0.0, 0.3]), np.array([-0.01, 0.01, 0.5])
    grasp, readings = _touch("cube", truth, guess)
    full = cube.estimate(grasp, readings, guess, budget=2000, seed=3)
    assert full.evaluations == 2000 and not full.stopped
    zero = cube.estimate(grasp, readings, guess, budget=2000, seed=3, stop_fitness=0.0)
    np.testing.assert_array_equal(zero.state, full.state)
    assert zero.trace_fitness == full.trace_fitness
    # a level the first swarm already reaches: one batch of 20, then the search ends
    first = cube.estimate(grasp, readings, guess, budget=2000, seed=3, stop_fitness=1e9)
    assert first.stopped and first.evaluations == 20
    # a level in between: the same search as the full one up to the first batch below it
    s = 0.05
    part = cube.estimate(grasp, readings, guess, budget=2000, seed=3, stop_fitness=s)
    k = next(i for i, f in enumerate(full.trace_fitness) if f < s)
    assert part.stopped and part.fitness < s
    assert part.evaluations == full.trace_evaluations[k] < 2000
    assert part.trace_fitness == full.trace_fitness[: k + 1]
    # the local optimisers stop there too
    local = cube.estimate(grasp, readings, guess, optimizer="descent", budget=2000, stop_fitness=1e9)
    assert local.stopped and local.evaluations < 2000
    for bad in (-0.1, float("nan"), float("inf")):
        with pytest.raises(ValueError, match="stop_fitness"):
            cube.estimate(grasp, readings, guess, stop_fitness=bad)
    # the loop's settings carry it to the search
    planner = T.TouchPlanner(cube, guess, T.TouchSettings(seed=3, stop_fitness=s))
    assert planner.observe(grasp, readings).evaluations == part.evaluations


def test_bad_input(cube):
    grasp, none = _touch("cube", (0.0, 0.0, 0.0), (0.3, 0.3, 0.0))
    assert none.contact_count == 0
    r = cube.estimate(grasp, none, (0.3, 0.3, 0.0))
    assert r.status == T.EstimateStatus.no_contact and r.evaluations == 0 and "nothing learnt" in r.message
    np.testing.assert_array_equal(r.state, [0.3, 0.3, 0.0, 1.0])
    bad = T.TouchReadings(np.full(7, np.nan), none.contact, none.hand_pose)
    with pytest.raises(ValueError, match="joints"):
        cube.estimate(grasp, bad, (0.3, 0.3, 0.0))
    with pytest.raises(ValueError, match="budget"):
        cube.estimate(grasp, none, (0.3, 0.3, 0.0), optimizer="firefly", budget=10)
    with pytest.raises(ValueError, match="optimizer"):
        T.estimate_options(optimizer="newton")
    with pytest.raises(ValueError, match="states"):
        cube.predict(grasp, np.zeros((2, 2)))
    with pytest.raises(ValueError, match="scale"):
        T.scaled_object("cube", -1.0)
    assert T.minimum_budget(T.OPTIMIZERS["pso"], 3) == 40


def test_pub1_runs_and_reports_without_the_loop(tmp_path, monkeypatch):
    # three runs of each optimiser on the cube, the second grasp replaced (it needs grasp models)
    from bayesgrasp.experiments.run_records import PlannedGrasp, SecondGrasp

    def second_grasp(obj, planner, truth, ctx):
        return SecondGrasp(PlannedGrasp(np.zeros(3), False, 0.0, False), PlannedGrasp(np.zeros(3), True, 0.1, True))

    monkeypatch.setattr(S, "_second_grasp", second_grasp)
    monkeypatch.setattr(S, "BUDGET", 200)
    exp = get_experiment("pub1")
    from bayesgrasp.experiments import RunContext
    ctx = RunContext()
    results = {}
    for opt in exp.methods:
        series, fn = exp.make_run(exp, opt, ctx)
        seeds = [run_seed(0, exp.seeds, "cube", i) for i in range(3)]
        results[opt] = [(RunKey(series, "cube", i, s), fn(series, "cube", i, s).to_dict())
                        for i, s in enumerate(seeds)]
    # every optimiser saw the same problems
    truths = {opt: [r["cases"]["pose"]["truth"] for _, r in res] for opt, res in results.items()}
    assert all(t == truths["pso"] for t in truths.values())
    summary = exp.report(exp, results, tmp_path).summary
    for case in S.CASES:
        assert (tmp_path / f"errors_{case}.png").exists()
        assert {r["optimizer"] for r in summary[case]} == set(S.OPTIMIZERS)
    assert [f["finding"] for f in summary["findings"]][0].startswith("one touch")
    assert all(isinstance(f["yes"], bool) for f in summary["findings"])
    assert all(g["success_updated"] == 1.0 for g in summary["second_grasp"])
    assert "## The thesis's findings" in (tmp_path / "summary.md").read_text()
