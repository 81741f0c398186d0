#!/usr/bin/env bash
# GP benchmarks: bayesgrasp's FITC / exact GP against GPy's FITC and scikit-learn's
# GaussianProcessRegressor on the same data, one thread each.
# Env: BUILD_DIR (holds bench_gp), BAYESGRASP_PY (python with bayesgrasp), BENCH_PY (peers).
source "$(dirname "$0")/env.sh"
DATA=$R/gp_data
mkdir -p "$DATA"
echo ">> data (seeded): N=5000, D=3, M=200 fixed inducing inputs, 100k prediction inputs"
"$BENCH_PY" bench/gp_peers.py data "$DATA"
echo ">> C++ (Google Benchmark, bench_gp)"
export BAYESGRASP_GP_DATA="$DATA"
run_cpp_bench gp 3
echo ">> peers: GPy FITC, scikit-learn (BENCH_PY)"
"$BENCH_PY" bench/gp_peers.py peers "$DATA" "$R/gp_peers.json"
echo ">> bayesgrasp through Python (BAYESGRASP_PY)"
"$BAYESGRASP_PY" bench/gp_ours.py "$DATA" "$R/gp_ours.json"
"$BAYESGRASP_PY" bench/gp_report.py "$R"
