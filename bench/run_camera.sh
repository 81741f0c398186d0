#!/usr/bin/env bash
# Camera data in (issue 26): a 640x480 depth PNG to the object's cloud in the table frame, ours vs
# the same steps as direct Open3D calls, on one core; then registration from sensor-like depth
# images vs from the simulated camera, on the same views (14 objects x 20 viewpoints).
source "$(dirname "${BASH_SOURCE[0]}")/env.sh"
taskset -c 0 "$BAYESGRASP_PY" bench/camera_pipeline.py --reps 40 --out "$R/camera_pipeline.json"
"$BAYESGRASP_PY" bench/camera_registration.py --views-per-object "${CAMERA_VIEWS:-20}" --threads 2 \
  --out "$R/camera_registration.json"
