"""The defects a probe of bad input found (issue 18), one test each: every one failed before its fix.

Crashes run in a child process, so that a regression fails the test instead of ending pytest.
"""
import os
import signal
import subprocess
import sys
import textwrap
import time
from dataclasses import replace

import numpy as np
import pytest

from bayesgrasp import _core, belief, optim, quality, vision
from bayesgrasp.gp import ExactGP, SparseGP
from bayesgrasp.planners import Reading
from testkit import TINY, tiny_planner

X = np.random.default_rng(0).uniform(size=(20, 2))
Y = np.sin(3 * X[:, 0]) + 0.5 * X[:, 1]


def run_child(code: str, timeout: float = 120.0) -> subprocess.CompletedProcess:
    """``code`` in a fresh interpreter; a crash shows as a negative return code."""
    return subprocess.run([sys.executable, "-c", textwrap.dedent(code)], capture_output=True, text=True,
                          timeout=timeout)


# ---- 1. segfaults ---------------------------------------------------------------------------
@pytest.mark.parametrize("cls", ["ExactGP", "SparseGP"])
def test_joint_sampling_on_zero_rows_gives_an_empty_draw(cls):
    r = run_child(f"""
        import numpy as np
        from bayesgrasp import _core
        X = np.random.default_rng(0).uniform(size=(20, 2)); y = np.sin(X[:, 0])
        g = _core.gp.{cls}(); g.fit(X, y)
        print(g.sample(np.zeros((0, 2)), 3, 0, True, True).shape)
    """)
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip() == "(3, 0, 1)"


def test_huge_thread_counts_are_capped_not_fatal():
    r = run_child("""
        import numpy as np
        from bayesgrasp.gp import ExactGP
        from bayesgrasp.world import World
        b = World.single("cube").grasp_batch([[0.0, 0.0, 0.0]], threads=100000)
        X = np.random.default_rng(0).uniform(size=(20, 2)); y = np.sin(X[:, 0])
        p = ExactGP(threads=100000).fit(X, y).predict(np.zeros((5000, 2)))
        print(len(b.epsilon), p.shape)
    """)
    assert r.returncode == 0, r.stderr
    assert r.stdout.split() == ["1", "(5000,)"]


def _grid(channels=2):
    values = np.zeros((3 * 3 * 4, channels))
    return _core.belief.RelativePoseGrid([-0.1, -0.1], [0.1, 0.1], 3, 3, 4, values, np.full(channels, np.nan))


@pytest.mark.parametrize("c0", [2**31 - 1, 2**31 - 2])
def test_channel_ranges_are_checked_in_64_bits(c0):
    g, A, P = _grid(), np.zeros((1, 3)), np.zeros((2, 3))
    with pytest.raises(ValueError, match="out of range"):
        g.interpolate_pairs(A, P, c0, 2, 1)
    with pytest.raises(ValueError, match="out of range"):
        g.expected_posterior_entropy(A, P, np.zeros(2), c0, 0, 1, 10, 0, 1)


# ---- 2. silent wrong results ----------------------------------------------------------------
@pytest.mark.parametrize("phase", [dict(squeeze_time=5e6), dict(hold_time=4.5e6), dict(lift_time=1e7),
                                   dict(time_step=1e-9)])
def test_a_lift_test_longer_than_the_step_bound_is_refused(phase):
    from bayesgrasp.physics import LiftTester

    with pytest.raises(ValueError, match="steps"):
        LiftTester(None, *_box(), **phase)


def _box():
    from bayesgrasp.objects import load_object

    o = load_object("cube")
    return o.vertices, o.faces


@pytest.mark.parametrize("cls", [ExactGP, SparseGP])
def test_inputs_beyond_1e100_are_refused_not_predicted_as_nan(cls):
    with pytest.raises(ValueError, match="X: values beyond 1e100"):
        cls().fit(X * 1e155, Y)
    m = cls().fit(X, Y)
    with pytest.raises(ValueError, match="X: values beyond 1e100"):
        m.predict(np.full((1, 2), 1e155))


@pytest.mark.parametrize("case", ["one point", "constant y"])
def test_a_sparse_gp_on_degenerate_data_keeps_a_sane_variance(case):
    Xd, yd = (X[:1], Y[:1]) if case == "one point" else (X, np.full(len(X), 0.7))
    m = SparseGP(n_inducing=5).fit(Xd, yd)
    _, std = m.predict(np.array([[50.0, 50.0]]), return_std=True)   # far from the data: the prior's std
    assert m.variance_ > 1e-12
    assert std[0] > 1e-6


def test_an_initial_noise_of_zero_reaches_the_same_optimum():
    rng = np.random.default_rng(1)
    Xn = rng.uniform(size=(40, 1))
    yn = np.sin(6 * Xn[:, 0]) + 0.1 * rng.normal(size=40)
    from_default = ExactGP().fit(Xn, yn).log_marginal_likelihood()
    from_zero = ExactGP(noise=0.0).fit(Xn, yn).log_marginal_likelihood()
    assert from_zero == pytest.approx(from_default, abs=0.05)


def test_counts_beyond_int32_are_not_truncated():
    P = np.array([[0.01, 0, 0], [-0.01, 0, 0], [0, 0.01, 0]])
    with pytest.raises(ValueError, match="counts"):
        quality.epsilon_volume_batch(P, -P, np.zeros(3), 0.01, counts=np.array([2**32 + 3], np.int64))
    with pytest.raises(ValueError, match="counts"):
        _core.quality.epsilon_volume_batch(P, -P, np.array([2**32 + 3], np.int64), np.zeros(3), 0.01)


@pytest.mark.parametrize("cls", [_core.gp.ExactGP, _core.gp.SparseGP])
def test_an_unfitted_core_gp_has_no_log_marginal_likelihood(cls):
    with pytest.raises(ValueError, match="not fitted"):
        cls().log_marginal_likelihood()


@pytest.fixture(scope="module")
def planner():
    return tiny_planner()


def test_a_measurement_far_outside_any_joint_range_warns(planner):
    from bayesgrasp.planners.base import MeasurementWarning

    m = np.full(planner.models.n_joints, 1e6)
    with pytest.warns(MeasurementWarning, match="degrees instead of radians"):
        planner.observe([0.0, 0.0, 0.0], Reading(m, held=False))


@pytest.mark.parametrize("held", ["no", "yes", 2, 0.5])
def test_an_outcome_that_is_not_a_bool_is_refused(held):
    with pytest.raises(TypeError, match="held: expected a bool"):
        Reading([0.5, 0.5], held=held)


def test_numpy_bools_0_1_and_unknown_are_outcomes(planner):
    m = np.full(planner.models.n_joints, 0.5)
    planner.observe([0.0, 0.0, 0.0], Reading(m, held=np.bool_(False)))
    planner.observe([0.0, 0.0, 0.0], Reading(m, held=1))
    planner.observe([0.0, 0.0, 0.0], m)    # joint angles alone: whether it held is not known
    assert [o.stable for o in planner.observations[-3:]] == [False, True, None]
    # an unknown outcome adds no P(S) factor: the likelihood is the joint angles' alone
    P = planner.belief.particles[:5]
    unknown = planner.observations[-1]
    ll = planner.log_likelihood(P, unknown)
    for held in (False, True):      # neither outcome: None is not read as held or as dropped
        assert not np.allclose(ll, planner.log_likelihood(P, replace(unknown, stable=held)))
    planner.settings = replace(planner.settings, use_outcome=False)     # the joint angles' likelihood alone
    np.testing.assert_allclose(ll, planner.log_likelihood(P, replace(unknown, stable=True)))


def test_rotation_error_refuses_a_matrix_that_is_no_rotation():
    with pytest.raises(ValueError, match="Ra: is not a rotation"):
        vision.rotation_error(2 * np.eye(3), np.eye(3))
    with pytest.raises(ValueError, match="Rb: is not a rotation"):
        vision.rotation_error(np.eye(3), np.diag([1.0, 1.0, -1.0]))   # a reflection
    assert vision.rotation_error(np.eye(3), np.eye(3)) == pytest.approx(0.0)


# ---- 4. degenerate meshes -------------------------------------------------------------------
@pytest.mark.parametrize("obj", [
    "v 0 0 0\nv 0.05 0 0\nv 0 0.05 0\nf 1 2 3\n",                                   # one triangle
    "v 0 0 0\nv 0.05 0 0\nv 0.05 0.05 0\nv 0 0.05 0\nf 1 2 3\nf 1 3 4\n",          # a flat square
])
def test_a_mesh_without_volume_is_a_clear_error(tmp_path, obj):
    from bayesgrasp.objects import load_object

    f = tmp_path / "flat.obj"
    f.write_text(obj)
    with pytest.raises(ValueError, match="degenerate|flat"):
        load_object(str(f))
    r = subprocess.run([sys.executable, "-m", "bayesgrasp.cli", "grasp", "--object", str(f), "--top", "0,0,0"],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 2, r.stderr
    assert "Traceback" not in r.stderr and ("flat" in r.stderr or "degenerate" in r.stderr)


# ---- 5. orphans and unbounded work ----------------------------------------------------------
def test_workers_end_when_their_parent_is_killed(tmp_path):
    (tmp_path / "slow_runs.py").write_text("import time\n\ndef run(experiment, obj, i, seed):\n"
                                           "    time.sleep(600)\n    return {}\n")
    parent = subprocess.Popen([sys.executable, "-c", textwrap.dedent(f"""
        import sys; sys.path.insert(0, {str(tmp_path)!r})
        import slow_runs
        from bayesgrasp.experiments.runner import ResultStore, run_experiment
        run_experiment("slow", ["a"], 4, slow_runs.run, ResultStore({str(tmp_path / 'r.sqlite')!r}), workers=2,
                       progress=False)
    """)])
    children = []
    for _ in range(600):   # until both workers are up (each imports the package)
        children = _children(parent.pid)
        if len(children) >= 3:     # two workers and the resource tracker
            break
        time.sleep(0.1)
    assert len(children) >= 2, children
    os.kill(parent.pid, signal.SIGKILL)
    parent.wait()
    for _ in range(300):
        alive = [p for p in children if _alive(p)]
        if not alive:
            break
        time.sleep(0.1)
    for p in alive:
        os.kill(p, signal.SIGKILL)
    assert not alive, f"processes {alive} outlived their parent"


def _children(pid: int) -> list:
    # from /proc, not `ps`: under `make sanitize` the ASan runtime is preloaded into every
    # subprocess, and `ps` hangs with it
    kids = []
    for d in filter(str.isdigit, os.listdir("/proc")):
        try:
            with open(f"/proc/{d}/stat") as f:
                fields = f.read().rsplit(")", 1)[1].split()
        except (FileNotFoundError, ProcessLookupError, IndexError):
            continue
        if int(fields[1]) == pid:
            kids.append(int(d))
    return kids


def _alive(pid: int) -> bool:
    try:
        with open(f"/proc/{pid}/stat") as f:
            return f.read().split()[2] != "Z"
    except FileNotFoundError:
        return False


def test_sizes_beyond_their_limits_are_refused():
    from bayesgrasp.objects import load_object

    with pytest.raises(ValueError, match="model_samples: at most"):
        vision.model_samples(load_object("mug"), samples=10**9)
    P = np.array([[0.01, 0, 0], [-0.01, 0, 0], [0, 0.01, 0]])
    with pytest.raises(ValueError, match="n_edges: must be in"):
        quality.epsilon_volume(P, -P, np.zeros(3), 0.01, n_edges=10**6)


# ---- 6. messages ----------------------------------------------------------------------------
def _cli(*args, timeout=60):
    return subprocess.run([sys.executable, "-m", "bayesgrasp.cli", *args], capture_output=True, text=True,
                          timeout=timeout)


@pytest.mark.parametrize("flag, value", [("--seed", "-1"), ("--seed", str(2**70)), ("--attempts", "0")])
def test_bad_integers_name_their_flag(flag, value):
    r = _cli("plan", "--object", "cube", "--true-pose", "0,0,0", flag, value)
    assert r.returncode == 2
    assert f"argument {flag}: expected an integer" in r.stderr


def test_an_unwritable_cache_fails_before_any_model_is_built(monkeypatch, capsys):
    import bayesgrasp.models.build as build
    from bayesgrasp.cli import main

    builds = []
    monkeypatch.setattr(build, "build_models", lambda *a, **k: builds.append(a) or pytest.fail("models were built"))
    assert main(["plan", "--object", "cube", "--true-pose", "0,0,0", "--cache", "/proc/nope"]) == 2
    assert "--cache: cannot write to /proc/nope" in capsys.readouterr().err
    assert builds == []   # the builder itself was never called


def test_negative_and_nan_settings_are_refused():
    b = belief.ParticleBelief.uniform([0, 0], [1, 1], 10)
    with pytest.raises(ValueError, match="n: must be >= 0"):
        b.resample(n=-1)
    f = lambda Xs: (Xs**2).sum(1)  # noqa: E731
    with pytest.raises(ValueError, match="stall_iter"):
        optim.pso(f, [[-1, 1], [-1, 1]], stall_iter=-1)
    with pytest.raises(ValueError, match="t0"):
        optim.simulated_annealing(f, [[-1, 1], [-1, 1]], t0=float("nan"))
    from bayesgrasp.planners.base import PlannerSettings

    with pytest.raises(ValueError, match="outcome_floor"):
        PlannerSettings(outcome_floor=-1)


# ---- 7. the same digits from a cold and a warm cache ----------------------------------------
def test_a_fresh_build_hands_back_its_models_as_reloaded_from_their_files(tmp_path, monkeypatch):
    # Runs always use models read back from their files (build._as_reloaded), so a cold cache and
    # a warm one give the same digits. Proven on the objects: the fitted models are not the ones
    # returned, and what is returned predicts bit for bit as the files do.
    import bayesgrasp.models.build as build

    fitted = []
    train = build._train
    monkeypatch.setattr(build, "_train", lambda *a, **k: fitted.append(train(*a, **k)) or fitted[-1])
    cold = build.build_models("cube", settings=TINY, cache_dir=tmp_path)
    assert len(fitted) == 1 and cold is not fitted[0] and cold.stability is not fitted[0].stability
    warm = build.build_models("cube", settings=TINY, cache_dir=tmp_path)
    assert len(fitted) == 1 and not cold.loaded_from_cache and warm.loaded_from_cache   # not trained again
    nocache = build.build_models("cube", settings=TINY, cache_dir=None)   # read back through a temporary dir
    assert len(fitted) == 2 and nocache is not fitted[1]
    Xq = np.random.default_rng(3).uniform(-1, 1, size=(50, 4))
    for a, b in [(cold, warm), (nocache, warm)]:
        np.testing.assert_array_equal(a.stability.predict(Xq), b.stability.predict(Xq))
        np.testing.assert_array_equal(a.measurement.predict(Xq), b.measurement.predict(Xq))
    # the fitted models are the same models to within rounding: the comparison above is not vacuous
    np.testing.assert_allclose(fitted[0].stability.predict(Xq), warm.stability.predict(Xq), rtol=0, atol=1e-8)


@pytest.mark.parametrize("call", [
    lambda: ExactGP(threads=2**70).fit(X, Y),
    lambda: SparseGP(seed=2**70).fit(X, Y),
    lambda: belief.ParticleBelief.uniform([0, 0], [1, 1], 2**40),
    lambda: belief.ParticleBelief.uniform([0, 0], [1, 1], 10, seed=-1),
    lambda: quality.epsilon_volume(np.eye(3) * 0.01, -np.eye(3), np.zeros(3), 0.01, n_edges=2**40),
    lambda: optim.pso(lambda Xs: (Xs**2).sum(1), [[-1, 1]], n_particles=2**40),
    lambda: __import__("bayesgrasp.physics").physics.make_options(solver_iterations=2**40),
])
def test_oversized_integers_are_a_value_error_naming_the_argument(call):
    with pytest.raises(ValueError, match=r"(threads|seed|n|n_edges|n_particles|solver_iterations): must be in \["):
        call()
