#!/usr/bin/env bash
# Runs every benchmark: each concept has bench/run_<concept>.sh, which runs its C++
# benchmark binaries (built in $BUILD_DIR) and its peer scripts, and writes JSON to
# bench/results/. Env: BUILD_DIR, BAYESGRASP_PY (python with bayesgrasp), BENCH_PY
# (python with the peers).
set -euo pipefail
cd "$(dirname "$0")/.."
export BUILD_DIR=${BUILD_DIR:-build/py}
export BAYESGRASP_PY=${BAYESGRASP_PY:-.venv/bin/python}
export BENCH_PY=${BENCH_PY:-.venv-bench/bin/python}
export OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 MKL_NUM_THREADS=1
mkdir -p bench/results
for script in bench/run_*.sh; do
  echo "=== $script"
  bash "$script"
done
