#!/usr/bin/env bash
# One touch's estimate (Pub. I), one core: bench_touch (C++, Google Benchmark) on the cube, the
# library's cylinder and mug (exported in their object frames by the Python package), each
# estimate a 2,000-evaluation budget; PSO, descent, annealing and firefly in 3 DoF, PSO in 4 DoF.
# Writes bench/results/touch_cpp.json. Env: BUILD_DIR (holds bench_touch), BAYESGRASP_PY (a Python
# with the package installed, as `make` leaves it in .venv).
source "$(dirname "$0")/env.sh"
"$BAYESGRASP_PY" -c "
import numpy as np
from bayesgrasp.planners.touch import canonical_object
for name in ('cylinder', 'mug'):
    m = canonical_object(name)
    with open(f'$R/touch_{name}.txt', 'w') as f:
        f.write(f'{len(m.vertices)} {len(m.faces)}\\n')
        np.savetxt(f, m.vertices, fmt='%.17g')
        np.savetxt(f, m.faces, fmt='%d')"
run_cpp_bench touch 3 --mesh=cylinder="$R/touch_cylinder.txt" --mesh=mug="$R/touch_mug.txt" "$@"
