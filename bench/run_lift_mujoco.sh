#!/usr/bin/env bash
# The lift test checked against MuJoCo (an independent simulator): closed grasps with our verdicts
# exported (bench/lift_heldset.py: force-closure top grasps on the five Pub. II objects, random
# force-closure approaches on the mug and bottle categories, and the held share of 200 force-closure
# top grasps per Pub. II object), replayed in MuJoCo with the same hand, object, squeeze model and
# script (bench/lift_mujoco.py), then the verdict agreement and the disagreements by cause.
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
echo ">> our lift test: export the grasps and verdicts ($OUT)"
# A development build's module if there is one (BUILD_DIR/bayesgrasp_core), else the installed package.
if [ -d "$BUILD_DIR/bayesgrasp_core" ]; then export BAYESGRASP_CORE_DIR="$BUILD_DIR/bayesgrasp_core" PYTHONPATH=python; fi
"$BAYESGRASP_PY" bench/lift_heldset.py --out "$OUT" \
  --per-object 40 --per-category-object 10 --held-share 200 | tee bench/results/lift_held_share.txt
echo ">> MuJoCo: the same grasps"
"$MJ_PY" bench/lift_mujoco.py "$OUT" --out bench/results/lift_mujoco.json | tee bench/results/lift_mujoco.txt
