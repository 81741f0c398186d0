#!/usr/bin/env bash
# Grasp-quality benchmarks: epsilon + GWS volume per grasp, one core.
#  1. C++ (Google Benchmark, bench_quality): grasp_quality() for 2..7 contacts, 8 cone edges
#     (and 5 contacts with 4 edges), on seeded ellipsoid grasps.
#  2. The same computation through Python on the same seeded wrench sets: ours
#     (bayesgrasp.quality.epsilon_volume, BAYESGRASP_PY) against scipy.spatial.ConvexHull
#     (scipy's bundled Qhull, options "Qt"; epsilon = min facet offset, volume = hull volume;
#     BENCH_PY) - what a user would write otherwise. Wrenches are generated once by ours and
#     saved to bench/results/quality_wrenches.npz, so both sides hull identical points.
# Env (set by bench/bench_all.sh): BUILD_DIR, BAYESGRASP_PY, BENCH_PY.
source "$(dirname "$0")/env.sh"
echo ">> C++: grasp_quality per grasp (CPU time, median of 3)"
run_cpp_bench quality 3

echo ">> ours through Python vs scipy.spatial.ConvexHull on the same wrenches (5 contacts, 8 edges)"
"$BAYESGRASP_PY" - "$R" <<'PY'
import json, sys, time
import numpy as np
from bayesgrasp import quality
R = sys.argv[1]
rng = np.random.default_rng(2026)
axes = np.array([0.04, 0.03, 0.02])
P, N, W = [], [], []
for i in range(200):
    u = rng.normal(size=(5, 3)); u /= np.linalg.norm(u, axis=1, keepdims=True)
    p = u * axes; n = p / axes**2; n /= np.linalg.norm(n, axis=1, keepdims=True)
    P.append(p); N.append(n); W.append(quality.contact_wrenches(p, n, np.zeros(3), 0.04))
np.savez(f"{R}/quality_wrenches.npz", W=np.stack(W))
res = [quality.epsilon_volume(p, n, np.zeros(3), 0.04) for p, n in zip(P, N)]  # warm-up + values
times = []
for rep in range(5):
    t0 = time.perf_counter()
    for p, n in zip(P, N):
        quality.epsilon_volume(p, n, np.zeros(3), 0.04)
    times.append((time.perf_counter() - t0) / len(P))
out = dict(name="ours_epsilon_volume_python", grasps=len(P), contacts=5, edges=8,
           median_us_per_grasp=float(np.median(times) * 1e6),
           epsilon=[r[0] for r in res], volume=[r[1] for r in res])
json.dump(out, open(f"{R}/quality_ours.json", "w"))
print(f"ours  (bayesgrasp, Qhull Q0/Qt in C++): {out['median_us_per_grasp']:.0f} us/grasp")
PY
"$BENCH_PY" - "$R" <<'PY'
import json, sys, time
import numpy as np
from scipy.spatial import ConvexHull, QhullError
R = sys.argv[1]
W = np.load(f"{R}/quality_wrenches.npz")["W"]
def eps_vol(w):
    try:
        h = ConvexHull(w, qhull_options="Qt")
    except QhullError:
        return 0.0, 0.0
    return float(-h.equations[:, -1].max()), float(h.volume)
res = [eps_vol(w) for w in W]
times = []
for rep in range(5):
    t0 = time.perf_counter()
    for w in W:
        eps_vol(w)
    times.append((time.perf_counter() - t0) / len(W))
ours = json.load(open(f"{R}/quality_ours.json"))
diff = float(np.max(np.abs(np.array([r[0] for r in res]) - np.array(ours["epsilon"]))))
out = dict(name="scipy_ConvexHull_Qt", grasps=len(W), median_us_per_grasp=float(np.median(times) * 1e6),
           max_abs_epsilon_difference_vs_ours=diff)
json.dump(out, open(f"{R}/quality_scipy.json", "w"))
ratio = out["median_us_per_grasp"] / ours["median_us_per_grasp"]
print(f"scipy (ConvexHull 'Qt', wrenches given): {out['median_us_per_grasp']:.0f} us/grasp")
print(f"ratio scipy / ours: {ratio:.2f}x   (max |epsilon difference| {diff:.2e})")
json.dump(dict(ours_us=ours["median_us_per_grasp"], scipy_us=out["median_us_per_grasp"], ratio=ratio,
               max_abs_epsilon_difference=diff), open(f"{R}/quality_vs_scipy.json", "w"))
PY
