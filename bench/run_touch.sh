#!/usr/bin/env bash
# One touch's estimate (Pub. I), one core: bench_touch (C++, Google Benchmark) on a cube, a
# cylinder and the built-in mug (exported in its object frame by the Python package), each
# estimate a 2,000-evaluation budget; PSO, descent, annealing and firefly in 3 DoF, PSO in 4 DoF.
# Writes bench/results/touch_cpp.json. Env: BUILD_DIR (holds bench_touch), BAYESGRASP_PY.
source "$(dirname "$0")/env.sh"
BAYESGRASP_CORE_DIR=${BAYESGRASP_CORE_DIR:-$BUILD_DIR/bayesgrasp_core} PYTHONPATH=python "$BAYESGRASP_PY" -c "
import numpy as np
from bayesgrasp.planners.touch import canonical_object
m = canonical_object('mug')
with open('$R/touch_mug.txt', 'w') as f:
    f.write(f'{len(m.vertices)} {len(m.faces)}\\n')
    np.savetxt(f, m.vertices, fmt='%.17g')
    np.savetxt(f, m.faces, fmt='%d')"
run_cpp_bench touch 3 --mesh="$R/touch_mug.txt" "$@"
