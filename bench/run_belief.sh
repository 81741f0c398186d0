#!/usr/bin/env bash
# Belief benchmarks: C++ throughput (update cycle, expected posterior entropy, KDE entropy,
# relative poses) with Google Benchmark, then the Python API against a vectorised numpy
# implementation of the same algorithms. Env (set by bench/bench_all.sh): BUILD_DIR, BAYESGRASP_PY.
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR=${BUILD_DIR:-build/py}
BAYESGRASP_PY=${BAYESGRASP_PY:-.venv/bin/python}
export OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 MKL_NUM_THREADS=1
mkdir -p bench/results
echo "--- C++: belief update cycle, expected posterior entropy, KDE entropy, relative poses (CPU time)"
"$BUILD_DIR/bench_belief" --benchmark_repetitions=5 --benchmark_report_aggregates_only=true \
  --benchmark_out=bench/results/belief_cpp.json --benchmark_out_format=json
echo "--- Python API vs vectorised numpy (same algorithms)"
"$BAYESGRASP_PY" bench/belief_python_compare.py
