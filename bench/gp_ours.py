"""bayesgrasp side of the GP benchmark (runs with BAYESGRASP_PY), on the data written by
gp_peers.py: the same workloads as the peers, timed through the Python API.

  python bench/gp_ours.py OUT_DIR JSON
"""
import json
import os
import sys
import time

import numpy as np

from bayesgrasp.gp import ExactGP, SparseGP
from gp_timing import CPU, median_time  # bench/gp_timing.py, beside this script


def main(out, json_path):
    d = np.load(os.path.join(out, "gp_data.npz"))
    X, y, Z, Xs = d["X"], d["y"], d["Z"], d["Xs"]
    res = {}
    # FITC, same start as GPy (lengthscales 1, variance 1, noise 1), fixed Z, no normalisation.
    kw = dict(kernel="se", lengthscale=np.ones(3), variance=1.0, noise=1.0, inducing=Z,
              normalize_x=False, normalize_y=False, threads=1)
    fits, cfits = [], []
    for _ in range(3):
        gp = SparseGP(**kw)
        t, c = time.perf_counter(), time.process_time()
        gp.fit(X, y)
        fits.append(time.perf_counter() - t)
        cfits.append(time.process_time() - c)
    res["ours_fitc_train_s"] = float(np.median(fits))
    CPU["ours_fitc_train_s"] = float(np.median(cfits))
    res["ours_fitc_evaluations"] = gp.fit_info_.evaluations
    res["ours_fitc_lml"] = gp.log_marginal_likelihood()
    res["ours_fitc_params"] = {"lengthscale": gp.lengthscale_.tolist(), "variance": gp.variance_,
                               "noise": gp.noise_}
    core = gp.models_[0]
    th = core.parameters()
    res["ours_fitc_objective_s"] = median_time(lambda: core.objective(th), 10, name="ours_fitc_objective_s")
    res["ours_predict_mean_100k_s"] = median_time(lambda: gp.predict(Xs), 5, name="ours_predict_mean_100k_s")
    res["ours_predict_mean_var_100k_s"] = median_time(lambda: gp.predict(Xs, return_std=True), 5,
                                                      name="ours_predict_mean_var_100k_s")
    mu, sd = gp.predict(Xs[:1000], return_std=True)
    gpy = os.path.join(out, "gpy_pred.npz")
    if os.path.exists(gpy):
        g = np.load(gpy)
        res["fitc_mean_max_abs_diff_vs_gpy"] = float(np.abs(mu - g["mean"]).max())
        res["fitc_std_max_abs_diff_vs_gpy"] = float(np.abs(sd - np.sqrt(g["var"])).max())
    # Exact GP vs scikit-learn with the same fixed hyper-parameters.
    ex = ExactGP(kernel="se", lengthscale=[0.3, 0.4, 0.8], variance=0.5, noise=0.01, optimize=False,
                 normalize_x=False, normalize_y=False)
    Xe, ye, Xse = X[:2000], y[:2000], Xs[:10000]
    res["ours_exact_fit_s"] = median_time(lambda: ex.fit(Xe, ye), 3, name="ours_exact_fit_s")
    res["ours_exact_predict_mean_10k_s"] = median_time(lambda: ex.predict(Xse), 5,
                                                       name="ours_exact_predict_mean_10k_s")
    res["ours_exact_predict_mean_std_10k_s"] = median_time(lambda: ex.predict(Xse, return_std=True), 5,
                                                           name="ours_exact_predict_mean_std_10k_s")
    sk = os.path.join(out, "sklearn_pred.npz")
    if os.path.exists(sk):
        s = np.load(sk)
        mu, sd = ex.predict(Xse[:1000], return_std=True)
        res["exact_mean_max_abs_diff_vs_sklearn"] = float(np.abs(mu - s["mean"]).max())
        res["exact_var_max_abs_diff_vs_sklearn"] = float(np.abs(sd ** 2 - s["var"]).max())
        res["exact_lml_diff_vs_sklearn"] = float(ex.log_marginal_likelihood() - s["lml"])
    res["cpu_s"] = CPU
    with open(json_path, "w") as f:
        json.dump(res, f, indent=1)


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
