#!/usr/bin/env bash
# Contact-simulation benchmarks: auto-grasp on a ~2k-triangle mug, one core.
#   1. bench_sim (C++, Google Benchmark): our conservative-advancement auto-grasp (top grasps and
#      closing alone, FCL representation variants), the GraspIt!-style fixed 0.01-rad stepping on
#      the same FCL backend and grasps, and the 2-thread batch. It also exports the mug and the
#      grasp set (bench/results/mug.obj, sim_grasps.csv) and the joint-angle agreement.
#   2. sim_pybullet.py (BENCH_PY): the same hand (URDF written to bench/results/) closed on the
#      same mug by pybullet POSITION_CONTROL, same grasps.
#   3. sim_report.py: medians, ratios -> bench/results/sim.json.
#   4. bench_sim on the built-in mug (exported by world_export_mesh.py): approaches from random
#      directions on the upper hemisphere (all, and those reaching the object) beside top grasps
#      -> bench/results/bench_sim_approach.json.
#   5. hands_urdf.py: top grasps/s with the BH8 and Robotiq 3F from their hand files and from
#      their URDFs, and the parallel-jaw gripper (convex mesh jaws), on the built-in mug
#      -> bench/results/hands_urdf.json.
# Env: BUILD_DIR (holds bench_sim), BENCH_PY (pybullet), BAYESGRASP_PY (exports the built-in mug).
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR=${BUILD_DIR:-build/py}
BENCH_PY=${BENCH_PY:-.venv-bench/bin/python}
OUT=bench/results
mkdir -p "$OUT"
export OMP_NUM_THREADS=${OMP_NUM_THREADS:-1}
"$BUILD_DIR/bench_sim" --export="$OUT" --grasps=256 \
  --benchmark_repetitions=5 --benchmark_report_aggregates_only=true \
  --benchmark_out="$OUT/bench_sim.json" --benchmark_out_format=json
"$BENCH_PY" bench/sim_pybullet.py --results "$OUT" --grasps "${SIM_PYBULLET_GRASPS:-64}"
"$BENCH_PY" bench/sim_report.py --results "$OUT"
"${BAYESGRASP_PY:-.venv/bin/python}" bench/world_export_mesh.py mug "$OUT/builtin_mug.obj"
"$BUILD_DIR/bench_sim" --mesh="$OUT/builtin_mug.obj" --grasps=256 --benchmark_filter='Approach/|TopGrasp/0$' \
  --benchmark_repetitions=5 --benchmark_report_aggregates_only=true \
  --benchmark_out="$OUT/bench_sim_approach.json" --benchmark_out_format=json
"${BAYESGRASP_PY:-.venv/bin/python}" bench/hands_urdf.py --out "$OUT/hands_urdf.json"
