# Sourced by bench/run_<concept>.sh: works from the repository root, with the build directory and
# the interpreters of bench/bench_all.sh (defaults for a standalone run), one thread, the results
# in $R, and run_cpp_bench NAME REPETITIONS [ARGS...], which runs build/.../bench_NAME (Google
# Benchmark, aggregates only) and writes $R/NAME_cpp.json.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
BUILD_DIR=${BUILD_DIR:-build/py}
BAYESGRASP_PY=${BAYESGRASP_PY:-.venv/bin/python}
BENCH_PY=${BENCH_PY:-.venv-bench/bin/python}
export OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 MKL_NUM_THREADS=1
R=bench/results
mkdir -p "$R"

run_cpp_bench() {
  local name=$1 repetitions=$2
  shift 2
  "$BUILD_DIR/bench_$name" --benchmark_repetitions="$repetitions" --benchmark_report_aggregates_only=true \
    --benchmark_out="$R/${name}_cpp.json" --benchmark_out_format=json "$@"
}
