#!/usr/bin/env bash
# Golden outputs (issues 33 and 34): the JSON of grasp, plan, category, fuse, touch, register and
# a small pub2, recorded before a change and compared after it (tests/golden/compare.py).
#   bash tests/golden/record.sh OUTDIR        (uses .venv/bin/bayesgrasp and the default model cache)
# Every command is seeded, so two recordings of one build are identical; a first run builds the
# models it needs (a few minutes from an empty cache).
set -euo pipefail
cd "$(dirname "$0")/../.."
OUT=${1:?usage: record.sh OUTDIR}
BG=${BAYESGRASP:-.venv/bin/bayesgrasp}
mkdir -p "$OUT"
run() {  # NAME ARGS...: stdout to OUT/NAME.json
  local name=$1; shift
  echo ">> golden: $name" >&2
  "$BG" "$@" > "$OUT/$name.json"
}
run grasp_mug        grasp --object mug --top 0,0,0.3 --object-pose 0.1,0,0.5 --json
run grasp_cube       grasp --object cube --top -0.01,0,0 --object-pose -0.05,0.02,-0.4 --json
run grasp_side       grasp --object cylinder --approach 1,0,0 --at 0,0,0.06 --json
run plan_mug2        plan --object mug2 --true-pose 0.03,-0.02,1.0 --method explore --json
run plan_pitcher     plan --object pitcher --true-pose 0.02,0,0.3 --families top,side --json
run touch_mug        touch --object mug --true-pose 0.01,-0.02,0.4 --estimate -0.01,0,0.6 --json
run touch_cube_size  touch --object cube --true-pose 0,0,0.3 --true-scale 1.1 --estimate 0.01,-0.01,0.5 --size --optimizer firefly --json
run register_mug3    register --scene-object mug/3 --object-pose 0.05,0,1.0 --models mug/0 mug/1 bottle/0 --json
run category_bottle  category --category bottle --task side --scene-object bottle/4 --object-pose 0,0,0.5 --method baseline --json
run category_mug     category --category mug --task handle --scene-object mug/3 --object-pose 0.02,-0.01,2.0 --json
run fuse_mug         fuse --category mug --task top --scene-object mug/3 --object-pose 0.01,0.02,0.7 --json
echo ">> golden: pub2 (2 runs)" >&2
rm -rf "$OUT/pub2"
"$BG" experiment pub2 --runs 2 --workers 1 --out "$OUT/pub2" > /dev/null
