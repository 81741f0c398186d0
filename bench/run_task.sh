#!/usr/bin/env bash
# Category task grasping (Eq. 4.1): (candidate, model grasp) pairs/s of the grasp mixture and the
# open hand's clearance checks, one thread (Google Benchmark, CPU time).
source "$(dirname "$0")/env.sh"
echo "--- C++: grasp mixture pairs/s, hand clearance poses/s"
run_cpp_bench task 5
echo "--- one category decision (registration against 6 mugs + Eq. 4.1 plan) and one tactile round, one core"
"$BAYESGRASP_PY" bench/category_decision.py --views 10
