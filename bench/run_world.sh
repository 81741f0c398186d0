#!/usr/bin/env bash
# The robot's world end to end: auto-grasp + epsilon on the built-in mug, one core.
set -euo pipefail
cd "$(dirname "$0")/.."
"${BAYESGRASP_PY:-.venv/bin/python}" bench/world_grasp_quality.py bench/results
