#!/usr/bin/env bash
# GP benchmarks (issue 3, section 6): bayesgrasp's FITC / exact GP against GPy's FITC and
# scikit-learn's GaussianProcessRegressor on the same data, one thread each.
# Env: BUILD_DIR (holds bench_gp), BAYESGRASP_PY (python with bayesgrasp), BENCH_PY (peers).
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR=${BUILD_DIR:-build/py}
BAYESGRASP_PY=${BAYESGRASP_PY:-.venv/bin/python}
BENCH_PY=${BENCH_PY:-.venv-bench/bin/python}
export OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 MKL_NUM_THREADS=1
R=bench/results
DATA=$R/gp_data
mkdir -p "$DATA"
echo ">> data (seeded): N=5000, D=3, M=200 fixed inducing inputs, 100k prediction inputs"
"$BENCH_PY" bench/gp_peers.py data "$DATA"
echo ">> C++ (Google Benchmark, bench_gp)"
BAYESGRASP_GP_DATA="$DATA" "$BUILD_DIR/bench_gp" --benchmark_repetitions=3 \
  --benchmark_report_aggregates_only=true --benchmark_out="$R/gp_cpp.json" --benchmark_out_format=json
echo ">> peers: GPy FITC, scikit-learn (BENCH_PY)"
"$BENCH_PY" bench/gp_peers.py peers "$DATA" "$R/gp_peers.json"
echo ">> bayesgrasp through Python (BAYESGRASP_PY)"
"$BAYESGRASP_PY" bench/gp_ours.py "$DATA" "$R/gp_ours.json"
"$BAYESGRASP_PY" bench/gp_report.py "$R"
