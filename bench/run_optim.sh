#!/usr/bin/env bash
# Optimiser benchmarks: C++ overhead per evaluation (Google Benchmark) and PSO against pyswarms
# on the same budget (ours with BAYESGRASP_PY, pyswarms with BENCH_PY, in this same run).
# Env (set by bench/bench_all.sh): BUILD_DIR, BAYESGRASP_PY, BENCH_PY.
source "$(dirname "$0")/env.sh"
echo "--- C++: optimiser overhead per evaluation (trivial objective f = x0), CPU time"
run_cpp_bench optim 5
echo "--- PSO vs pyswarms (GlobalBestPSO), 4-D Rastrigin, same budget"
"$BAYESGRASP_PY" bench/optim_pso_compare.py --side ours
"$BENCH_PY" bench/optim_pso_compare.py --side pyswarms
"$BAYESGRASP_PY" bench/optim_pso_compare.py --report
