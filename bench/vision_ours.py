"""Our registration (bayesgrasp._core.vision.register_models) on the benchmark views, one model per
call (the view's own model), single thread. Usage: python bench/vision_ours.py [--up-prior 0|1]
Writes bench/results/vision_ours[_noprior].json."""
import argparse
import json
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(__file__))
from bayesgrasp import _core  # noqa: E402
from vision_common import errors, load_views, summarise  # noqa: E402


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--views", default="bench/results/vision_views.npz")
    ap.add_argument("--up-prior", type=int, default=1)
    ap.add_argument("--limit", type=int, default=0)
    a = ap.parse_args()
    views, models, voxel = load_views(a.views)
    if a.limit:
        views = views[:a.limit]
    rows = []
    for i, v in enumerate(views):
        m = models[v["model"]]
        t0 = time.perf_counter()
        r = _core.vision.register_models(v["points"], [(m["points"], m["normals"])], voxel=voxel, seed=i,
                                         viewpoint=v["eye"], up_prior=bool(a.up_prior), threads=1)[0]
        dt = time.perf_counter() - t0
        rot, tr = errors(np.asarray(r["transform"]), v["T_true"], m["axis"])
        rows.append(dict(view=i, model=m["name"], time=dt, rot_deg=rot, trans_m=tr,
                         success=bool(r["success"]) and rot < 10 and tr < 0.01, fitness=r["fitness"],
                         time_features=r["time_features"], time_global=r["time_global"], time_icp=r["time_icp"]))
    name = "ours (PCL FPFH + seeded RANSAC " + ("4-DOF, up prior" if a.up_prior else "6-DOF, no prior") + " + ICP)"
    s = summarise(name, rows)
    out = "bench/results/vision_ours%s.json" % ("" if a.up_prior else "_noprior")
    with open(out, "w") as f:
        json.dump({"summary": s, "rows": rows}, f, indent=1)
    print(json.dumps(s))


if __name__ == "__main__":
    main()
