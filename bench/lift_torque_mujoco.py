"""The lift test's torque sweep checked in MuJoCo: exported grasps (bench/lift_heldset.py's .npz)
replayed by bench/lift_mujoco.py's model at each finger torque and at the hand's own.

Columns: each torque of ``--torques`` (N m, the limit at every driven joint) and ``hand``: the hand
file's torque_nm per joint (the BH8: 1.467 N m proximal, 1.1 N m distal). Per file (object and
grasp source) it counts the grasps MuJoCo lifts (lift_mujoco.py's verdict: rose >= 8 cm and moved
< 2 cm in the palm frame through the shake and hold) and, when the export has them
(``lift_heldset.py --sweep-torques``, the same torques), ours and the agreement per torque.

    .venv-bench/bin/python bench/lift_torque_mujoco.py bench/results/heldset/cube_top.npz \\
        --torques 0.25,0.5,1,2,3 --max-grasps 20 --out bench/results/lift_torque_mujoco.json

Arguments are .npz files or directories of them.
"""
import argparse
import glob
import json
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import lift_mujoco as lm  # noqa: E402  (the model, the replay and the export's loader)


def files_of(paths):
    out = []
    for p in paths:
        out += sorted(glob.glob(os.path.join(p, "*.npz"))) if os.path.isdir(p) else [p]
    return out


def ours_at(z, torque):
    """Our verdicts at `torque` ("hand": the hand file's) from the export's sweep, or None."""
    if "sweep_torques" not in z:
        if torque == "hand" and "finger_torque" in z and float(z["finger_torque"]) == 0.0:
            return np.asarray(z["lifted"], bool)  # the export's own verdicts are at the hand's torques
        return None
    t = 0.0 if torque == "hand" else float(torque)
    k = np.flatnonzero(np.isclose(z["sweep_torques"], t, rtol=0, atol=1e-9))
    return np.asarray(z["sweep_lifted"][k[0]], bool) if len(k) else None


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("heldset", nargs="+", help=".npz files of bench/lift_heldset.py, or directories of them")
    ap.add_argument("--torques", default="0.25,0.5,1,2,3", help="N m, comma-separated (the hand's own are added)")
    ap.add_argument("--max-grasps", type=int, default=0, help="per file (0: all)")
    ap.add_argument("--timestep", type=float, default=0.001)
    ap.add_argument("--contact-solref", type=float, default=None, metavar="S",
                    help="contacts' solref time constant in s (default: MuJoCo's 0.02; e.g. 0.002 = 2 steps, stiff)")
    ap.add_argument("--out", default=None, help="JSON file for the counts and per-grasp verdicts")
    a = ap.parse_args()
    try:
        torques = [float(t) for t in a.torques.split(",") if t.strip()]
    except ValueError:
        ap.error(f"--torques: expected comma-separated numbers, got {a.torques!r}")
    if any(not (np.isfinite(t) and t > 0) for t in torques):
        ap.error("--torques: torques must be > 0")
    columns = torques + ["hand"]
    if a.contact_solref is not None:
        if not a.contact_solref > 0:
            ap.error("--contact-solref: must be > 0")
        lm.CONTACT_SOLREF = a.contact_solref
    paths = files_of(a.heldset)
    if not paths:
        ap.error("no .npz files found")
    out = {"torques": columns, "timestep": a.timestep, "files": {}}
    t0 = time.time()
    for path in paths:
        z, hand = lm.load(path)
        n = len(z["lifted"]) if a.max_grasps <= 0 else min(a.max_grasps, len(z["lifted"]))
        res = {"object": str(z["name"]), "grasps": n, "mujoco_held": [], "ours_held": [], "agree": [],
               "mujoco_lifted": [], "ours_lifted": []}
        for t in columns:
            mj = [lm.replay(z, g, hand, a.timestep, finger_torque=0.0 if t == "hand" else t)["lifted"]
                  for g in range(n)]
            our = ours_at(z, t)
            our = None if our is None else our[:n]
            res["mujoco_held"].append(int(sum(mj)))
            res["mujoco_lifted"].append([bool(x) for x in mj])
            res["ours_held"].append(None if our is None else int(our.sum()))
            res["ours_lifted"].append(None if our is None else [bool(x) for x in our])
            res["agree"].append(None if our is None else int(np.sum(our == np.asarray(mj, bool))))
            print(f"{os.path.basename(path)}: torque {t}: MuJoCo held {sum(mj)}/{n}"
                  + ("" if our is None else f", ours {int(our.sum())}, agree {res['agree'][-1]}")
                  + f" ({time.time() - t0:.0f} s)", file=sys.stderr, flush=True)
        out["files"][os.path.basename(path)] = res
    head = " ".join(f"{str(t):>6}" for t in columns)
    print(f"{'file':24s} {'grasps':>6}  held at torque (N m): {head}")
    for f, r in out["files"].items():
        print(f"{f:24s} {r['grasps']:6d}  MuJoCo               " + " ".join(f"{x:6d}" for x in r["mujoco_held"]))
        if any(x is not None for x in r["ours_held"]):
            print(f"{'':24s} {'':6s}  ours                 "
                  + " ".join(f"{'-' if x is None else x:>6}" for x in r["ours_held"]))
            print(f"{'':24s} {'':6s}  agree                "
                  + " ".join(f"{'-' if x is None else x:>6}" for x in r["agree"]))
    if a.out:
        os.makedirs(os.path.dirname(a.out) or ".", exist_ok=True)
        with open(a.out, "w") as f:
            json.dump(out, f, indent=1)


if __name__ == "__main__":
    main()
