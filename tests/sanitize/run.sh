#!/usr/bin/env bash
# `make sanitize`: the core, the bindings and the C++ tests under AddressSanitizer and
# UndefinedBehaviorSanitizer (issue 32), in their own build tree build/asan (kept between runs).
#   1. configure and build build/asan with -fsanitize=address,undefined (benchmarks off);
#   2. ctest there with leak checking on; lsan.supp holds third-party leaks only;
#   3. a fast Python subset on the sanitized module (the ASan runtime preloaded into the
#      interpreter, leak checking off for it): the fuzz tests at 25 cases, test_bad_input.py and
#      one test per binding module (SUBSET below).
# Any report fails the run (-fno-sanitize-recover=undefined; ASan aborts on its first error).
set -euo pipefail
cd "$(dirname "$0")/../.."
B=${ASAN_BUILD_DIR:-build/asan}
JOBS=${JOBS:-$(nproc 2>/dev/null || echo 2)}
PY=${PY:-.venv/bin/python}
SAN="-fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined"

GEN=()
if command -v ninja >/dev/null; then GEN=(-G Ninja)
elif [ -x .venv/bin/ninja ]; then GEN=(-G Ninja -DCMAKE_MAKE_PROGRAM="$PWD/.venv/bin/ninja"); fi

start=$(date +%s)
cmake -S . -B "$B" "${GEN[@]}" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DBAYESGRASP_BENCH=OFF \
  -DPython_EXECUTABLE="$PWD/$PY" \
  -DCMAKE_C_FLAGS="$SAN" -DCMAKE_CXX_FLAGS="$SAN" \
  -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined" -DCMAKE_SHARED_LINKER_FLAGS="-fsanitize=address,undefined" >/dev/null
cmake --build "$B" -j "$JOBS"
echo ">> sanitize: build $(( $(date +%s) - start )) s" >&2

export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
export LSAN_OPTIONS=suppressions=$PWD/tests/sanitize/lsan.supp:print_suppressions=0
ASAN_OPTIONS=detect_leaks=1:abort_on_error=1:strict_string_checks=1 \
  ctest --test-dir "$B" -j "$JOBS" --output-on-failure
echo ">> sanitize: ctest done at $(( $(date +%s) - start )) s" >&2

SUBSET=(
  tests/python/test_fuzz.py
  tests/python/test_bad_input.py
  tests/python/test_belief.py::test_uniform_weights_entropy_and_ess
  tests/python/test_objects.py::test_cube_mass_properties_are_analytic
  tests/python/test_gp.py::test_exact_matches_sklearn_with_fixed_hyperparameters
  tests/python/test_hand.py::test_builtin_hands_listed_and_loaded
  tests/python/test_optim.py::test_pso_python_callable_matches_cpp_builtin
  tests/python/test_physics.py::test_held_box_is_lifted_and_open_hand_leaves_it
  tests/python/test_quality.py::test_twelve_frictionless_contacts_hand_derived
  tests/python/test_sim.py::test_top_grasp_on_cylinder_matches_trigonometry
  tests/python/test_category.py::test_weights_split_the_mixture_and_the_baseline_takes_the_best_fitting_model
  tests/python/test_touch.py::test_the_truth_predicts_the_measured_readings
  tests/python/test_vision.py::test_plane_depth_matches_analytic
)
RT="$(gcc -print-file-name=libasan.so) $(gcc -print-file-name=libubsan.so)"
LD_PRELOAD="$RT" ASAN_OPTIONS=detect_leaks=0:abort_on_error=1 \
  BAYESGRASP_CORE_DIR="$PWD/$B/bayesgrasp_core" PYTHONPATH="$PWD/python" BAYESGRASP_FUZZ_EXAMPLES=25 \
  OMP_NUM_THREADS=2 "$PY" -m pytest -q -p no:cacheprovider "${SUBSET[@]}"
echo ">> sanitize: clean in $(( $(date +%s) - start )) s" >&2
