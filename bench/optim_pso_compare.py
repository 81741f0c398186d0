"""PSO against pyswarms' GlobalBestPSO on the same budget and objective (4-D Rastrigin).

Run twice by bench/run_optim.sh: `--side ours` with the bayesgrasp interpreter, `--side pyswarms`
with the peer interpreter (which has no bayesgrasp); each writes bench/results/optim_pso_<side>.json
and `--report` prints both and the ratios. Same workload on both sides: n_particles, evaluation
budget, bounds, constriction parameters (w = 0.7298, c1 = c2 = 1.49618), a vectorised numpy
objective; one thread; median of repeats with different seeds; CPU time of the process
(time.process_time: the machine may be shared). Both sides also run a trivial objective
(f = x_0, one numpy copy per call) to show the optimiser's own overhead per evaluation, and our
side runs the C++ built-in objective (no Python in the loop).
"""
import argparse
import json
import os
import statistics
import sys
import time

import numpy as np

WORKLOADS = [  # (name, n_particles, evaluations)
    ("40x200", 40, 8000),
    ("100x1000", 100, 100000),
]
D, LO, HI = 4, -5.12, 5.12
REPEATS = 7
RESULTS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "results")


def rastrigin(X):
    return 10.0 * X.shape[1] + (X * X - 10.0 * np.cos(2.0 * np.pi * X)).sum(axis=1)


def trivial(X):
    return X[:, 0].copy()


clock = time.process_time


def run_ours():
    from bayesgrasp import optim
    out = {"side": "bayesgrasp", "workloads": {}}
    for name, n, evals in WORKLOADS:
        iters = evals // n - 1  # ours evaluates the initial swarm too: n * (iters + 1) = evals
        res = {}
        for label, fun in (("python_callable", rastrigin), ("cpp_builtin", "rastrigin"),
                           ("trivial_python_callable", trivial)):
            times, best = [], []
            for seed in range(REPEATS):
                t = clock()
                r = optim.pso(fun, ([LO] * D, [HI] * D), n_particles=n, max_iter=iters, seed=seed)
                times.append(clock() - t)
                best.append(r.fun)
                assert r.nfev == evals, (r.nfev, evals)
            res[label] = {"median_s": statistics.median(times), "median_best_f": statistics.median(best),
                          "ns_per_eval": statistics.median(times) / evals * 1e9}
        out["workloads"][name] = {"n_particles": n, "evaluations": evals, **res}
    return out


def run_pyswarms():
    import logging
    import pyswarms as ps
    logging.getLogger("pyswarms").setLevel(logging.ERROR)
    out = {"side": "pyswarms", "version": ps.__version__, "workloads": {}}
    for name, n, evals in WORKLOADS:
        iters = evals // n  # pyswarms evaluates once per iteration
        res = {}
        for label, fun in (("python_callable", rastrigin), ("trivial_python_callable", trivial)):
            times, best = [], []
            for seed in range(REPEATS):
                np.random.seed(seed)
                opt = ps.single.GlobalBestPSO(n_particles=n, dimensions=D,
                                              options={"c1": 1.49618, "c2": 1.49618, "w": 0.7298},
                                              bounds=(np.full(D, LO), np.full(D, HI)))
                t = clock()
                cost, _ = opt.optimize(fun, iters=iters, verbose=False)
                times.append(clock() - t)
                best.append(cost)
            res[label] = {"median_s": statistics.median(times), "median_best_f": statistics.median(best),
                          "ns_per_eval": statistics.median(times) / evals * 1e9}
        out["workloads"][name] = {"n_particles": n, "evaluations": evals, **res}
    return out


def report():
    ours = json.load(open(os.path.join(RESULTS, "optim_pso_ours.json")))
    peer = json.load(open(os.path.join(RESULTS, "optim_pso_pyswarms.json")))
    print(f"PSO, {D}-D Rastrigin, median of {REPEATS} seeds, one thread; pyswarms {peer.get('version')}")
    print(f"{'workload':>10} {'side':>34} {'CPU ms':>9} {'ns/eval':>9} {'best f':>9}")
    summary = {}
    for name in ours["workloads"]:
        o, p = ours["workloads"][name], peer["workloads"][name]
        rows = [("pyswarms (numpy Rastrigin)", p["python_callable"]),
                ("bayesgrasp (numpy Rastrigin)", o["python_callable"]),
                ("bayesgrasp (C++ Rastrigin)", o["cpp_builtin"]),
                ("pyswarms (trivial numpy objective)", p["trivial_python_callable"]),
                ("bayesgrasp (trivial numpy objective)", o["trivial_python_callable"])]
        for label, r in rows:
            print(f"{name:>10} {label:>34} {r['median_s'] * 1e3:9.2f} {r['ns_per_eval']:9.1f} "
                  f"{r['median_best_f']:9.2e}")
        s1 = p["python_callable"]["median_s"] / o["python_callable"]["median_s"]
        s2 = p["python_callable"]["median_s"] / o["cpp_builtin"]["median_s"]
        s3 = p["trivial_python_callable"]["median_s"] / o["trivial_python_callable"]["median_s"]
        print(f"{name:>10} speed-up vs pyswarms: {s1:.1f}x (same numpy Rastrigin), {s2:.1f}x (C++ Rastrigin), "
              f"{s3:.1f}x (trivial objective: optimiser overhead)")
        summary[name] = {"speedup_same_objective": s1, "speedup_cpp_objective": s2, "speedup_trivial_objective": s3}
    json.dump({"ours": ours, "pyswarms": peer, "summary": summary},
              open(os.path.join(RESULTS, "optim_pso_vs_pyswarms.json"), "w"), indent=2)


if __name__ == "__main__":
    ap = argparse.ArgumentParser()
    ap.add_argument("--side", choices=["ours", "pyswarms"])
    ap.add_argument("--report", action="store_true")
    a = ap.parse_args()
    os.makedirs(RESULTS, exist_ok=True)
    if a.side:
        res = run_ours() if a.side == "ours" else run_pyswarms()
        json.dump(res, open(os.path.join(RESULTS, f"optim_pso_{a.side}.json"), "w"), indent=2)
    if a.report:
        report()
    if not a.side and not a.report:
        ap.print_help()
        sys.exit(2)
