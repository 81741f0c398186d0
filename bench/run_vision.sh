#!/usr/bin/env bash
# Vision benchmarks: ray-casting throughput (C++), then registration of a fixed set of >= 200
# partial views: ours vs Open3D's FPFH + RANSAC + ICP on the same clouds and voxel size.
# Env: BUILD_DIR (bench binaries), BAYESGRASP_PY (has bayesgrasp), BENCH_PY (has open3d).
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR=${BUILD_DIR:-build/py}
BAYESGRASP_PY=${BAYESGRASP_PY:-.venv/bin/python}
BENCH_PY=${BENCH_PY:-.venv-bench/bin/python}
export OMP_NUM_THREADS=${OMP_NUM_THREADS:-1}
mkdir -p bench/results

if [ -x "$BUILD_DIR/bench_vision" ]; then
  "$BUILD_DIR/bench_vision" --benchmark_out=bench/results/vision_raycast.json --benchmark_out_format=json
fi

VIEWS=bench/results/vision_views.npz
[ -f "$VIEWS" ] || "$BAYESGRASP_PY" bench/vision_make_views.py --views 240 --seed 0 --out "$VIEWS"
# Models prepared once in a Registrar (untimed), as Open3D's are cached (--model-cache 1) below.
"$BAYESGRASP_PY" bench/vision_ours.py --views "$VIEWS" --up-prior 1
"$BAYESGRASP_PY" bench/vision_ours.py --views "$VIEWS" --up-prior 0
"$BAYESGRASP_PY" bench/vision_ours.py --views "$VIEWS" --registrar 0   # one-shot: model prepared in every call
if "$BENCH_PY" -c "import open3d" 2>/dev/null; then
  "$BENCH_PY" bench/vision_open3d.py --views "$VIEWS"
else
  echo "open3d not importable by $BENCH_PY: peer skipped"
fi
"$BAYESGRASP_PY" bench/vision_report.py
