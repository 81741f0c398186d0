#!/usr/bin/env bash
# CPU seconds, wall seconds and peak memory of compiling one translation unit of the package's core,
# with the build's own command (from build/py's ninja file; run `make` once first). Issue 54, item 5.
#   bash bench/compile_time.sh cpp/bayesgrasp/vision/segmentation.cpp [more .cpp files]
# The object goes to a temporary file; the build tree is not touched.
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
BUILD=${BUILD_DIR:-$ROOT/build/py}
NINJA=$ROOT/.venv/bin/ninja; [ -x "$NINJA" ] || NINJA=ninja
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
printf '%-50s %8s %8s %8s\n' "file" "cpu_s" "wall_s" "peak_MB"
for f in "$@"; do
  src=$(cd "$(dirname "$f")" && pwd)/$(basename "$f")
  cmd=$("$NINJA" -C "$BUILD" -t commands _core.cpython-311-x86_64-linux-gnu.so | grep -F -- "-c $src" | head -1)
  [ -n "$cmd" ] || { echo "compile_time: $f is not compiled into _core" >&2; exit 2; }
  cmd=$(sed -E "s# -o [^ ]+# -o $TMP/out.o#; s# -MF [^ ]+# -MF $TMP/out.d#" <<< "$cmd")
  (cd "$BUILD" && /usr/bin/time -o "$TMP/t" -f '%U %S %e %M' bash -c "$cmd" > /dev/null 2>&1)
  read -r u s e m < "$TMP/t"
  awk -v f="$f" -v u="$u" -v s="$s" -v e="$e" -v m="$m" 'BEGIN { printf "%-50s %8.1f %8.1f %8.0f\n", f, u + s, e, m / 1024 }'
done
