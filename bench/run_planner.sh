#!/usr/bin/env bash
# One planning decision with 500 particles: stability and exploration planners on the
# tabulated models vs the same stability search evaluating the FITC GP directly; one thread.
set -euo pipefail
cd "$(dirname "$0")/.."
export OMP_NUM_THREADS=1
"${BAYESGRASP_PY:-.venv/bin/python}" bench/planner_decision.py --out bench/results/planner.json --reps "${PLANNER_REPS:-10}"
