#!/usr/bin/env bash
# Top grasps against mesh size (a tessellated box, 12 to 62k triangles, and the mug), one thread,
# with and without the simulator's tie tolerance. Writes bench/results/sim_mesh_size.json.
set -euo pipefail
cd "$(dirname "$0")/.."
"${BAYESGRASP_PY:-.venv/bin/python}" bench/sim_mesh_size.py bench/results
