#!/usr/bin/env bash
# Lift-test benchmark (issue 2, sections 6 and 10): lift tests per second on one core
# (bench_physics: a held box, an open hand, a held concave cup with the tetrahedra shape).
# No peer is run here. Env (set by bench/bench_all.sh): BUILD_DIR.
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR=${BUILD_DIR:-build/py}
export OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 MKL_NUM_THREADS=1
mkdir -p bench/results
echo ">> C++: LiftTester::run per test (CPU time, median of 3)"
"$BUILD_DIR/bench_physics" --benchmark_repetitions=3 --benchmark_report_aggregates_only=true \
  --benchmark_out=bench/results/physics_cpp.json --benchmark_out_format=json
