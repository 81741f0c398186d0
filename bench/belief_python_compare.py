"""Belief operations from Python: bayesgrasp (C++ core) against a straightforward vectorised numpy
implementation of the same algorithms (the baseline a Python planner would otherwise use; there is
no standard particle-belief library to compare with).

  * update cycle: reweight by a cheap Gaussian pose likelihood + systematic resampling + one
    Metropolis sweep, N = 500 and 5000 particles; particles per second. The likelihood is the same
    numpy callable on both sides (ours calls it once per batch from C++), so the difference is the
    belief machinery around it.
  * expected posterior entropy (Eq. 3.2) of one action: 500 particles x 100 samples, K = 3 outputs.

Median CPU time (time.process_time) of repeats, one thread. Writes bench/results/belief_python.json.
"""
import json
import os
import statistics
import time

import numpy as np

RESULTS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "results")
clock = time.process_time
LOW = np.array([-0.1, -0.1, -np.pi])
HIGH = np.array([0.1, 0.1, np.pi])
STEP = np.array([0.005, 0.005, 0.05])


def loglik(P):
    dyaw = np.remainder(P[:, 2] - 0.3 + np.pi, 2 * np.pi) - np.pi
    return -0.5 * (((P[:, 0] - 0.02) / 0.01) ** 2 + ((P[:, 1] + 0.01) / 0.01) ** 2 + (dyaw / 0.1) ** 2)


# ---- numpy baseline -----------------------------------------------------------------------------
def np_cycle(P, lw, rng):
    lw = lw + loglik(P)
    lw -= lw.max()
    w = np.exp(lw)
    w /= w.sum()
    n = len(w)
    u = (rng.random() + np.arange(n)) / n
    idx = np.minimum(np.searchsorted(np.cumsum(w), u, side="right"), n - 1)
    P = P[idx]
    cur = loglik(P)
    Y = P + STEP * rng.standard_normal(P.shape)
    Y[:, 2] = np.remainder(Y[:, 2] + np.pi, 2 * np.pi) - np.pi
    inside = np.all((Y[:, :2] >= LOW[:2]) & (Y[:, :2] <= HIGH[:2]), axis=1)
    Y[~inside] = P[~inside]
    prop = loglik(Y)
    acc = inside & (np.log(rng.random(n)) < prop - cur)
    P[acc] = Y[acc]
    return P, np.full(n, -np.log(n))


def np_epe(lw, mean, var, n_samples, rng):
    w = np.exp(lw - lw.max())
    w /= w.sum()
    j = np.minimum(np.searchsorted(np.cumsum(w), (np.arange(n_samples) + rng.random(n_samples)) / n_samples,
                                   side="right"), len(w) - 1)
    m = mean[j] + np.sqrt(var[j]) * rng.standard_normal((n_samples, mean.shape[1]))      # (S, K)
    base = lw - 0.5 * np.log(var).sum(axis=1)
    L = base[None, :] - 0.5 * (((m[:, None, :] - mean[None, :, :]) ** 2) / var[None, :, :]).sum(axis=2)  # (S, N)
    L -= L.max(axis=1, keepdims=True)
    E = np.exp(L)
    S = E.sum(axis=1)
    H = np.log(S) - (E * L).sum(axis=1) / S
    return H.mean()


def median_time(fn, repeats):
    ts = []
    for _ in range(repeats):
        t = clock()
        fn()
        ts.append(clock() - t)
    return statistics.median(ts)


def main():
    from bayesgrasp.belief import ParticleBelief, expected_posterior_entropy
    out = {"update_cycle": {}, "expected_entropy": {}}
    for n in (500, 5000):
        reps = 200 if n == 500 else 40
        b = ParticleBelief.uniform(LOW, HIGH, n, [False, False, True], seed=0)

        def ours():
            b.update(loglik)
            b.resample("systematic")
            b.metropolis(loglik, STEP, 1)

        rng = np.random.default_rng(0)
        state = [ParticleBelief.uniform(LOW, HIGH, n, [False, False, True], seed=0).particles, np.zeros(n)]

        def base():
            state[0], state[1] = np_cycle(state[0], state[1], rng)

        t_ours, t_np = median_time(ours, reps), median_time(base, reps)
        out["update_cycle"][str(n)] = {"bayesgrasp_s": t_ours, "numpy_s": t_np,
                                       "bayesgrasp_particles_per_s": n / t_ours, "numpy_particles_per_s": n / t_np,
                                       "speedup": t_np / t_ours}
    rng = np.random.default_rng(1)
    n, K, S = 500, 3, 100
    lw = -rng.random(n)
    mean = rng.random((n, K))
    var = 0.01 + 0.05 * rng.random((n, K))
    t_ours = median_time(lambda: expected_posterior_entropy(lw, mean, var, S, 7), 200)
    t_np = median_time(lambda: np_epe(lw, mean, var, S, rng), 50)
    h_ours = expected_posterior_entropy(lw, mean, var, 4000, 7)[0]
    h_np = np.mean([np_epe(lw, mean, var, 1000, np.random.default_rng(s)) for s in range(4)])
    out["expected_entropy"] = {"particles": n, "samples": S, "outputs": K, "bayesgrasp_s": t_ours, "numpy_s": t_np,
                               "speedup": t_np / t_ours, "check_bayesgrasp_4000_samples": h_ours,
                               "check_numpy_4000_samples": float(h_np)}
    os.makedirs(RESULTS, exist_ok=True)
    json.dump(out, open(os.path.join(RESULTS, "belief_python.json"), "w"), indent=2)
    print("Belief from Python (median CPU time, one thread); baseline: vectorised numpy, same algorithm")
    for n, r in out["update_cycle"].items():
        print(f"  update cycle (reweight + systematic resample + 1 Metropolis sweep), N = {n:>5}: "
              f"bayesgrasp {r['bayesgrasp_particles_per_s'] / 1e6:6.2f} M particles/s, "
              f"numpy {r['numpy_particles_per_s'] / 1e6:6.2f} M particles/s ({r['speedup']:.1f}x)")
    e = out["expected_entropy"]
    print(f"  expected posterior entropy, 500 particles x 100 samples, K = 3: bayesgrasp {e['bayesgrasp_s'] * 1e3:.3f} ms, "
          f"numpy {e['numpy_s'] * 1e3:.3f} ms ({e['speedup']:.1f}x); estimates agree: "
          f"{e['check_bayesgrasp_4000_samples']:.4f} vs {e['check_numpy_4000_samples']:.4f}")


if __name__ == "__main__":
    main()
