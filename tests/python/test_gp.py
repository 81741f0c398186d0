"""Tests of bayesgrasp.gp: agreement with scikit-learn's exact GP at fixed hyper-parameters,
FITC = exact GP when Z = X, gradients vs finite differences, save/load, seeds, bad input."""
import numpy as np
import pytest

from bayesgrasp.gp import ExactGP, SparseGP, load


def data(n=60, d=2, p=1, seed=0, noise=0.1):
    rng = np.random.default_rng(seed)
    X = rng.uniform(-2, 2, (n, d))
    Y = np.stack([np.sin((1 + k) * X).sum(1) + 0.3 * k for k in range(p)], axis=1)
    Y = Y + noise * rng.standard_normal(Y.shape)
    return X, (Y[:, 0] if p == 1 else Y)


FIXED = dict(optimize=False, normalize_x=False, normalize_y=False)


@pytest.mark.parametrize("white", [True, False])
def test_exact_matches_sklearn_with_fixed_hyperparameters(white):
    sk = pytest.importorskip("sklearn.gaussian_process")
    from sklearn.gaussian_process.kernels import RBF, ConstantKernel, WhiteKernel
    X, y = data(80, 3)
    ls, var, noise = np.array([0.7, 1.1, 1.9]), 1.7, (0.04 if white else 1e-10)
    kern = ConstantKernel(var, "fixed") * RBF(ls, "fixed")
    if white:
        kern = kern + WhiteKernel(noise, "fixed")
    ref = sk.GaussianProcessRegressor(kernel=kern, optimizer=None, alpha=0.0 if white else 1e-10).fit(X, y)
    gp = ExactGP(lengthscale=ls, variance=var, noise=noise, **FIXED).fit(X, y)
    Xs, _ = data(50, 3, seed=1)
    m_ref, s_ref = ref.predict(Xs, return_std=True)
    m, s = gp.predict(Xs, return_std=True)
    np.testing.assert_allclose(m, m_ref, atol=1e-7)
    # sklearn's std includes the WhiteKernel's noise (it is part of its kernel); ours is of f.
    np.testing.assert_allclose(s ** 2 + (noise if white else 0.0), s_ref ** 2, atol=1e-7)
    assert gp.log_marginal_likelihood() == pytest.approx(ref.log_marginal_likelihood_value_, abs=1e-6)


def test_sparse_equals_exact_when_inducing_inputs_are_training_inputs():
    X, y = data(50, 2, p=2)
    kw = dict(lengthscale=[0.8, 1.3], variance=1.2, noise=0.03, jitter=1e-10, **FIXED)
    ex = ExactGP(**kw).fit(X, y)
    sp = SparseGP(inducing=X, **kw).fit(X, y)
    Xs, Ys = data(30, 2, p=2, seed=3)
    me, se = ex.predict(Xs, return_std=True)
    ms, ss = sp.predict(Xs, return_std=True)
    np.testing.assert_allclose(ms, me, atol=1e-6)
    np.testing.assert_allclose(ss, se, atol=1e-6)
    assert sp.log_marginal_likelihood() == pytest.approx(ex.log_marginal_likelihood(), abs=1e-6)
    np.testing.assert_allclose(sp.log_predictive_density(Xs, Ys), ex.log_predictive_density(Xs, Ys), atol=1e-5)


def _se(A, B, ls, var):
    d = (A[:, None, :] - B[None, :, :]) / ls
    return var * np.exp(-0.5 * (d ** 2).sum(-1))


@pytest.mark.parametrize("ns", [1, 23, 24, 25, 97])
def test_sparse_variance_equals_dense_fitc_formula(ns):
    # var = kss - k*^T (Kmm^-1 - Sigma) k*, Sigma = (Kmm + Kmn Lambda^-1 Knm)^-1 (Snelson &
    # Ghahramani 2006), in numpy, against the fused C++ kernel at batch sizes around its group.
    X, y = data(150, 3, seed=4)
    Z, _ = data(29, 3, seed=5)
    ls, var, noise = np.array([0.9, 1.2, 1.6]), 1.4, 0.02
    sp = SparseGP(inducing=Z, lengthscale=ls, variance=var, noise=noise, **FIXED).fit(X, y)
    jit = sp.fit_info_.jitter_used
    Kmm = _se(Z, Z, ls, var) + jit * var * np.eye(29)
    Kmn = _se(Z, X, ls, var)
    Ki = np.linalg.inv(Kmm)
    lam = var - np.einsum("mi,mk,ki->i", Kmn, Ki, Kmn) + noise
    Sigma = np.linalg.inv(Kmm + (Kmn / lam) @ Kmn.T)
    Xs, _ = data(ns, 3, seed=6)
    Ksm = _se(Xs, Z, ls, var)
    mean = Ksm @ Sigma @ (Kmn / lam) @ y
    v = var - np.einsum("im,mk,ik->i", Ksm, Ki - Sigma, Ksm)
    m, s = sp.predict(Xs, return_std=True)
    assert m.shape == (ns,) and np.all(np.isfinite(s))
    np.testing.assert_allclose(m, mean, atol=1e-6)
    np.testing.assert_allclose(s ** 2, np.maximum(v, 0.0), atol=1e-7)


@pytest.mark.parametrize("cls,extra", [(ExactGP, {}), (SparseGP, dict(n_inducing=10, optimize_inducing=True))])
@pytest.mark.parametrize("kernel", ["se", "matern52"])
def test_gradient_matches_finite_differences(cls, extra, kernel):
    X, y = data(70, 3, p=2, seed=4)
    gp = cls(kernel=kernel, mean="constant", lengthscale=[0.6, 1.0, 1.5], optimize=False, **extra).fit(X, y)
    core = gp.models_[0]
    th = core.parameters()
    f, g = core.objective(th)
    assert f == pytest.approx(-gp.log_marginal_likelihood(), rel=1e-12)
    fd = np.empty_like(th)
    for i in range(th.size):
        h = 1e-5 * max(1.0, abs(th[i]))
        e = np.zeros_like(th)
        e[i] = h
        fd[i] = (core.objective(th + e)[0] - core.objective(th - e)[0]) / (2 * h)
    np.testing.assert_allclose(g, fd, rtol=1e-5, atol=1e-5)


def test_log_predictive_density_is_gaussian_density_with_noise():
    X, y = data(40, 2)
    gp = SparseGP(n_inducing=15, seed=1).fit(X, y)
    Xs, ys = data(10, 2, seed=5)
    m, s = gp.predict(Xs, return_std=True)
    noise_raw = gp.noise_ * gp.models_[0].y_scale[0] ** 2
    v = s ** 2 + noise_raw
    ref = -0.5 * np.log(2 * np.pi * v) - 0.5 * (ys - m) ** 2 / v
    np.testing.assert_allclose(gp.log_predictive_density(Xs, ys), ref, rtol=1e-10, atol=1e-10)


def test_multi_output_lpd_is_sum_over_outputs():
    X, Y = data(60, 2, p=3)
    gp = ExactGP(optimize=False, shared_hyperparameters=False).fit(X, Y)
    Xs, Ys = data(8, 2, p=3, seed=6)
    total = gp.log_predictive_density(Xs, Ys)
    parts = [ExactGP(optimize=False).fit(X, Y[:, k]).log_predictive_density(Xs, Ys[:, k]) for k in range(3)]
    np.testing.assert_allclose(total, np.sum(parts, axis=0), rtol=1e-12)
    assert gp.predict(Xs).shape == (8, 3)


def test_fit_improves_likelihood_and_score():
    X, y = data(300, 2, noise=0.1)
    fixed = SparseGP(n_inducing=30, optimize=False, noise=0.5).fit(X, y)
    gp = SparseGP(n_inducing=30, noise=0.5).fit(X, y)
    assert gp.log_marginal_likelihood() > fixed.log_marginal_likelihood() + 10
    Xs, ys = data(200, 2, seed=7, noise=0.0)
    assert gp.score(Xs, ys) > 0.95
    assert gp.fit(X, y) is gp


def test_save_load_round_trip(tmp_path):
    X, Y = data(80, 2, p=2)
    for est in (SparseGP(n_inducing=20, mean="constant", seed=3), ExactGP(kernel="matern52"),
                SparseGP(n_inducing=10, shared_hyperparameters=False)):
        est.fit(X, Y)
        path = tmp_path / "m.npz"
        est.save(path)
        back = load(path)
        assert type(back) is type(est)
        assert back.get_params().keys() == est.get_params().keys()
        Xs, Ys = data(25, 2, p=2, seed=8)
        np.testing.assert_allclose(back.predict(Xs), est.predict(Xs), atol=1e-10)
        np.testing.assert_allclose(back.predict(Xs, return_std=True)[1], est.predict(Xs, return_std=True)[1],
                                   atol=1e-10)
        assert back.log_marginal_likelihood() == pytest.approx(est.log_marginal_likelihood(), abs=1e-8)
        with np.load(path, allow_pickle=False) as f:  # plain arrays only
            assert "X" in f.files


def test_same_seed_same_result():
    X, y = data(200, 2)
    a = SparseGP(n_inducing=20, seed=5).fit(X, y)
    b = SparseGP(n_inducing=20, seed=5).fit(X, y)
    np.testing.assert_array_equal(a.inducing_inputs_, b.inducing_inputs_)
    np.testing.assert_array_equal(a.sample_y(X[:5], 3, seed=9), b.sample_y(X[:5], 3, seed=9))
    assert not np.array_equal(a.sample_y(X[:5], 3, seed=9), a.sample_y(X[:5], 3, seed=10))
    assert a.sample_y(X[:5], 4).shape == (5, 4)
    c = SparseGP(n_inducing=20, seed=6).fit(X, y)
    assert not np.array_equal(a.inducing_inputs_, c.inducing_inputs_)


def test_sample_moments_match_prediction():
    X, y = data(40, 1)
    gp = ExactGP(optimize=False).fit(X, y)
    Xs = np.array([[-1.0], [0.5], [4.0]])
    m, s = gp.predict(Xs, return_std=True)
    for joint in (True, False):
        S = gp.sample_y(Xs, 20000, seed=2, joint=joint)
        np.testing.assert_allclose(S.mean(1), m, atol=5 * s.max() / np.sqrt(20000))
        np.testing.assert_allclose(S.std(1), s, rtol=0.05)


def test_robustness_duplicates_zero_noise_extreme_scales():
    X, y = data(30, 2)
    Xd, yd = np.vstack([X, X]), np.concatenate([y, y])
    gp = ExactGP(noise=0.0, **FIXED).fit(Xd, yd)
    assert np.all(np.isfinite(gp.predict(X)))
    np.testing.assert_allclose(gp.predict(X), y, atol=1e-3)
    sp = SparseGP(noise=0.0, n_inducing=50, **FIXED).fit(Xd, yd)
    assert np.all(np.isfinite(sp.log_predictive_density(X, y)))
    base = SparseGP(n_inducing=15).fit(X, y).predict(X)
    tiny = SparseGP(n_inducing=15).fit(X * 1e-6, y * 1e-8).predict(X * 1e-6) * 1e8
    huge = SparseGP(n_inducing=15).fit(X * 1e6 + 1e9, y * 1e8).predict(X * 1e6 + 1e9) * 1e-8
    np.testing.assert_allclose(tiny, base, atol=1e-5)
    np.testing.assert_allclose(huge, base, atol=1e-4)


@pytest.mark.parametrize("make,match", [
    (lambda X, y: ExactGP(lengthscale=0.0).fit(X, y), "lengthscale"),
    (lambda X, y: ExactGP(lengthscale=[1.0, -2.0]).fit(X, y), "lengthscale"),
    (lambda X, y: ExactGP(lengthscale=[1.0, 1.0, 1.0]).fit(X, y), "lengthscale"),
    (lambda X, y: ExactGP(noise=-1.0).fit(X, y), "noise"),
    (lambda X, y: ExactGP(variance=0.0).fit(X, y), "variance"),
    (lambda X, y: ExactGP(kernel="linear").fit(X, y), "kernel"),
    (lambda X, y: ExactGP(mean="quadratic").fit(X, y), "mean"),
    (lambda X, y: SparseGP(n_inducing=0).fit(X, y), "n_inducing"),
    (lambda X, y: ExactGP().fit(X, y[:-1]), "y"),
    (lambda X, y: ExactGP().fit(np.where(X > 1.5, np.nan, X), y), "X"),
    (lambda X, y: ExactGP().fit(X, np.where(y > 0.5, np.inf, y)), "y"),
    (lambda X, y: ExactGP().fit(X[:, 0], y), "X"),
    (lambda X, y: ExactGP().predict(X), "not fitted"),
    (lambda X, y: ExactGP().fit(X, y).predict(X[:, :1]), "X"),
    (lambda X, y: ExactGP().fit(X, y).log_predictive_density(X, y[:-1]), "Y"),
    (lambda X, y: ExactGP().fit(X, y).sample_y(X, 0), "n_samples"),
    (lambda X, y: ExactGP().set_params(nonsense=1), "nonsense"),
])
def test_bad_input_raises_value_error_naming_argument(make, match):
    X, y = data(20, 2)
    with pytest.raises(ValueError, match=match):
        make(X, y)


def test_get_set_params():
    gp = SparseGP(n_inducing=7)
    assert gp.get_params()["n_inducing"] == 7
    assert gp.set_params(n_inducing=9, kernel="matern52") is gp
    assert gp.n_inducing == 9 and gp.kernel == "matern52"


def test_fit_info_is_a_bound_class():
    X, y = data(60, 2)
    gp = SparseGP(n_inducing=15, max_iter=30).fit(X, y)
    info = gp.fit_info_
    assert isinstance(info.iterations, int) and 0 < info.iterations <= 30
    assert isinstance(info.evaluations, int) and info.evaluations >= info.iterations
    assert info.log_marginal_likelihood == pytest.approx(gp.log_marginal_likelihood(), rel=1e-12)
    assert info.jitter_used >= 0.0
    assert info.message == "converged" or info.message.startswith("stopped: ")
    with pytest.raises(AttributeError):
        info.iterations = 0
    fixed = ExactGP(optimize=False).fit(X, y).fit_info_
    assert fixed.iterations == 0 and fixed.evaluations == 0 and fixed.message == ""
    per_model = ExactGP(max_iter=5, shared_hyperparameters=False).fit(X, np.c_[y, -y]).fit_info_
    assert len(per_model) == 2 and all(f.iterations <= 5 for f in per_model)
    from bayesgrasp import _core
    for name in ["iterations", "evaluations", "log_marginal_likelihood", "jitter_used", "message"]:
        assert getattr(_core.gp.FitInfo, name).__doc__.startswith(f"{name} : ")


def test_threads_zero_means_all_cores_with_the_same_predictions():
    import os
    X, y = data(150, 3)
    Xs, _ = data(4096, 3, seed=9)  # large enough for the threaded path (>= 2048 inputs)
    for cls in (ExactGP, SparseGP):
        all_cores = cls(threads=0, max_iter=10).fit(X, y)
        one = cls(threads=1, max_iter=10).fit(X, y)
        assert all_cores.models_[0].threads == len(os.sched_getaffinity(0))
        assert one.models_[0].threads == 1
        m0, s0 = all_cores.predict(Xs, return_std=True)
        m1, s1 = one.predict(Xs, return_std=True)
        np.testing.assert_array_equal(m0, m1)
        np.testing.assert_array_equal(s0, s1)
        assert all_cores.models_[0].options.threads == 0
    with pytest.raises(ValueError, match="threads"):
        ExactGP(threads=-1).fit(X, y)
