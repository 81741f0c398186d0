"""Gaussian-process regression: exact and sparse (FITC), scikit-learn style.

``ExactGP`` and ``SparseGP`` wrap the C++ models in :mod:`bayesgrasp._core.gp` and are
scikit-learn estimators (``BaseEstimator``, ``RegressorMixin``, when scikit-learn is installed),
so they can be swapped for ``GaussianProcessRegressor``::

    gp = SparseGP(kernel="se", n_inducing=200, seed=0).fit(X, y)   # X (N, D), y (N,) or (N, P)
    mean, std = gp.predict(Xs, return_std=True)
    lp = gp.log_predictive_density(Xs, Ys)   # measurement likelihood, one value per row

Hyper-parameters (``lengthscale``, ``variance``, ``noise``) are initial values (the fitted ones are
in ``lengthscale_``, ``variance_``, ``noise_``); with ``normalize_x`` / ``normalize_y`` they live in
the standardised input / output space, as scikit-learn's ``normalize_y`` does. Predictions are
always in the original units. Several outputs share one set of hyper-parameters (one
factorisation) unless ``shared_hyperparameters=False``, which fits one model per output.
Models are saved as ``.npz`` (no pickle) with :meth:`save` and read back with :func:`load`.
"""
from __future__ import annotations

import inspect
import os

from bayesgrasp._args import c_int, c_seed
import numpy as np

from bayesgrasp import _core

__all__ = ["ExactGP", "SparseGP", "load"]

def _as_2d(a, name, cols=None):
    try:
        a = np.asarray(a, dtype=float)
    except (TypeError, ValueError) as e:
        raise ValueError(f"{name}: not a numeric array ({e})") from None
    if a.ndim == 1 and cols == 1:
        a = a[:, None]
    if a.ndim != 2:
        raise ValueError(f"{name}: expected a 2-D array (N, D), got shape {a.shape}")
    if a.shape[0] == 0:
        raise ValueError(f"{name}: is empty")
    if cols is not None and a.shape[1] != cols:
        raise ValueError(f"{name}: expected {cols} columns, got {a.shape[1]}")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{name}: contains NaN or infinity")
    return np.ascontiguousarray(a)


try:   # scikit-learn (installed by `make`) makes them real estimators: clone, cross_val_score, Pipeline
    from sklearn.base import BaseEstimator as _Estimator, RegressorMixin as _Regressor
except ImportError:   # pragma: no cover - the same API without scikit-learn's machinery
    _Estimator, _Regressor = object, object


class _GPBase(_Regressor, _Estimator):
    _core_cls = None

    def __init__(self, kernel="se", lengthscale=None, variance=1.0, noise=1e-2, mean="zero", optimize=True,
                 max_iter=200, normalize_x=True, normalize_y=True, jitter=1e-8, threads=1,
                 shared_hyperparameters=True, seed=0):
        self.kernel = kernel
        self.lengthscale = lengthscale
        self.variance = variance
        self.noise = noise
        self.mean = mean
        self.optimize = optimize
        self.max_iter = max_iter
        self.normalize_x = normalize_x
        self.normalize_y = normalize_y
        self.jitter = jitter
        self.threads = threads
        self.shared_hyperparameters = shared_hyperparameters
        self.seed = seed

    # ---- scikit-learn parameter protocol -------------------------------------------------------
    @classmethod
    def _param_names(cls):
        sig = inspect.signature(cls.__init__)
        return [p for p in sig.parameters if p != "self"]

    def get_params(self, deep=True):
        return {k: getattr(self, k) for k in self._param_names()}

    def set_params(self, **params):
        names = self._param_names()
        for k, v in params.items():
            if k not in names:
                raise ValueError(f"{k}: not a parameter of {type(self).__name__}")
            setattr(self, k, v)
        return self

    def __repr__(self):
        args = ", ".join(f"{k}={v!r}" for k, v in self.get_params().items())
        return f"{type(self).__name__}({args})"

    # ---- core options (the C++ model validates them when it is built) --------------------------
    def _check_params(self):
        """Checks what the C++ options cannot hold; everything else is checked by the C++ model."""
        if self.lengthscale is not None and (np.ndim(self.lengthscale) > 1 or np.size(self.lengthscale) == 0):
            raise ValueError(f"lengthscale: expected a scalar or a non-empty 1-D array, got {self.lengthscale!r}")

    def _core_kwargs(self, D):
        ls = None if self.lengthscale is None else np.atleast_1d(np.asarray(self.lengthscale, dtype=float))
        return dict(kernel=self.kernel, lengthscale=ls, variance=float(self.variance), noise=float(self.noise),
                    mean=self.mean, optimize=bool(self.optimize), max_iter=c_int(self.max_iter, "max_iter"),
                    normalize_x=bool(self.normalize_x), normalize_y=bool(self.normalize_y),
                    jitter=float(self.jitter), threads=c_int(self.threads, "threads"))

    def _check_fitted(self):
        if not hasattr(self, "models_"):
            raise ValueError(f"this {type(self).__name__} is not fitted; call fit(X, y) first")

    # ---- estimator API -------------------------------------------------------------------------
    def fit(self, X, y):
        """Fits to X (N, D) and y (N,) or (N, P). Returns self."""
        self._check_params()
        X = _as_2d(X, "X")
        y_arr = np.asarray(y, dtype=float)
        if y_arr.ndim not in (1, 2):
            raise ValueError(f"y: expected shape (N,) or (N, P), got {y_arr.shape}")
        if y_arr.shape[0] != X.shape[0]:
            raise ValueError(f"y: has {y_arr.shape[0]} rows but X has {X.shape[0]}")
        if not np.all(np.isfinite(y_arr)):
            raise ValueError("y: contains NaN or infinity")
        self._y_1d = y_arr.ndim == 1
        Y = y_arr.reshape(len(y_arr), -1)
        kw = self._core_kwargs(X.shape[1])
        if self.shared_hyperparameters or Y.shape[1] == 1:
            m = self._make_core(kw)
            m.fit(X, Y)
            self.models_ = [m]
        else:
            self.models_ = []
            for p in range(Y.shape[1]):
                m = self._make_core(kw)
                m.fit(X, Y[:, p])
                self.models_.append(m)
        self.n_features_in_ = X.shape[1]
        self.n_outputs_ = Y.shape[1]
        self.X_train_, self.y_train_ = X, y_arr
        return self

    def _make_core(self, kw):
        options = _core.gp.GPOptions()
        for name, value in kw.items():
            if value is not None:
                setattr(options, name, value)
        return self._core_cls(options)

    def _per_model(self, fn):
        parts = [fn(m) for m in self.models_]
        return np.concatenate(parts, axis=1) if len(parts) > 1 else parts[0]

    def _shape_out(self, a):
        return a[:, 0] if self._y_1d else a

    def predict(self, X, return_std=False, return_cov=False):
        """Predictive mean (N,) or (N, P); with return_std also the standard deviation of f."""
        self._check_fitted()
        X = _as_2d(X, "X", self.n_features_in_)
        if return_cov:
            if self.n_outputs_ != 1:
                raise ValueError("return_cov: only for a single output")
            return self._shape_out(self.models_[0].predict_mean(X)), self.models_[0].predict_cov(X, 0, False)
        if not return_std:
            return self._shape_out(self._per_model(lambda m: m.predict_mean(X)))
        mv = [m.predict(X, False) for m in self.models_]
        mean = np.concatenate([a for a, _ in mv], axis=1)
        var = np.concatenate([b for _, b in mv], axis=1)
        return self._shape_out(mean), self._shape_out(np.sqrt(np.maximum(var, 0.0)))

    def log_marginal_likelihood(self):
        """Log marginal likelihood of the fitted model (summed over outputs; standardised y)."""
        self._check_fitted()
        return float(sum(m.log_marginal_likelihood() for m in self.models_))

    def log_predictive_density(self, X, Y):
        """log p(Y_i | X_i) under the predictive distribution with noise, summed over outputs: (N,)."""
        self._check_fitted()
        X = _as_2d(X, "X", self.n_features_in_)
        Y = _as_2d(Y, "Y", self.n_outputs_) if np.ndim(Y) == 2 else _as_2d(np.reshape(Y, (-1, 1)), "Y",
                                                                            self.n_outputs_)
        if Y.shape[0] != X.shape[0]:
            raise ValueError(f"Y: has {Y.shape[0]} rows but X has {X.shape[0]}")
        if len(self.models_) == 1:
            return self.models_[0].log_predictive_density(X, Y)
        return sum(m.log_predictive_density(X, Y[:, [p]]) for p, m in enumerate(self.models_))

    def sample_y(self, X, n_samples=1, seed=0, joint=True, include_noise=False):
        """Samples from the predictive distribution, shaped like scikit-learn's:
        (N, n_samples) for 1-D y, else (N, P, n_samples). joint=False draws each input independently
        (the planners' measurement draws, Eq. 3.2); include_noise adds the observation noise."""
        self._check_fitted()
        X = _as_2d(X, "X", self.n_features_in_)
        if c_int(n_samples, "n_samples") < 1:
            raise ValueError(f"n_samples: must be >= 1, got {n_samples}")
        seed = c_seed(seed, "seed") if seed is not None else 0
        parts = [m.sample(X, c_int(n_samples, "n_samples"), (seed + 7919 * p) % 2**64, bool(include_noise), bool(joint))
                 for p, m in enumerate(self.models_)]
        s = np.concatenate(parts, axis=2)  # (S, N, P)
        s = np.transpose(s, (1, 2, 0))  # (N, P, S)
        return s[:, 0, :] if self._y_1d else s

    def score(self, X, y):
        """Coefficient of determination R^2 of the mean prediction (uniform average over outputs)."""
        pred = np.asarray(self.predict(X)).reshape(len(X), -1)
        y = np.asarray(y, dtype=float).reshape(len(X), -1)
        ss_res = ((y - pred) ** 2).sum(axis=0)
        ss_tot = ((y - y.mean(axis=0)) ** 2).sum(axis=0)
        r2 = np.where(ss_tot > 0, 1.0 - ss_res / np.where(ss_tot > 0, ss_tot, 1.0), 0.0)
        return float(np.mean(r2))

    # ---- fitted attributes ---------------------------------------------------------------------
    def _fitted_attr(self, name):
        self._check_fitted()
        vals = [np.atleast_1d(np.asarray(getattr(m, name), dtype=float)) for m in self.models_]
        return vals[0] if len(vals) == 1 else np.stack(vals)

    @property
    def lengthscale_(self):
        return self._fitted_attr("lengthscale")

    @property
    def variance_(self):
        v = self._fitted_attr("variance")
        return float(v[0]) if v.size == 1 else v.ravel()

    @property
    def noise_(self):
        v = self._fitted_attr("noise")
        return float(v[0]) if v.size == 1 else v.ravel()

    @property
    def fit_info_(self):
        """:class:`bayesgrasp._core.gp.FitInfo` of the fit (a list of them, one per model, if not shared)."""
        self._check_fitted()
        return [m.fit_info for m in self.models_] if len(self.models_) > 1 else self.models_[0].fit_info

    # ---- persistence (.npz, no pickle) ---------------------------------------------------------
    def save(self, path):
        """Saves the fitted model to an .npz file (parameters, fitted hyper-parameters, data)."""
        self._check_fitted()
        params = self.get_params()
        data = {"class": np.array(type(self).__name__), "version": np.array(1),
                "X": self.X_train_, "y": self.y_train_}
        for k, v in params.items():
            data["param_" + k] = np.array("__none__" if v is None else v)
        for p, m in enumerate(self.models_):
            data[f"m{p}_lengthscale"] = np.asarray(m.lengthscale)
            data[f"m{p}_variance"] = np.array(m.variance)
            data[f"m{p}_noise"] = np.array(m.noise)
            data[f"m{p}_mean_constant"] = np.asarray(m.mean_constant)
            if hasattr(m, "inducing_inputs"):
                data[f"m{p}_inducing"] = np.asarray(m.inducing_inputs)
        path = os.fspath(path)
        np.savez(path, **data)

    def _restore(self, d):
        X, y = d["X"], d["y"]
        self._y_1d = y.ndim == 1
        Y = y.reshape(len(y), -1)
        self.models_ = []
        shared = self.shared_hyperparameters or Y.shape[1] == 1
        cols = [Y] if shared else [Y[:, [p]] for p in range(Y.shape[1])]
        for p, Yp in enumerate(cols):
            kw = self._core_kwargs(X.shape[1])
            kw.update(lengthscale=d[f"m{p}_lengthscale"], variance=float(d[f"m{p}_variance"]),
                      noise=float(d[f"m{p}_noise"]), optimize=False)
            if f"m{p}_inducing" in d:
                kw.update(inducing=d[f"m{p}_inducing"])
            if self.mean == "constant":
                kw.update(mean_constant=np.atleast_1d(d[f"m{p}_mean_constant"]))
            m = self._make_core(kw)
            m.fit(X, Yp)
            self.models_.append(m)
        self.n_features_in_ = X.shape[1]
        self.n_outputs_ = Y.shape[1]
        self.X_train_, self.y_train_ = X, y


class ExactGP(_GPBase):
    """Exact GP regression (O(N^3)); see the module docstring.

    Parameters: kernel 'se' | 'matern52'; lengthscale (scalar or (D,), None = 1); variance; noise
    (noise variance, >= 0); mean 'zero' | 'constant'; optimize (maximise the log marginal
    likelihood with L-BFGS-B and analytic gradients); max_iter; normalize_x; normalize_y; jitter
    (initial relative jitter for failed Cholesky factorisations); threads (prediction batches;
    0 = all cores); shared_hyperparameters (one model for all outputs); seed (for sampling defaults).
    """

    _core_cls = _core.gp.ExactGP


class SparseGP(_GPBase):
    """Sparse GP regression with the FITC approximation (Snelson & Ghahramani 2006).

    Parameters as :class:`ExactGP`, plus n_inducing (M), optimize_inducing (also optimise the
    inducing inputs), inducing (fixed initial inducing inputs (M, D) in input units; None =
    k-means++ seeded with seed), kmeans_iter (Lloyd iterations after k-means++).
    """

    _core_cls = _core.gp.SparseGP

    def __init__(self, kernel="se", lengthscale=None, variance=1.0, noise=1e-2, mean="zero", optimize=True,
                 max_iter=200, normalize_x=True, normalize_y=True, jitter=1e-8, threads=1,
                 shared_hyperparameters=True, seed=0, n_inducing=200, optimize_inducing=False, inducing=None,
                 kmeans_iter=10):
        super().__init__(kernel=kernel, lengthscale=lengthscale, variance=variance, noise=noise, mean=mean,
                         optimize=optimize, max_iter=max_iter, normalize_x=normalize_x, normalize_y=normalize_y,
                         jitter=jitter, threads=threads, shared_hyperparameters=shared_hyperparameters, seed=seed)
        self.n_inducing = n_inducing
        self.optimize_inducing = optimize_inducing
        self.inducing = inducing
        self.kmeans_iter = kmeans_iter

    def _check_params(self):
        super()._check_params()
        c_seed(self.seed, "seed")  # the C++ seed is unsigned 64-bit

    def _core_kwargs(self, D):
        kw = super()._core_kwargs(D)
        kw.update(n_inducing=c_int(self.n_inducing, "n_inducing"), optimize_inducing=bool(self.optimize_inducing),
                  seed=c_seed(self.seed, "seed"), kmeans_iter=c_int(self.kmeans_iter, "kmeans_iter"))
        if self.inducing is not None:
            kw["inducing"] = _as_2d(self.inducing, "inducing", D)
        return kw

    @property
    def inducing_inputs_(self):
        """Inducing inputs (M, D) in input units (stacked per output if not shared)."""
        self._check_fitted()
        z = [np.asarray(m.inducing_inputs) for m in self.models_]
        return z[0] if len(z) == 1 else np.stack(z)


def load(path):
    """Reads a model written by ``save`` (an .npz file) and returns the fitted estimator."""
    with np.load(os.fspath(path), allow_pickle=False) as d:
        d = {k: d[k] for k in d.files}
    cls = {"ExactGP": ExactGP, "SparseGP": SparseGP}.get(str(d["class"]))
    if cls is None:
        raise ValueError(f"path: not a bayesgrasp GP model file ({d.get('class')!r})")
    params = {}
    for k in cls._param_names():
        v = d.get("param_" + k)
        if v is None:
            continue
        v = v.item() if v.ndim == 0 else v
        params[k] = None if isinstance(v, str) and v == "__none__" else v
    est = cls(**params)
    est._restore(d)
    return est


ExactGP.load = staticmethod(load)
SparseGP.load = staticmethod(load)
