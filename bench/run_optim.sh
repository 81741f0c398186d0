#!/usr/bin/env bash
# Optimiser benchmarks: C++ overhead per evaluation (Google Benchmark) and PSO against pyswarms
# on the same budget (ours with BAYESGRASP_PY, pyswarms with BENCH_PY, in this same run).
# Env (set by bench/bench_all.sh): BUILD_DIR, BAYESGRASP_PY, BENCH_PY.
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR=${BUILD_DIR:-build/py}
BAYESGRASP_PY=${BAYESGRASP_PY:-.venv/bin/python}
BENCH_PY=${BENCH_PY:-.venv-bench/bin/python}
export OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 MKL_NUM_THREADS=1
mkdir -p bench/results
echo "--- C++: optimiser overhead per evaluation (trivial objective f = x0), CPU time"
"$BUILD_DIR/bench_optim" --benchmark_repetitions=5 --benchmark_report_aggregates_only=true \
  --benchmark_out=bench/results/optim_cpp.json --benchmark_out_format=json
echo "--- PSO vs pyswarms (GlobalBestPSO), 4-D Rastrigin, same budget"
"$BAYESGRASP_PY" bench/optim_pso_compare.py --side ours
"$BENCH_PY" bench/optim_pso_compare.py --side pyswarms
"$BAYESGRASP_PY" bench/optim_pso_compare.py --report
