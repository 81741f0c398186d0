#!/usr/bin/env bash
# Belief benchmarks: C++ throughput (update cycle, expected posterior entropy, KDE entropy,
# relative poses) with Google Benchmark, then the Python API against a vectorised numpy
# implementation of the same algorithms. Env (set by bench/bench_all.sh): BUILD_DIR, BAYESGRASP_PY.
source "$(dirname "$0")/env.sh"
echo "--- C++: belief update cycle, expected posterior entropy, KDE entropy, relative poses (CPU time)"
run_cpp_bench belief 5
echo "--- Python API vs vectorised numpy (same algorithms)"
"$BAYESGRASP_PY" bench/belief_python_compare.py
