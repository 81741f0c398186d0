"""Fewer lift tests for the same models (issue 54, item 2): the P(S) calibration fitted on
n_calibration fresh simulated, lift-tested grasps (today's "held_out") or on the training grasps'
own lift outcomes scored out of fold ("cross_fit", no further lift test). Per object: lift tests
and wall seconds of the build, the calibration, and how well each model's P(S) predicts a judge
set of ``--judge`` fresh grasps lift-tested (seed offset 5; log loss, Brier score, and the judge
set's success rate among the grasps each model rates P(S) > 0.5). Every build from an empty cache.

    OMP_NUM_THREADS=1 .venv/bin/python bench/calibration_crossfit.py [--objects cube,mug,pitcher] [--judge 500]
"""
import argparse
import json
import tempfile
import time
from dataclasses import replace

import numpy as np

from bayesgrasp.models import ModelSettings, build_models
from bayesgrasp.models import training
from bayesgrasp.models.families import Variant
from bayesgrasp.world import World

COUNT = [0]


def counted(real):
    def wrap(variant, world, rel, say=None):
        COUNT[0] += len(rel)
        return real(variant, world, rel, say)
    return wrap


def judge_set(world, models, settings, n):
    """n fresh grasps of the models' variant (seed offset 5) and their lift outcomes."""
    variant = Variant(**models.info["variant"])
    rel, _, _ = training.simulate_training_data(world, settings, seed_offset=5, n=n, spread=variant)
    return rel, training.lift_outcomes(world, rel, variant)


def scores(models, rel, lifted):
    p = np.clip(models.stability_probability(rel), 1e-6, 1 - 1e-6)
    y = lifted.astype(float)
    rated = p > 0.5
    return {"log_loss": float(-np.mean(y * np.log(p) + (1 - y) * np.log(1 - p))),
            "brier": float(np.mean((p - y) ** 2)),
            "rated_above_half": int(rated.sum()),
            "success_when_rated_above_half": float(y[rated].mean()) if rated.any() else None,
            "mean_p": float(p.mean()), "judge_success_rate": float(y.mean())}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--objects", default="cube,mug,pitcher")
    ap.add_argument("--judge", type=int, default=500)
    ap.add_argument("--json", default=None)
    a = ap.parse_args()
    training.lifted_in_chunks = counted(training.lifted_in_chunks)
    rows = []
    print("| object | calibration | lift tests | build s | (a, b) | log loss | Brier | judged P(S)>0.5: lifted share (n) |")
    print("|---|---|---|---|---|---|---|---|")
    for name in a.objects.split(","):
        world = World.single(name, pose=(0.0, 0.0, 0.0))
        built = {}
        for cal in ("held_out", "cross_fit"):
            settings = replace(ModelSettings(), calibration=cal)
            COUNT[0] = 0
            with tempfile.TemporaryDirectory(prefix="calib-") as d:
                t0 = time.perf_counter()
                built[cal] = (build_models(name, settings=settings, cache_dir=d), COUNT[0], time.perf_counter() - t0)
        rel, lifted = judge_set(world, built["held_out"][0], ModelSettings(), a.judge)
        for cal, (m, n_lift, secs) in built.items():
            s = scores(m, rel, lifted)
            row = dict(object=name, calibration=cal, lift_tests=n_lift, build_s=secs,
                       calibration_ab=m.info["calibration"], **s)
            rows.append(row)
            ab = ", ".join(f"{v:.2f}" for v in m.info["calibration"])
            share = "-" if s["success_when_rated_above_half"] is None else f"{s['success_when_rated_above_half']:.2f}"
            print(f"| {name} | {cal} | {n_lift} | {secs:.0f} | ({ab}) | {s['log_loss']:.3f} | {s['brier']:.3f} | "
                  f"{share} ({s['rated_above_half']}) |", flush=True)
    if a.json:
        with open(a.json, "w") as f:
            json.dump(rows, f, indent=1)


if __name__ == "__main__":
    main()
