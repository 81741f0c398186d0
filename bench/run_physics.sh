#!/usr/bin/env bash
# Lift-test benchmark: lift tests per second on one core
# (bench_physics: a held box, an open hand, a held concave cup and a pot pinched through its
# opening with the hull, tetrahedra and convex-decomposition shapes), then the built-in mugs
# and pitcher through Python: decomposition (CoACD pieces) vs tetrahedra verdicts and speed on
# grasps that reach into the object's hull. No peer is run here. Env (set by bench/bench_all.sh): BUILD_DIR.
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR=${BUILD_DIR:-build/py}
export OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 MKL_NUM_THREADS=1
mkdir -p bench/results
echo ">> C++: LiftTester::run per test (CPU time, median of 3)"
"$BUILD_DIR/bench_physics" --benchmark_repetitions=3 --benchmark_report_aggregates_only=true \
  --benchmark_out=bench/results/physics_cpp.json --benchmark_out_format=json
echo ">> Python: decomposition vs tetrahedra on the built-in concave objects (one thread)"
BAYESGRASP_PY=${BAYESGRASP_PY:-python}
"$BAYESGRASP_PY" bench/bench_physics_concave.py --max-grasps 20 --out bench/results/physics_concave.json
