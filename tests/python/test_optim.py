"""Python-level tests of bayesgrasp.optim: the vectorised-callable path against the C++ objective
path, bookkeeping, error propagation from callbacks, local optimisers, bad input."""
import numpy as np
import pytest

from bayesgrasp import optim


def _rastrigin(X):
    return 10 * X.shape[1] + (X ** 2 - 10 * np.cos(2 * np.pi * X)).sum(axis=1)


BOX4 = ([-5.12] * 4, [5.12] * 4)


def test_pso_python_callable_matches_cpp_builtin():
    # Same arithmetic and seed: the Python objective gives the very same run as the C++ one.
    a = optim.pso(_rastrigin, BOX4, seed=3, max_iter=100)
    b = optim.pso("rastrigin", BOX4, seed=3, max_iter=100)
    np.testing.assert_allclose(a.x, b.x, rtol=0, atol=1e-12)
    assert a.nfev == b.nfev == 40 * 101
    np.testing.assert_allclose(optim.rastrigin(a.x[None, :]), [a.fun], atol=1e-12)


def test_pso_finds_rastrigin_global_minimum_4d():
    r = optim.pso(_rastrigin, BOX4, n_particles=40, max_iter=400, seed=0)
    assert r.fun < 1e-3 and np.linalg.norm(r.x) < 1e-2


def test_callable_called_once_per_iteration_with_whole_swarm():
    shapes = []

    def f(X):
        shapes.append(X.shape)
        return (X ** 2).sum(axis=1)

    r = optim.pso(f, ([-1, -1, -1], [1, 1, 1]), n_particles=12, max_iter=9, record_history=True)
    assert shapes == [(12, 3)] * 10
    assert r.nit == 9 and r.nfev == 120 and len(r.history) == 10
    assert np.all(np.diff(r.history) <= 0)


def test_callback_exception_propagates():
    def bad(X):
        raise RuntimeError("boom")

    with pytest.raises(RuntimeError, match="boom"):
        optim.pso(bad, ([0, 0], [1, 1]))


@pytest.mark.parametrize("ret, match", [
    (lambda X: np.zeros(len(X) + 1), "shape"),
    (lambda X: np.zeros((len(X), 2)), "shape"),
])
def test_callback_wrong_shape_is_value_error(ret, match):
    with pytest.raises(ValueError, match=match):
        optim.pso(ret, ([0, 0], [1, 1]))


def test_seed_repeats_and_changes():
    a = optim.simulated_annealing("ackley", ([-5] * 3, [5] * 3), seed=1, max_iter=100)
    b = optim.simulated_annealing("ackley", ([-5] * 3, [5] * 3), seed=1, max_iter=100)
    c = optim.simulated_annealing("ackley", ([-5] * 3, [5] * 3), seed=2, max_iter=100)
    np.testing.assert_array_equal(a.x, b.x)
    assert not np.array_equal(a.x, c.x)


def test_annealing_and_firefly_solve_ackley():
    sa = optim.simulated_annealing(lambda X: optim.ackley(X), ([-32.768] * 3, [32.768] * 3), seed=0)
    assert sa.fun < 1e-3 and sa.nfev == 16 * 1001
    ff = optim.firefly("ackley", ([-32.768] * 2, [32.768] * 2), n_fireflies=25, max_iter=400, seed=0)
    assert ff.fun < 1e-3 and ff.nfev == 25 * 401


def test_levenberg_marquardt_rosenbrock_and_trust_region_posterior_mode():
    def res(X):
        return np.stack([10 * (X[:, 1] - X[:, 0] ** 2), 1 - X[:, 0]], axis=1)

    r = optim.levenberg_marquardt(res, [-1.2, 1.0])
    np.testing.assert_allclose(r.x, [1, 1], atol=1e-7)
    # Gaussian likelihood x prior in 2-D: the mode is the precision-weighted mean.
    m, s2, mu0, p2 = np.array([0.4, -0.2]), np.array([0.01, 0.02]), np.zeros(2), np.array([0.04, 0.04])
    t = optim.trust_region(lambda X: 0.5 * (((X - m) ** 2) / s2 + ((X - mu0) ** 2) / p2).sum(axis=1), [0.0, 0.0])
    np.testing.assert_allclose(t.x, (m / s2 + mu0 / p2) / (1 / s2 + 1 / p2), atol=1e-6)


def test_steepest_descent_quadratic_with_bounds():
    c = np.array([0.5, 2.0])
    r = optim.steepest_descent(lambda X: ((X - c) ** 2 * [1.0, 5.0]).sum(axis=1), [0.0, 0.0], bounds=([-1, -1], [1, 1]))
    np.testing.assert_allclose(r.x, [0.5, 1.0], atol=1e-6)  # second coordinate clipped at the bound


@pytest.mark.parametrize("call, match", [
    (lambda: optim.pso("sphere", ([0, 1], [1, 0])), "low > high"),
    (lambda: optim.pso("sphere", ([0, np.nan], [1, 1])), "NaN"),
    (lambda: optim.pso("sphere", ([0, 0], [1, 1, 1])), "bounds"),
    (lambda: optim.pso("nope", ([0], [1])), "unknown built-in"),
    (lambda: optim.pso(42, ([0], [1])), "objective"),
    (lambda: optim.pso("sphere", ([0], [1]), n_particles=0), "n_particles"),
    (lambda: optim.firefly("sphere", ([0], [1]), alpha_decay=0.0), "alpha_decay"),
    (lambda: optim.simulated_annealing("sphere", ([0], [1]), cooling=1.5), "cooling"),
    (lambda: optim.steepest_descent("sphere", [np.nan, 0.0]), "x0"),
    (lambda: optim.levenberg_marquardt("sphere", [0.0]), "residuals"),
    (lambda: optim.pso("sphere", ([0, 0], [1, 1]), init=np.zeros((3, 2))), "init"),
])
def test_bad_input(call, match):
    with pytest.raises(ValueError, match=match):
        call()


def _documented(cls, fields):
    """Every field is a property with a numpydoc 'name : type' docstring."""
    for name in fields:
        doc = getattr(cls, name).__doc__ or ""
        assert doc.startswith(f"{name} : "), (cls.__name__, name, doc)


def test_result_is_a_bound_class_with_numpy_fields():
    r = optim.pso("sphere", ([-1, -1], [1, 1]), n_particles=8, max_iter=5, record_history=True, seed=1)
    assert isinstance(r, optim.OptimizeResult)
    assert isinstance(r.x, np.ndarray) and r.x.shape == (2,) and r.x.dtype == np.float64
    assert isinstance(r.history, np.ndarray) and r.history.shape == (6,)
    assert isinstance(r.fun, float) and isinstance(r.nit, int) and isinstance(r.nfev, int)
    assert isinstance(r.converged, bool) and isinstance(r.message, str)
    assert r.nit == 5 and r.nfev == 8 * 6 and r.history[-1] == r.fun
    assert r.x is r.x  # one array per result
    r.x[0] = 5.0  # writable, as the result's own copy
    assert r.x[0] == 5.0
    with pytest.raises(AttributeError):
        r.fun = 0.0
    no_history = optim.trust_region("sphere", [0.5, 0.5])
    assert no_history.history.shape == (0,) and no_history.fun < 1e-12
    assert "OptimizeResult(" in repr(r)
    _documented(optim.OptimizeResult, ["x", "fun", "nit", "nfev", "history", "converged", "message"])


def test_options_classes_are_bound_and_documented():
    c = optim._c
    _documented(c.PSOOptions, ["n_particles", "max_iter", "inertia", "c1", "c2", "vmax_fraction", "stall_iter",
                               "ftol", "seed", "target", "record_history", "init"])
    _documented(c.AnnealingOptions, ["n_chains", "t0", "cooling", "step", "adapt_interval", "init"])
    _documented(c.FireflyOptions, ["n_fireflies", "beta0", "gamma", "alpha", "alpha_decay", "init"])
    _documented(c.TrustRegionOptions, ["radius0", "max_radius", "eta", "gtol", "xtol"])
    o = c.PSOOptions()
    assert o.n_particles == 40 and o.inertia == pytest.approx(0.7298) and o.target == -np.inf
    o.n_particles = 12
    r = c.pso("sphere", np.array([-1.0, -1.0]), np.array([1.0, 1.0]), o)
    assert r.nfev == 12 * (o.max_iter + 1)
