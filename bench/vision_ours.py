"""Our registration on the benchmark views, one model per call (the view's own model), single
thread. With --registrar 1 (the default) the models are prepared once in a
bayesgrasp._core.vision.Registrar before the timed calls (radius grid over the dense samples,
downsampled cloud, normals, FPFH), as bench/vision_open3d.py --model-cache 1 does for Open3D, and each
timed call does only the per-view work; --registrar 0 times one-shot register_models calls that prepare the model inside.
--pcl-features 1 uses PCL's normal and FPFH estimators instead of ours (same definitions).
Usage: python bench/vision_ours.py [--up-prior 0|1] [--registrar 0|1] [--pcl-features 0|1]
Writes bench/results/vision_ours[_noprior][_oneshot].json (or --out)."""
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
    ap.add_argument("--registrar", type=int, default=1)
    ap.add_argument("--pcl-features", type=int, default=0, help="PCL's normals + FPFH instead of ours")
    ap.add_argument("--limit", type=int, default=0)
    ap.add_argument("--out", default="")
    a = ap.parse_args()
    views, models, voxel = load_views(a.views)
    if a.limit:
        views = views[:a.limit]
    V = _core.vision
    samples = [(m["points"], m["normals"]) for m in models]
    options = V.RegistrationOptions(voxel=voxel, threads=1)
    options.up_prior.enabled = bool(a.up_prior)
    options.features.estimator = V.FeatureEstimator.Pcl if a.pcl_features else V.FeatureEstimator.Ours
    t0 = time.perf_counter()
    reg = V.Registrar(options, samples) if a.registrar else None
    t_prepare = time.perf_counter() - t0
    rows = []
    for i, v in enumerate(views):
        m = models[v["model"]]
        t0 = time.perf_counter()
        if reg is not None:
            r = reg.register(v["points"], seed=i, viewpoint=v["eye"], models=[v["model"]])[0]
        else:
            r = V.register_models(v["points"], [samples[v["model"]]], options, seed=i, viewpoint=v["eye"])[0]
        dt = time.perf_counter() - t0
        rot, tr = errors(np.asarray(r.transform), v["T_true"], m["axis"])
        rows.append(dict(view=i, model=m["name"], time=dt, rot_deg=rot, trans_m=tr,
                         success=r.success and rot < 10 and tr < 0.01, fitness=r.fitness,
                         time_features=r.time_features, time_global=r.time_global, time_icp=r.time_icp))
    name = "ours (" + ("PCL" if a.pcl_features else "own") + " FPFH + seeded RANSAC " + ("4-DOF, up prior" if a.up_prior else "6-DOF, no prior") + " + ICP" \
        + (", models prepared once)" if a.registrar else ", one-shot)")
    s = summarise(name, rows)
    if reg is not None:
        s["model_preparation_s"] = t_prepare
    out = a.out or "bench/results/vision_ours%s%s.json" % ("" if a.up_prior else "_noprior",
                                                          "" if a.registrar else "_oneshot")
    with open(out, "w") as f:
        json.dump({"summary": s, "rows": rows}, f, indent=1)
    print(json.dumps(s))


if __name__ == "__main__":
    main()
