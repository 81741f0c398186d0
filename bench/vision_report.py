"""Prints the registration comparison table from bench/results/vision_*.json and writes
bench/results/vision_registration.json."""
import json
import os

rows = []
for f in ("vision_ours.json", "vision_ours_noprior.json", "vision_ours_oneshot.json", "vision_open3d.json"):
    p = os.path.join("bench/results", f)
    if os.path.exists(p):
        rows.append(json.load(open(p))["summary"])
if rows:
    print(f"{'method':<78} {'views':>5} {'success':>8} {'median s':>9} {'feat':>7} {'global':>7} {'icp':>7}")
    for r in rows:
        print(f"{r['method']:<78} {r['views']:>5} {r['success_rate']:>8.3f} {r['median_time_s']:>9.4f} "
              f"{r.get('median_time_features', float('nan')):>7.4f} {r.get('median_time_global', float('nan')):>7.4f} "
              f"{r.get('median_time_icp', float('nan')):>7.4f}")
    o3d = [r for r in rows if r["method"].startswith("Open3D")]
    for r in rows:
        if o3d and r is not o3d[0]:
            print(f"speed-up of {r['method'][:40]}... over Open3D (median time): "
                  f"{o3d[0]['median_time_s'] / r['median_time_s']:.2f}x")
    json.dump(rows, open("bench/results/vision_registration.json", "w"), indent=1)
