"""GP peers for bench/run_gp.sh (runs with BENCH_PY: GPy, scikit-learn, numpy).

  python bench/gp_peers.py data  OUT_DIR        # writes the shared data (npz + raw .bin for C++)
  python bench/gp_peers.py peers OUT_DIR JSON   # times GPy FITC and scikit-learn on that data

Workload: N = 5000 training points in 3-D, M = 200 fixed inducing inputs,
prediction at 100,000 inputs; exact GP vs scikit-learn at N = 2000, 10,000 prediction inputs.
"""
import json
import os
import sys
import time

import numpy as np

from gp_timing import CPU, median_time  # bench/gp_timing.py, beside this script

N, D, M, NS = 5000, 3, 200, 100_000
N_EXACT, NS_EXACT = 2000, 10_000


def make_data(out):
    rng = np.random.default_rng(20261122)
    X = rng.uniform(0.0, 1.0, (N, D))
    y = np.sin(6 * X[:, 0]) * np.cos(4 * X[:, 1]) + X[:, 2] ** 2 + 0.1 * rng.standard_normal(N)
    Z = X[rng.choice(N, M, replace=False)]
    Xs = rng.uniform(0.0, 1.0, (NS, D))
    os.makedirs(out, exist_ok=True)
    np.savez(os.path.join(out, "gp_data.npz"), X=X, y=y, Z=Z, Xs=Xs)
    for name, a in (("X", X), ("y", y), ("Z", Z), ("Xs", Xs)):
        np.ascontiguousarray(a, dtype=np.float64).tofile(os.path.join(out, name + ".bin"))


def dgemm_gflops():
    a = np.random.default_rng(0).standard_normal((M, N))
    b = a.T.copy()
    t = median_time(lambda: a @ b, 20)
    return 2.0 * M * N * M / t / 1e9


def peers(out, json_path):
    d = np.load(os.path.join(out, "gp_data.npz"))
    X, y, Z, Xs = d["X"], d["y"][:, None], d["Z"], d["Xs"]
    res = {"numpy_dgemm_gflops": dgemm_gflops()}
    try:
        import GPy
        res["gpy_version"] = GPy.__version__
        res["gpy_inference"] = "FITC"
        res["numpy_version"] = np.__version__

        def build():
            # GPy's FITC: SparseGPRegression would pick the variational VarDTC (Titsias)
            # inference instead, a different approximation.
            k = GPy.kern.RBF(D, variance=1.0, lengthscale=np.ones(D), ARD=True)
            m = GPy.core.SparseGP(X, y, Z.copy(), k, GPy.likelihoods.Gaussian(variance=1.0),
                                  inference_method=GPy.inference.latent_function_inference.FITC())
            m.Z.fix()
            return m

        fits, cfits = [], []
        for _ in range(3):
            m = build()
            t, c = time.perf_counter(), time.process_time()
            m.optimize(optimizer="lbfgsb")
            fits.append(time.perf_counter() - t)
            cfits.append(time.process_time() - c)
        res["gpy_fitc_train_s"] = float(np.median(fits))
        CPU["gpy_fitc_train_s"] = float(np.median(cfits))
        run = m.optimization_runs[-1]
        res["gpy_fitc_evaluations"] = int(getattr(run, "funct_eval", -1) or -1)
        res["gpy_fitc_lml"] = float(np.ravel(m.log_likelihood())[0])
        res["gpy_fitc_params"] = {"lengthscale": np.asarray(m.kern.lengthscale).tolist(),
                                  "variance": float(np.ravel(m.kern.variance)[0]),
                                  "noise": float(np.ravel(m.likelihood.variance)[0])}
        x = m.optimizer_array.copy()
        m._objective_grads(x)
        res["gpy_fitc_objective_s"] = median_time(lambda: m._objective_grads(x), 10, name="gpy_fitc_objective_s")
        wv = m.posterior.woodbury_vector
        res["gpy_predict_mean_100k_s"] = median_time(lambda: m.kern.K(Xs, m.Z.values) @ wv, 5, name="gpy_predict_mean_100k_s")
        res["gpy_predict_mean_var_100k_s"] = median_time(lambda: m.predict(Xs, include_likelihood=False), 3, name="gpy_predict_mean_var_100k_s")
        mu, var = m.predict(Xs[:1000], include_likelihood=False)
        np.savez(os.path.join(out, "gpy_pred.npz"), mean=mu[:, 0], var=var[:, 0])
    except Exception as e:  # report, don't hide
        res["gpy_error"] = f"{type(e).__name__}: {e}"
    try:
        import sklearn
        from sklearn.gaussian_process import GaussianProcessRegressor
        from sklearn.gaussian_process.kernels import RBF, ConstantKernel, WhiteKernel
        res["sklearn_version"] = sklearn.__version__
        ls, var, noise = np.array([0.3, 0.4, 0.8]), 0.5, 0.01
        kern = ConstantKernel(var, "fixed") * RBF(ls, "fixed") + WhiteKernel(noise, "fixed")
        gpr = GaussianProcessRegressor(kernel=kern, optimizer=None, normalize_y=False)
        Xe, ye, Xse = X[:N_EXACT], y[:N_EXACT, 0], Xs[:NS_EXACT]
        res["sklearn_exact_fit_s"] = median_time(lambda: gpr.fit(Xe, ye), 3, name="sklearn_exact_fit_s")
        res["sklearn_exact_predict_mean_10k_s"] = median_time(lambda: gpr.predict(Xse), 3, name="sklearn_exact_predict_mean_10k_s")
        res["sklearn_exact_predict_mean_std_10k_s"] = median_time(lambda: gpr.predict(Xse, return_std=True), 3, name="sklearn_exact_predict_mean_std_10k_s")
        mu, sd = gpr.predict(Xse[:1000], return_std=True)
        # return_std of sklearn includes the WhiteKernel noise: remove it to compare var of f
        np.savez(os.path.join(out, "sklearn_pred.npz"), mean=mu, var=sd ** 2 - noise,
                 lml=gpr.log_marginal_likelihood_value_)
    except Exception as e:
        res["sklearn_error"] = f"{type(e).__name__}: {e}"
    res["cpu_s"] = CPU
    with open(json_path, "w") as f:
        json.dump(res, f, indent=1)


if __name__ == "__main__":
    if sys.argv[1] == "data":
        make_data(sys.argv[2])
    else:
        peers(sys.argv[2], sys.argv[3])
