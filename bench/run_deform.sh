#!/usr/bin/env bash
# Non-rigid registration: our CPD (C++ core, Nystrom low rank) against pycpd and probreg on the
# same clouds (a held-out mug's view and another mug registered onto it), one thread each.
# Env: BAYESGRASP_PY (python with bayesgrasp), BENCH_PY (peers).
source "$(dirname "$0")/env.sh"
DATA=$R/deform_data
echo ">> clouds (seeded): 6 mug views, another mug's 800 surface samples registered onto each"
"$BAYESGRASP_PY" bench/deform_peers.py data "$DATA"
echo ">> ours (BAYESGRASP_PY)"
"$BAYESGRASP_PY" bench/deform_peers.py ours "$DATA" "$R/deform_ours.json"
echo ">> peers: pycpd, probreg (BENCH_PY)"
"$BENCH_PY" bench/deform_peers.py peers "$DATA" "$R/deform_peers.json" "$R/deform_ours.json"
"$BAYESGRASP_PY" bench/deform_peers.py report "$R/deform_ours.json" "$R/deform_peers.json" | tee "$R/deform_report.md"
