#!/usr/bin/env bash
# Experiment engines: pub2 runs/s on 1 and 2 workers, local processes vs Ray tasks (models built
# beforehand), and the per-run costs of pub2 and pub5 for a sweep's estimate.
set -euo pipefail
cd "$(dirname "$0")/.."
export OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 MKL_NUM_THREADS=1
"${BAYESGRASP_PY:-.venv/bin/python}" bench/engines.py --out bench/results/engines.json --runs "${ENGINE_RUNS:-8}"
