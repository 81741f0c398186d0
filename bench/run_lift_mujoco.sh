#!/usr/bin/env bash
# The lift test checked against MuJoCo (an independent simulator): closed grasps with our verdicts
# exported (bench/lift_heldset.py: force-closure top grasps on the five Pub. II objects, random
# force-closure approaches on the mug and bottle categories, and the held share of 200 force-closure
# top grasps per Pub. II object), replayed in MuJoCo with the same hand, object, squeeze model and
# script (bench/lift_mujoco.py), then the verdict agreement and the disagreements by cause.
# With the grasps the planners executed (issue 30, part 4): pub2 attempts of both grasp families
# and pub5 category task grasps, from the experiment directories in EXECUTED (comma-separated);
# by default small runs made here (pub2 --families top,side, 10 runs per object; pub5 on two mugs
# and two bottles, 2 runs each) into bench/results/executed_*.
# Env: BUILD_DIR (default build/dev), BAYESGRASP_PY (python with bayesgrasp's requirements),
# MJ_PY (python with bench/requirements.txt, i.e. mujoco; default .venv-bench, else .venv-mj).
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR=${BUILD_DIR:-build/dev}
export OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 MKL_NUM_THREADS=1
BAYESGRASP_PY=${BAYESGRASP_PY:-python}
if [ -z "${MJ_PY:-}" ]; then
  if [ -x .venv-bench/bin/python ]; then MJ_PY=.venv-bench/bin/python; else MJ_PY=.venv-mj/bin/python; fi
fi
OUT=bench/results/heldset
rm -rf "$OUT"
if [ -z "${EXECUTED:-}" ]; then
  echo ">> the planners' executed grasps: small pub2 (top and side) and pub5 runs"
  "$BAYESGRASP_PY" -m bayesgrasp.cli experiment pub2 --families top,side --runs "${EXECUTED_RUNS:-10}" --workers 2 \
    --out bench/results/executed_pub2 > /dev/null
  "$BAYESGRASP_PY" -m bayesgrasp.cli experiment pub5 --objects mug/0 mug/3 bottle/0 bottle/5 --runs 2 --workers 2 \
    --out bench/results/executed_pub5 > /dev/null
  EXECUTED=bench/results/executed_pub2,bench/results/executed_pub5
fi
echo ">> our lift test: export the grasps and verdicts ($OUT)"
# A development build's module if there is one (BUILD_DIR/bayesgrasp_core), else the installed package.
if [ -d "$BUILD_DIR/bayesgrasp_core" ]; then export BAYESGRASP_CORE_DIR="$BUILD_DIR/bayesgrasp_core" PYTHONPATH=python; fi
"$BAYESGRASP_PY" bench/lift_heldset.py --out "$OUT" \
  --per-object 40 --per-category-object 10 --held-share 200 --executed "$EXECUTED" | tee bench/results/lift_held_share.txt
echo ">> MuJoCo: the same grasps"
"$MJ_PY" bench/lift_mujoco.py "$OUT" --out bench/results/lift_mujoco.json | tee bench/results/lift_mujoco.txt
