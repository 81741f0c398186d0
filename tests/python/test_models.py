import numpy as np
import pytest

from bayesgrasp.models import ModelSettings, build_models, relative_top_grasps
from bayesgrasp.models import AUTO_SPREADS, simulate_training_data
from bayesgrasp.models import training
from bayesgrasp.models.training import lift_outcomes
from bayesgrasp.world import World

SMALL = ModelSettings(n_samples=400, n_inducing=60, xy_range=0.03, max_iter=40, seed=3, n_lift_samples=300,
                      n_calibration=200, n_pilot=100, n_pilot_lifts=20)


def test_relative_top_grasps_by_hand():
    # object at (0.1, 0, 90 deg): a world grasp at (0.1, 0.02, 90 deg) is 2 cm along the object's -x
    rel = relative_top_grasps([[0.1, 0.02, np.pi / 2]], [[0.1, 0.0, np.pi / 2]])
    np.testing.assert_allclose(rel[0, 0], [0.02, 0.0, 0.0], atol=1e-12)
    rel = relative_top_grasps([[0.0, 0.0, -3.0]], [[0.0, 0.0, 3.0]])
    assert -np.pi <= rel[0, 0, 2] < np.pi and rel[0, 0, 2] == pytest.approx(-6.0 + 2 * np.pi)


def test_models_predict_held_out_simulations_and_are_cached(tmp_path):
    models = build_models("cylinder", settings=SMALL, cache_dir=tmp_path)
    assert not models.loaded_from_cache
    # held-out grasps simulated independently
    held = ModelSettings(n_samples=120, n_inducing=60, xy_range=0.03, seed=99)
    rel, q, eps = simulate_training_data(World.single("cylinder"), held, spread=models.spread)
    mean, var = models.predict_measurement(rel)
    err = np.abs(mean - q[:, models.joint_index])
    # the GP explains most of the joint-angle variation of unseen grasps
    r2 = 1 - np.mean(err ** 2) / np.mean((q[:, models.joint_index] - q[:, models.joint_index].mean(0)) ** 2)
    assert r2 > 0.5
    # the true measurement is more likely at its own grasp than at a shifted one
    # (for most of 30 held-out grasps: above the median over the other grasps)
    wins = []
    for i in range(30):
        ll = models.log_likelihood(rel[:30], q[i, models.joint_index])
        wins.append(ll[i] > np.median(np.delete(ll, i)))
    assert np.mean(wins) > 0.7
    p = models.stability_probability(rel)
    assert np.all((p >= 0) & (p <= 1))
    # grasps the simulator's lift test holds get a higher predicted P(S) than those it drops
    lifted = lift_outcomes(World.single("cylinder"), rel, models.spread)
    assert 5 <= lifted.sum() <= len(lifted) - 5  # both classes among the held-out grasps
    assert p[lifted].mean() > p[~lifted].mean() + 0.1

    again = build_models("cylinder", settings=SMALL, cache_dir=tmp_path)
    assert again.loaded_from_cache
    np.testing.assert_allclose(again.predict_measurement(rel[:5])[0], mean[:5], atol=1e-10)
    # other settings (here the success criterion): a new key, the models are rebuilt
    other = build_models("cylinder", settings=ModelSettings(**{**SMALL.__dict__, "success": "epsilon"}),
                         cache_dir=tmp_path)
    assert not other.loaded_from_cache and other.settings.stability_threshold == SMALL.eps_stable
    assert len(list(tmp_path.glob("*.json"))) == 2


def test_long_lift_batches_report_progress_and_keep_their_verdicts(monkeypatch):
    world = World.single("cube")
    rng = np.random.default_rng(0)
    rel = np.column_stack([rng.uniform(-0.03, 0.03, 70), rng.uniform(-0.03, 0.03, 70), rng.uniform(-np.pi, np.pi, 70)])
    whole = lift_outcomes(world, rel, np.pi / 2)
    lines = []
    monkeypatch.setattr(training, "PROGRESS_EVERY", 0.0)
    chunked = lift_outcomes(world, rel, np.pi / 2, say=lines.append)
    np.testing.assert_array_equal(chunked, whole)
    assert 0 < whole.sum() < len(whole)   # both verdicts occur
    touching = len(lines) and int(lines[-1].split("/")[1].split()[0])
    assert touching > training.lift_chunk() and all("lift tests:" in x and " done, " in x for x in lines)
    done = {int(x.split("lift tests: ")[1].split("/")[0]) for x in lines}
    ends = set(range(training.lift_chunk(), touching, training.lift_chunk()))
    assert ends <= done <= ends | {0}   # every batch but the last reported (and, while one runs, heartbeats)


def test_bad_settings():
    with pytest.raises(ValueError, match="n_samples"):
        ModelSettings(n_samples=2)
    with pytest.raises(ValueError, match="xy_range"):
        ModelSettings(xy_range=-1.0)
    with pytest.raises(ValueError, match="success"):
        ModelSettings(success="quality")


def test_spread_chosen_by_the_pilot_is_recorded_and_fixed_spreads_are_kept(tmp_path):
    auto = build_models("cube", settings=SMALL, cache_dir=tmp_path)
    assert auto.spread in AUTO_SPREADS
    pilot = auto.info["spread_pilot"]
    assert len(pilot) == len(AUTO_SPREADS)
    # the chosen spread has the best stable x lifted score of the pilot
    score = {int(d): f * (l / t if t else 0.0) for d, (f, l, t) in pilot.items()}  # JSON keys are str
    assert score[round(np.degrees(auto.spread))] == max(score.values())
    fixed = build_models("cube", settings=ModelSettings(**{**SMALL.__dict__, "spread": 0.5}), cache_dir=tmp_path)
    assert fixed.spread == 0.5 and fixed.info["spread_pilot"] is None
    with pytest.raises(ValueError, match="spread"):
        ModelSettings(spread=4.0)


def test_epsilon_criterion_models_learn_epsilon(tmp_path):
    eps_settings = ModelSettings(**{**SMALL.__dict__, "success": "epsilon", "spread": 0.5})
    m = build_models("cube", settings=eps_settings, cache_dir=tmp_path)
    assert m.settings.stability_threshold == eps_settings.eps_stable
    held = ModelSettings(n_samples=150, xy_range=0.03, seed=98)
    rel, q, eps = simulate_training_data(World.single("cube"), held, spread=0.5)
    stable = eps > eps_settings.eps_stable
    assert 5 <= stable.sum() <= len(stable) - 5
    p = m.stability_probability(rel)
    assert p[stable].mean() > p[~stable].mean() + 0.1


def test_the_default_grasp_box_covers_the_object_and_scales_the_samples():
    from bayesgrasp.models.settings import BOX_MIN_HALF, MAX_SAMPLE_SCALE
    from bayesgrasp.objects import load_object

    s = ModelSettings()
    cube = s.grasp_box(load_object("cube"))            # 6 cm cube: the minimum box
    np.testing.assert_allclose(cube, [[-BOX_MIN_HALF, -BOX_MIN_HALF], [BOX_MIN_HALF, BOX_MIN_HALF]])
    assert s.scaled(2000, cube) == 2000
    pitcher = load_object("pitcher")
    box = s.grasp_box(pitcher)                          # the handle reaches 12 cm along +x
    assert box[1, 0] >= pitcher.bounds[1, 0] + 0.009 and box[0, 1] <= pitcher.bounds[0, 1]
    assert 2000 < s.scaled(2000, box) <= MAX_SAMPLE_SCALE * 2000
    fixed = ModelSettings(xy_range=0.03)
    np.testing.assert_allclose(fixed.grasp_box(pitcher), [[-0.03, -0.03], [0.03, 0.03]])
    assert fixed.scaled(2000, fixed.grasp_box(pitcher)) == 2000


def test_a_long_lift_batch_still_reports(monkeypatch):
    """While one batch runs long (a grasp that keeps the simulation busy), a heartbeat keeps
    stderr alive; the verdicts are the lift callable's, in order."""
    import time as _time

    monkeypatch.setattr(training, "PROGRESS_EVERY", 0.05)
    monkeypatch.setattr(training, "lift_chunk", lambda: 2)

    def slow(rows):
        _time.sleep(0.3)
        return np.asarray(rows) % 2 == 0

    lines = []
    out = training.lift_tests_in_chunks(slow, np.arange(5), lines.append)
    assert out.tolist() == [True, False, True, False, True]
    assert any(x.startswith("  lift tests: 0/5 done") for x in lines)   # during the first batch
    assert any("2/5 done, about" in x for x in lines) and any("4/5 done, about" in x for x in lines)


def test_models_of_several_objects_says_what_is_missing_and_the_time_left(tmp_path):
    """RunContext.models_of: the objects not cached are announced before the first build, the time
    left after each build but the last; a second call finds them all cached and says nothing of
    building (models_cached reads the cache without loading a GP)."""
    from bayesgrasp.experiments import RunContext
    from bayesgrasp.models import models_cached

    tiny = ModelSettings(n_samples=120, n_inducing=20, xy_range=0.03, max_iter=10, seed=5, n_lift_samples=20,
                         n_calibration=0, n_pilot=20, spread=0.0)
    said = []
    ctx = RunContext(cache_dir=str(tmp_path), model_settings=tiny, progress=said.append)
    build_models("cube", settings=tiny, cache_dir=tmp_path)          # one of the three already cached
    assert models_cached("cube", settings=tiny, cache_dir=tmp_path)
    assert not models_cached("cylinder", settings=tiny, cache_dir=tmp_path)
    models = ctx.models_of(["cube", "cylinder", "mug"])
    assert [m.loaded_from_cache for m in models] == [True, False, False]
    plan = [m for m in said if m.startswith("models: ")]
    assert plan[0].startswith("models: 2 of 3 not cached")
    assert len(plan) == 2 and plan[1].startswith("models: 1 of 2 built in") and "min left" in plan[1]
    said.clear()
    ctx2 = RunContext(cache_dir=str(tmp_path), model_settings=tiny, progress=said.append)
    ctx2.models_of(["cube", "cylinder", "mug"])
    assert not [m for m in said if m.startswith("models: ")]


def test_cross_fitted_calibration_lift_tests_no_held_out_grasp(tmp_path, monkeypatch):
    """calibration="cross_fit" fits P(S)'s calibration on the training grasps' own lift outcomes,
    scored out of fold: no calibration grasp is simulated, the key differs from the default's (which
    stays what it was before the option), and the calibration orders outcomes as the labels do."""
    from dataclasses import replace

    import bayesgrasp.models.build as build
    from bayesgrasp.models import cache_key
    from bayesgrasp.objects import load_object

    settings = replace(SMALL, spread=0.0, calibration="cross_fit")
    calls, fitted = [], []
    real, real_fit = build.simulate_training_data, build.fit_calibration
    monkeypatch.setattr(build, "simulate_training_data", lambda *a, **k: calls.append(k) or real(*a, **k))
    monkeypatch.setattr(build, "fit_calibration", lambda z, y: fitted.append((z, y)) or real_fit(z, y))
    m = build_models("cylinder", settings=settings, cache_dir=tmp_path)
    assert [k.get("seed_offset", 0) for k in calls] == [0]      # the training set only
    # fitted once, on every lift-tested training grasp (their outcomes are the stability GP's labels)
    assert len(fitted) == 1
    z, y = fitted[0]
    assert len(z) == len(y) == SMALL.n_lift_samples and np.mean(y) == pytest.approx(m.info["success_fraction"])
    assert tuple(m.info["calibration"]) == pytest.approx(real_fit(z, y))
    a, b = m.info["calibration"]
    assert a > 0                                                 # a higher GP score, a likelier lift
    cyl = load_object("cylinder")
    keys = {cache_key(cyl, "h", s) for s in (settings, replace(settings, calibration="held_out"))}
    assert len(keys) == 2
    assert "calibration" not in replace(settings, calibration="held_out").as_stored()
    with pytest.raises(ValueError, match="cross_fit"):
        ModelSettings(success="epsilon", calibration="cross_fit")
    with pytest.raises(ValueError, match="calibration"):
        ModelSettings(calibration="bogus")
