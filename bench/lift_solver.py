"""The lift test's solver settings against today's (issue 54, item 1): the same grasps lift-tested with
the default options and with each setting; per setting and object the verdicts that change, the
largest change of displacement and the median milliseconds per test on one thread. Grasps: the held
set of lift_residual.py (lift_torque_sweep.py's grid of top grasps, the first ``--grasps`` with
epsilon > 0, on the five Pub. II objects) and as many with the hand left open (the early-exit case).

A setting is ``name=key:value,key:value`` over LiftOptions fields (``;`` between settings), e.g.
``cache40=friction_direction_caching:1,warmstart_factor:1,solver_iterations:40``.

    OMP_NUM_THREADS=1 .venv/bin/python bench/lift_solver.py [--grasps 30] [--settings ...] [--json out.json]
"""
import argparse
import json
import sys
import time

import numpy as np

from bayesgrasp import physics
from bayesgrasp.world import World

sys.path.insert(0, __file__.rsplit("/", 1)[0])
from lift_torque_sweep import grasp_set, pieces_of  # noqa: E402

DEFAULT_SETTINGS = ("cache100=friction_direction_caching:1,warmstart_factor:1;"
                    "cache40=friction_direction_caching:1,warmstart_factor:1,solver_iterations:40;"
                    "cache30=friction_direction_caching:1,warmstart_factor:1,solver_iterations:30;"
                    "si40=solver_iterations:40")


def parse_settings(text: str) -> dict:
    """'name=k:v,k:v;name2=...' -> {name: {k: number or bool}}."""
    out = {}
    for part in filter(None, text.split(";")):
        name, _, body = part.partition("=")
        kw = {}
        for item in filter(None, body.split(",")):
            k, _, v = item.partition(":")
            kw[k] = bool(int(v)) if k in ("friction_direction_caching", "table") else (
                int(v) if k == "solver_iterations" else float(v))
        out[name] = kw
    return out


def run(w, pieces, H, Q, **kw):
    """Verdicts, displacements and per-test milliseconds (median of per-grasp CPU times)."""
    lt = physics.LiftTester(w.hand.path, w.vertices, w.faces, convex_pieces=pieces, mu=w.mu,
                            density=w.object.density, table=w.table, **kw)
    lifted, disp, ms = [], [], []
    for h, q in zip(H, Q):
        t0 = time.process_time()
        r = lt.run_batch(h[None], q[None], threads=1)
        ms.append(1e3 * (time.process_time() - t0))
        lifted.append(bool(r.lifted[0]))
        disp.append(float(r.displacement[0]))
    return np.array(lifted), np.array(disp), float(np.median(ms))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--objects", default="cube,cylinder,mug,mug2,pitcher")
    ap.add_argument("--grasps", type=int, default=30)
    ap.add_argument("--settings", default=DEFAULT_SETTINGS)
    ap.add_argument("--json", help="write the rows here too")
    a = ap.parse_args()
    settings = parse_settings(a.settings)
    rows = []
    print("| object | hand | setting | held (default -> setting) | verdicts changed | max displacement change, mm "
          "| ms/test (default -> setting) |")
    print("|---|---|---|---|---|---|---|")
    for name in a.objects.split(","):
        w = World.single(name)
        H, Q = grasp_set(w, a.grasps)
        open_q = np.array([w.hand.open_joints(q[0]) for q in Q])
        pieces = pieces_of(w)
        for kind, q in (("closed", Q), ("open", open_q)):
            base = run(w, pieces, H, q)
            for sname, kw in settings.items():
                r = run(w, pieces, H, q, **kw)
                dd = np.abs(r[1] - base[1])
                row = dict(object=name, hand=kind, setting=sname, options=kw, grasps=len(H),
                           held_default=int(base[0].sum()), held=int(r[0].sum()),
                           changed=int(np.sum(r[0] != base[0])),
                           max_displacement_change_mm=1e3 * float(np.max(dd[np.isfinite(dd)], initial=0.0)),
                           ms_default=base[2], ms=r[2])
                rows.append(row)
                print(f"| {name} | {kind} | {sname} | {row['held_default']} -> {row['held']} of {len(H)} | "
                      f"{row['changed']} | {row['max_displacement_change_mm']:.1f} | "
                      f"{base[2]:.1f} -> {r[2]:.1f} |", flush=True)
    if a.json:
        with open(a.json, "w") as f:
            json.dump(rows, f, indent=1)


if __name__ == "__main__":
    main()
