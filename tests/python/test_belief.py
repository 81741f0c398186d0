"""Python-level tests of bayesgrasp.belief: callables called once per batch, the all-zero
likelihood warning, KDE entropy against scipy's gaussian_kde, expected posterior entropy, the GP
measurement model paths, the relative pose, bad input."""

import numpy as np
import pytest
from scipy.stats import gaussian_kde

from bayesgrasp import belief
from bayesgrasp.belief import AllZeroLikelihoodWarning, ParticleBelief

LOW, HIGH, WRAPS = belief.planar_pose_bounds((-0.1, 0.1), (-0.1, 0.1))


def test_uniform_weights_entropy_and_ess():
    b = ParticleBelief.uniform(LOW, HIGH, 500, WRAPS, seed=0)
    assert b.weight_entropy() == pytest.approx(np.log(500))
    assert b.ess() == pytest.approx(500)
    P = b.particles
    assert P.shape == (500, 3) and np.all(P >= LOW) and np.all(P[:, :2] <= HIGH[:2]) and np.all(P[:, 2] < np.pi)


def test_update_calls_once_and_matches_bayes():
    b = ParticleBelief(np.array([[0.0, 0, 0], [0.05, 0, 0], [0.1, 0, 0]]), LOW, HIGH, WRAPS)
    calls = []

    def ll(P):
        calls.append(P.shape)
        return -0.5 * ((P[:, 0] - 0.05) / 0.05) ** 2

    assert b.update(ll) is False
    assert calls == [(3, 3)]
    e = np.exp(-0.5)
    np.testing.assert_allclose(b.weights, np.array([e, 1, e]) / (1 + 2 * e))
    assert b.ess() == pytest.approx(1 / np.sum((np.array([e, 1, e]) / (1 + 2 * e)) ** 2))


def test_all_zero_likelihood_warns_and_resets():
    b = ParticleBelief.uniform(LOW, HIGH, 20, WRAPS, seed=1)
    b.reweight(np.linspace(-2, 2, 20))
    with pytest.warns(AllZeroLikelihoodWarning):
        assert b.reweight(np.full(20, -np.inf)) is True
    np.testing.assert_allclose(b.weights, np.full(20, 1 / 20))
    with pytest.warns(AllZeroLikelihoodWarning):
        b.update(lambda P: np.full(len(P), -np.inf))
    assert np.all(np.isfinite(b.log_weights))


def test_metropolis_calls_once_per_sweep_and_is_seeded():
    def run(seed):
        b = ParticleBelief.uniform(LOW, HIGH, 300, WRAPS, seed=seed)
        calls = []

        def target(P):
            calls.append(len(P))
            return -0.5 * ((P[:, 0] - 0.02) / 0.01) ** 2

        st = b.metropolis(target, [0.01, 0.01, 0.1], n_steps=5)
        assert calls == [300] * 6 and st.evaluations == 1800
        b.resample("stratified")
        b.roughen(0.2)
        return b.particles

    np.testing.assert_array_equal(run(4), run(4))
    assert not np.array_equal(run(4), run(5))


def test_kde_entropy_matches_scipy_gaussian_kde():
    # Independent implementation: scipy's weighted gaussian_kde, entropy by resubstitution.
    rng = np.random.default_rng(0)
    X = rng.normal(size=(300, 2)) * [0.02, 0.05]
    w = rng.uniform(0.2, 1.0, size=300)
    w /= w.sum()
    for bw in ("scott", "silverman"):
        kde = gaussian_kde(X.T, bw_method=bw, weights=w)
        expect = -np.sum(w * np.log(kde(X.T)))
        got = belief.kde_entropy(X, np.log(w), [-1, -1], [1, 1], bandwidth=bw)
        assert got == pytest.approx(expect, rel=1e-9)


def test_expected_posterior_entropy_uninformative_vs_informative():
    n = 100
    lw = np.zeros(n)
    const = np.full((n, 2), 0.3)
    h, se = belief.expected_posterior_entropy(lw, const, np.full((n, 2), 0.01), n_samples=50, seed=0)
    assert h == pytest.approx(np.log(n)) and se == pytest.approx(0, abs=1e-12)
    informative = np.arange(n, dtype=float)[:, None] / n
    H, SE = belief.expected_posterior_entropy(lw, np.stack([np.repeat(0.3, n)[:, None], informative]),
                                              np.full((2, n, 1), 1e-4), n_samples=100, seed=0)
    assert H.shape == (2,) and SE.shape == (2,)
    assert H[0] == pytest.approx(np.log(n))
    assert H[1] < np.log(n) - 2.0  # sigma = 0.01 = the spacing: a few particles remain plausible


def test_relative_planar_pose_by_hand():
    R = belief.relative_planar_pose([[1.0, 0.0, np.pi / 2]], [[0.0, 0.0, np.pi / 2], [1.0, 1.0, 0.0]])
    np.testing.assert_allclose(R, [[0, -1, 0], [0, -1, np.pi / 2]], atol=1e-12)


def _identity_gp():
    from bayesgrasp.gp import ExactGP
    rng = np.random.default_rng(0)
    X = np.column_stack([rng.uniform(-0.3, 0.3, 200), rng.uniform(-0.3, 0.3, 200), rng.uniform(-1, 1, 200)])
    return ExactGP(lengthscale=[0.5, 0.5, 1.0], noise=1e-4, optimize=False).fit(X, X.copy())


def test_gp_update_paths_agree_and_entropy_gp_matches_manual():
    gp = _identity_gp()
    a = ParticleBelief.gaussian(LOW, HIGH, [0, 0, 0.2], [0.05, 0.05, 0.15], 300, WRAPS, seed=2)
    b = ParticleBelief(a.particles, LOW, HIGH, WRAPS)
    action, meas = np.array([0.0, 0.0, 0.5]), np.array([-0.03, 0.04, 0.25])
    a.update_gp(gp, action, meas)                                  # one C++ call
    b.update(belief.gp_log_likelihood(gp, action, meas))           # Python callable path
    np.testing.assert_allclose(a.log_weights, b.log_weights, atol=1e-8)
    actions = np.array([[0.0, 0.0, 0.0], [0.05, 0.02, 0.4]])
    h, se = belief.expected_posterior_entropy_gp(gp, a, actions, n_samples=30, seed=1)
    X = belief.relative_planar_pose(actions, a.particles)
    mv = [gp.models_[0].predict(X, True)]
    mean, var = mv[0][0].reshape(2, len(a), 3), mv[0][1].reshape(2, len(a), 3)
    h2, _ = belief.expected_posterior_entropy(a.log_weights, mean, var, n_samples=30, seed=1)
    np.testing.assert_allclose(h, h2, atol=1e-9)


@pytest.mark.parametrize("call, match", [
    (lambda: ParticleBelief(np.zeros((0, 3)), LOW, HIGH, WRAPS), "zero particles"),
    (lambda: ParticleBelief(np.zeros((2, 3)), HIGH, LOW, WRAPS), "low > high"),
    (lambda: ParticleBelief(np.full((2, 3), np.nan), LOW, HIGH, WRAPS), "NaN"),
    (lambda: ParticleBelief(np.full((2, 3), 0.5), LOW, HIGH, WRAPS), "outside"),
    (lambda: ParticleBelief(np.zeros((2, 3)), LOW, HIGH, WRAPS, log_weights=[-np.inf, -np.inf]), "all weights are zero"),
    (lambda: ParticleBelief(np.zeros((2, 3)), LOW, HIGH, [True]), "wraps"),
    (lambda: ParticleBelief(np.zeros((2, 3)), LOW, HIGH, WRAPS).reweight([0.0, np.nan]), "NaN"),
    (lambda: ParticleBelief(np.zeros((2, 3)), LOW, HIGH, WRAPS).update(lambda P: np.zeros(3)), "shape"),
    (lambda: ParticleBelief(np.zeros((2, 3)), LOW, HIGH, WRAPS).update(lambda P: np.full(2, np.nan)), "NaN"),
    (lambda: ParticleBelief(np.zeros((2, 3)), LOW, HIGH, WRAPS).resample("residual"), "scheme"),
    (lambda: ParticleBelief.uniform(LOW, HIGH, 0, WRAPS), "zero particles"),
    (lambda: belief.weight_entropy(np.array([])), "zero particles"),
    (lambda: belief.expected_posterior_entropy([0.0, 0.0], np.zeros((2, 1)), np.zeros((2, 1))), "var"),
    (lambda: belief.expected_posterior_entropy([0.0, 0.0], np.zeros((3, 1)), np.ones((3, 1))), "mean"),
    (lambda: belief.resample_indices([0.0, 0.0], 3), "zero"),
])
def test_bad_input(call, match):
    with pytest.raises(ValueError, match=match):
        call()


def test_metropolis_returns_a_bound_stats_class():
    b = ParticleBelief(np.zeros((50, 3)), LOW, HIGH, WRAPS, seed=2)  # 0.1 from every bound
    st = b.metropolis(lambda P: np.zeros(len(P)), [0.001, 0.001, 0.01], n_steps=3)
    assert isinstance(st, belief._c.MetropolisStats)
    assert st.evaluations == 50 * 4 and isinstance(st.evaluations, int)
    assert st.acceptance_rate == 1.0  # a flat target accepts every move that stays in the box
    for name in ("acceptance_rate", "evaluations"):
        assert getattr(belief._c.MetropolisStats, name).__doc__.startswith(f"{name} : ")


def test_absolute_planar_pose_by_hand_with_yaw_wrapping():
    # (0.1, 0, 3.0, extra 5) in an object at (1, 2, pi/2): R(pi/2)(0.1, 0) = (0, 0.1); 3 + pi/2 wraps.
    W = belief.absolute_planar_pose([[0.1, 0.0, 3.0, 5.0]], [[1.0, 2.0, np.pi / 2], [-1.0, 0.0, -np.pi]])
    np.testing.assert_allclose(W, [[1.0, 2.1, 3.0 + np.pi / 2 - 2 * np.pi, 5.0], [-1.1, 0.0, 3.0 - np.pi, 5.0]],
                               atol=1e-12)
    P = belief.absolute_planar_pose_paired([[0.1, 0.0, 3.0], [0.0, 0.2, -3.0]], [[1.0, 2.0, np.pi / 2],
                                                                                [-1.0, 0.0, -np.pi]])
    np.testing.assert_allclose(P, [[1.0, 2.1, 3.0 + np.pi / 2 - 2 * np.pi], [-1.0, -0.2, -3.0 + np.pi]], atol=1e-12)
    with pytest.raises(ValueError, match="poses"):
        belief.absolute_planar_pose_paired(np.zeros((2, 3)), np.zeros((3, 3)))
    with pytest.raises(ValueError, match="relative"):
        belief.absolute_planar_pose(np.zeros((2, 2)), np.zeros((1, 3)))


def test_absolute_planar_pose_inverts_relative_planar_pose_both_ways():
    rng = np.random.default_rng(3)
    A = np.column_stack([rng.uniform(-0.5, 0.5, (9, 2)), rng.uniform(-10, 10, 9), rng.normal(size=9)])
    P = np.column_stack([rng.uniform(-0.5, 0.5, (4, 2)), rng.uniform(-10, 10, 4)])
    rel = belief.relative_planar_pose(A, P).reshape(9, 4, 4)
    for j in range(4):
        back = belief.absolute_planar_pose(rel[:, j], P[j])
        np.testing.assert_allclose(back[:, [0, 1, 3]], A[:, [0, 1, 3]], atol=1e-12)
        np.testing.assert_allclose(np.angle(np.exp(1j * (back[:, 2] - A[:, 2]))), 0.0, atol=1e-12)
        assert np.all(back[:, 2] >= -np.pi) and np.all(back[:, 2] < np.pi)
        np.testing.assert_array_equal(belief.absolute_planar_pose_paired(rel[:, j], np.tile(P[j], (9, 1))), back)
    world = belief.absolute_planar_pose(A, P).reshape(9, 4, 4)
    for j in range(4):
        again = belief.relative_planar_pose(world[:, j], P[j])
        np.testing.assert_allclose(again[:, :2], A[:, :2], atol=1e-12)
        np.testing.assert_allclose(np.angle(np.exp(1j * (again[:, 2] - A[:, 2]))), 0.0, atol=1e-12)


def test_planar_pose_bounds_by_hand():
    low, high, wraps = belief.planar_pose_bounds((-0.1, 0.2), (-0.3, 0.4))
    np.testing.assert_array_equal(low, [-0.1, -0.3, -np.pi])
    np.testing.assert_array_equal(high, [0.2, 0.4, np.pi])
    assert wraps == [False, False, True]


def test_wrapping_flags_reach_every_constructor_and_the_kde():
    # A Gaussian at yaw = pi - 0.01 with std 0.1: wrapped, about half the particles land near -pi;
    # not wrapped, the truncation keeps them all below pi.
    mean, std = [0.0, 0.0, np.pi - 0.01], [0.01, 0.01, 0.1]
    wrapped = ParticleBelief.gaussian(LOW, HIGH, mean, std, 400, WRAPS, seed=1)
    clipped = ParticleBelief.gaussian(LOW, HIGH, mean, std, 400, seed=1)
    assert list(wrapped.wraps) == WRAPS and list(clipped.wraps) == [False] * 3
    assert 0.2 < np.mean(wrapped.particles[:, 2] < 0) < 0.8 and np.all(clipped.particles[:, 2] > 2.5)
    assert list(ParticleBelief.uniform(LOW, HIGH, 5, WRAPS).wraps) == WRAPS
    assert list(ParticleBelief(np.zeros((2, 3)), LOW, HIGH, WRAPS).wraps) == WRAPS
    # the KDE of that wrapped cloud measures it across the seam: as narrow as the same cloud at 0
    P = wrapped.particles
    at_zero = P.copy()
    at_zero[:, 2] = np.mod(P[:, 2] - np.pi, 2 * np.pi) - np.pi     # rotate by pi: the seam moves away
    lw = np.full(len(P), -np.log(len(P)))
    h_seam = belief.kde_entropy(P, lw, LOW, HIGH, WRAPS)
    assert h_seam == pytest.approx(belief.kde_entropy(at_zero, lw, LOW, HIGH, WRAPS), abs=0.05)
    assert belief.kde_entropy(P, lw, LOW, HIGH) > h_seam + 1.0       # unwrapped: two far clumps


def test_entropy_of_a_one_output_measurement_takes_flat_arrays():
    rng = np.random.default_rng(4)
    lw, mean, var = np.log(np.full(50, 1 / 50)), rng.uniform(0, 1, 50), rng.uniform(0.01, 0.1, 50)
    flat = belief.expected_posterior_entropy(lw, mean, var, n_samples=40, seed=3)
    column = belief.expected_posterior_entropy(lw, mean[:, None], var[:, None], n_samples=40, seed=3)
    assert flat == column and isinstance(flat[0], float)


def test_entropy_gp_with_one_model_per_output_matches_its_predictions():
    # shared_hyperparameters=False fits one C++ model per output: the Python path of
    # expected_posterior_entropy_gp and update_gp (not the single-model C++ call) is used.
    from bayesgrasp.gp import ExactGP
    rng = np.random.default_rng(0)
    X = np.column_stack([rng.uniform(-0.3, 0.3, 150), rng.uniform(-0.3, 0.3, 150), rng.uniform(-1, 1, 150)])
    gp = ExactGP(lengthscale=[0.5, 0.5, 1.0], noise=1e-4, optimize=False, shared_hyperparameters=False).fit(X, X * [1, 2, 3])
    assert len(gp.models_) == 3 and belief._single_core_model(gp) is None
    a = ParticleBelief.gaussian(LOW, HIGH, [0, 0, 0.2], [0.05, 0.05, 0.15], 200, WRAPS, seed=2)
    actions = np.array([[0.0, 0.0, 0.0], [0.05, 0.02, 0.4], [-0.04, 0.01, -0.3]])
    h, se = belief.expected_posterior_entropy_gp(gp, a, actions, n_samples=30, seed=1)
    Xr = belief.relative_planar_pose(actions, a.particles)
    mv = [m.predict(Xr, True) for m in gp.models_]
    mean = np.column_stack([m for m, _ in mv]).reshape(3, len(a), 3)
    var = np.column_stack([v for _, v in mv]).reshape(3, len(a), 3)
    h2, se2 = belief.expected_posterior_entropy(a.log_weights, mean, var, n_samples=30, seed=1)
    np.testing.assert_array_equal(h, h2)
    np.testing.assert_array_equal(se, se2)
    assert len(set(np.round(h, 9))) == 3                     # the three actions differ
    # update_gp = a Gaussian likelihood of the measurement under each output's predictive
    action, meas = np.array([0.02, -0.01, 0.3]), np.array([-0.03, 0.04, 0.25])
    b = ParticleBelief(a.particles, LOW, HIGH, WRAPS)
    b.update_gp(gp, action, meas)
    Xa = belief.relative_planar_pose(action[None, :], a.particles)
    ll = sum(-0.5 * ((meas[k] - m) ** 2 / v + np.log(2 * np.pi * v))
             for k, (m, v) in enumerate(m.predict(Xa, True) for m in gp.models_))
    ll = np.ravel(ll)
    expect = ll - np.logaddexp.reduce(ll)
    np.testing.assert_allclose(b.log_weights, expect, atol=1e-8)


@pytest.mark.parametrize("call, name", [
    (lambda: ParticleBelief.uniform(LOW, HIGH, 2**40), "n"),
    (lambda: ParticleBelief.uniform(LOW, HIGH, 5, seed=-1), "seed"),
    (lambda: ParticleBelief.gaussian(LOW, HIGH, [0, 0, 0], [1, 1, 1], 2**40), "n"),
    (lambda: ParticleBelief.gaussian(LOW, HIGH, [0, 0, 0], [1, 1, 1], 5, seed=-1), "seed"),
    (lambda: belief.resample_indices([1.0, 1.0], 2**40), "n"),
    (lambda: belief.resample_indices([1.0, 1.0], 3, seed=-1), "seed"),
    (lambda: belief.expected_posterior_entropy([0.0], [[0.0]], [[1.0]], n_samples=2**40), "n_samples"),
    (lambda: belief.expected_posterior_entropy([0.0], [[0.0]], [[1.0]], seed=-1), "seed"),
    (lambda: belief.expected_posterior_entropy([0.0], [[0.0]], [[1.0]], n_threads=2**40), "n_threads"),
    (lambda: belief.expected_posterior_entropy_gp(_identity_gp(), ParticleBelief.uniform(LOW, HIGH, 5), [[0, 0, 0]],
                                                  n_samples=2**40), "n_samples"),
    (lambda: belief.expected_posterior_entropy_gp(_identity_gp(), ParticleBelief.uniform(LOW, HIGH, 5), [[0, 0, 0]],
                                                  seed=-1), "seed"),
    (lambda: belief.expected_posterior_entropy_gp(_identity_gp(), ParticleBelief.uniform(LOW, HIGH, 5), [[0, 0, 0]],
                                                  n_threads=2**40), "n_threads"),
])
def test_out_of_range_integers_name_their_argument(call, name):
    with pytest.raises(ValueError, match=rf"^{name}: must be"):
        call()


def test_model_particles_resample_and_jitter_keeps_the_model_weight():
    """The joint (model, pose) belief's step (C++): below half the ESS the particles are drawn
    systematically and jittered, the model's total weight kept; above it nothing moves."""
    from bayesgrasp import _core

    b = _core.belief
    P = np.array([[0.0, 0.0, 3.1], [0.1, 0.0, 0.0], [0.2, 0.0, 0.0], [0.3, 0.0, 0.0]])
    lw = np.log([0.97, 0.01, 0.01, 0.01]) - 2.0   # total weight e^-2; ESS ~ 1.06 < 2
    did, Q, lw2 = b.resample_and_jitter(P, lw, np.array([0.0, 0.0, 0.1]), 0.5, 7)
    Q, lw2 = np.asarray(Q), np.asarray(lw2)
    assert did and Q.shape == (4, 3)
    assert np.allclose(lw2, -2.0 - np.log(4)) and np.isclose(np.logaddexp.reduce(lw2), -2.0)
    assert np.all(Q[:, 0] == 0.0) and np.all((Q[:, 2] >= -np.pi) & (Q[:, 2] < np.pi))   # all from row 0, yaw wrapped
    assert np.any(np.abs(Q[:, 2]) > 3.0) and not np.allclose(Q[:, 2], 3.1)                 # jittered around 3.1
    even = np.full(4, np.log(0.25))
    did, Q, lw3 = b.resample_and_jitter(P, even, np.array([0.01, 0.01, 0.1]), 0.5, 7)
    assert not did and np.array_equal(np.asarray(Q), P) and np.array_equal(np.asarray(lw3), even)
    with pytest.raises(ValueError, match="jitter_std"):
        b.resample_and_jitter(P, lw, np.array([-1.0, 0.0, 0.0]), 0.5, 0)
    assert b.LOG_MIN_LIKELIHOOD == pytest.approx(np.log(np.finfo(float).tiny))
