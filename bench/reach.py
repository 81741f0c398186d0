"""Reachability per grasp candidate (issue 57), one core: the batched check of bayesgrasp.arm
against its peer, pinocchio's own closed-loop IK (CLIK) called one candidate at a time from Python.

The scene: the shipped KUKA LBR4+ with the Barrett BH8 on its flange (the default mount), its base
0.6 m behind the table's origin; the built-in mug at the origin; 64 candidates a planner asks for
at once: top grasps (approach straight down) and side grasps (horizontal approach) around the mug,
positions, heights and yaws drawn from a seeded generator.

Rows, all medians over ``--repeats`` runs of the same 64 candidates, the three run in turn in each
repeat (so that they see the same load on a shared machine):

* ``ours, full check``: check_reach: IK of the grasp (8 starts), the pre-grasp 0.1 m back and the
  approach between them at 5 steps, the arm's links against the table and the mug;
* ``ours, grasp IK only``: the same batched damped least squares on the grasp poses alone, from the
  same starts (each grasp's 8 nearest entries of the start library: the nearest first, then the
  other 7 at once for the unconverged);
* ``peer, pinocchio CLIK``: for each candidate in a Python loop, pinocchio's forward kinematics,
  frame Jacobian and SE(3) log (error e = log(oMf^-1 oMdes), J <- -Jlog6 J, v = -J^T (J J^T +
  lambda^2 I)^-1 e, q <- integrate(q, v), clipped to the limits), from the same starts in turn
  until one converges, with the same tolerances, damping, step and iteration cap: the grasp IK only.

    OMP_NUM_THREADS=1 taskset -c 0 python bench/reach.py [--candidates 64] [--repeats 9]
"""
import argparse
import json
import statistics
import sys
import time

import numpy as np
from scipy.spatial.transform import Rotation

from bayesgrasp.arm import Arm, ReachOptions, check_reach, default_mount
from bayesgrasp.arm.ik import solve_ik
from bayesgrasp.arm.starts import nearest_starts
from bayesgrasp.hand import Hand
from bayesgrasp.objects import load_object


def candidates(mug, n: int, seed: int = 0) -> np.ndarray:
    """n palm poses about the mug: half top grasps (palm z = -z), half side grasps (palm z
    horizontal, towards the mug's axis), each with a random yaw about its approach."""
    rng = np.random.default_rng(seed)
    lo, hi = np.asarray(mug.bounds)
    P = np.tile(np.eye(4), (n, 1, 1))
    for i in range(n):
        roll = rng.uniform(-np.pi, np.pi)
        if i % 2 == 0:   # top: above the mug's top, approaching down
            R = Rotation.from_euler("z", roll).as_matrix() @ np.diag([1.0, -1.0, -1.0])
            p = [rng.uniform(lo[0], hi[0]), rng.uniform(lo[1], hi[1]), hi[2] + rng.uniform(0.0, 0.03)]
        else:            # side: from a direction about the mug, at a height on it
            a = rng.uniform(-np.pi, np.pi)
            z = -np.array([np.cos(a), np.sin(a), 0.0])            # approach towards the axis
            x = np.array([0.0, 0.0, 1.0])
            R = np.column_stack([x, np.cross(z, x), z]) @ Rotation.from_euler("z", roll).as_matrix()
            r = 0.5 * (hi[0] - lo[0]) + 0.02
            p = [-r * z[0], -r * z[1], rng.uniform(0.3, 0.8) * hi[2]]
        P[i, :3, :3], P[i, :3, 3] = R, p
    return P


def peer_clik(arm: Arm, P: np.ndarray, starts: np.ndarray, opt: ReachOptions):
    """pinocchio's CLIK for the flange frame, one candidate at a time. Returns converged (n,)."""
    import pinocchio as pin

    model, data = arm.model, arm.model.createData()
    fid = model.getFrameId(arm.flange)
    base_inv, mount_inv = np.linalg.inv(arm.base), np.linalg.inv(arm.mount)
    lo, hi = model.lowerPositionLimit, model.upperPositionLimit
    ok = np.zeros(len(P), dtype=bool)
    for i in range(len(P)):
        target = pin.SE3(base_inv @ P[i] @ mount_inv)   # the flange's pose in the arm's root frame
        for s in starts[i]:
            q = arm.pin_q(s)
            for _ in range(opt.iterations + 1):
                pin.framesForwardKinematics(model, data, q)
                iMd = data.oMf[fid].actInv(target)
                e = pin.log(iMd).vector
                # the palm's error: the flange's position error moved to the palm is within the tolerance
                # when the flange's is (same rotation error; mount offset 0.06 m adds <= 0.06 * angle)
                if np.linalg.norm(e[:3]) <= opt.tol_position and np.linalg.norm(e[3:]) <= opt.tol_rotation:
                    ok[i] = True
                    break
                J = pin.computeFrameJacobian(model, data, q, fid)
                J = -pin.Jlog6(iMd.inverse()) @ J
                v = -J.T @ np.linalg.solve(J @ J.T + opt.damping ** 2 * np.eye(6), e)
                v *= min(1.0, opt.max_step / max(np.abs(v).max(), 1e-12))
                q = np.clip(pin.integrate(model, q, v), lo, hi)
            if ok[i]:
                break
    return ok


def ours_ik_only(arm: Arm, P: np.ndarray, starts: np.ndarray, opt: ReachOptions):
    """check_reach's step 1 alone: the nearest start for every grasp, then the others at once."""
    kw = dict(iterations=opt.iterations, damping=opt.damping, max_step=opt.max_step,
              tol_position=opt.tol_position, tol_rotation=opt.tol_rotation)
    ok = solve_ik(arm, P, starts[:, 0], **kw).converged
    rest = np.flatnonzero(~ok)
    if rest.size:
        cand = np.repeat(rest, starts.shape[1] - 1)
        sol = solve_ik(arm, P[cand], starts[rest, 1:].reshape(-1, arm.dof), **kw)
        ok[np.unique(cand[sol.converged])] = True
    return ok


def interleaved(fs, repeats: int):
    """Median seconds of each function, run in turn repeats times (each round sees the same load)."""
    times, outs = [[] for _ in fs], [None] * len(fs)
    for _ in range(repeats):
        for k, f in enumerate(fs):
            t = time.perf_counter()
            outs[k] = f()
            times[k].append(time.perf_counter() - t)
    return [statistics.median(t) for t in times], outs


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--candidates", type=int, default=64)
    p.add_argument("--repeats", type=int, default=9)
    p.add_argument("--out", default="", help="also write the figures to this JSON file")
    a = p.parse_args(argv)
    arm = Arm.load("kuka_lbr4", base=(-0.6, 0.0, 0.0, 0.0), mount=default_mount(Hand.load("barrett_bh8")))
    mug = load_object("mug")
    P = candidates(mug, a.candidates)
    opt = ReachOptions()
    starts = nearest_starts(arm, P, opt.seeds, opt.seed)    # (n, seeds, dof), the same for all three
    check_reach(arm, P[:4], (mug.vertices, mug.faces), opt)   # warm-up (imports, first calls)
    (t_full, t_ik, t_peer), (res, ik_ok, peer_ok) = interleaved(
        [lambda: check_reach(arm, P, (mug.vertices, mug.faces), opt), lambda: ours_ik_only(arm, P, starts, opt),
         lambda: peer_clik(arm, P, starts, opt)], a.repeats)
    n = len(P)
    rows = [("ours, full check (grasp + pre-grasp + approach + collisions)", t_full, int(res.reachable.sum())),
            ("ours, grasp IK only", t_ik, int(ik_ok.sum())),
            ("peer, pinocchio CLIK one candidate at a time (grasp IK only)", t_peer, int(peer_ok.sum()))]
    print(f"{n} candidates (top and side grasps on the mug), KUKA LBR4+ at (-0.6, 0, 0, 0), BH8 mounted; "
          f"medians of {a.repeats} runs", file=sys.stderr)
    print("| method | ms per candidate | ms per call | candidates solved |")
    print("|---|---|---|---|")
    for name, t, k in rows:
        print(f"| {name} | {1e3 * t / n:.3f} | {1e3 * t:.1f} | {k} of {n} |")
    reasons = {r: res.reason.count(r) for r in sorted(set(res.reason))}
    print(f"\nfull check's reasons: {reasons}; grasp IK agreement ours/peer: "
          f"{int(np.sum(ik_ok == peer_ok))} of {n}; speed-up of our grasp IK over the peer: {t_peer / t_ik:.1f}x")
    if a.out:
        with open(a.out, "w") as f:
            json.dump({"candidates": n, "repeats": a.repeats, "rows": [{"method": m, "seconds": t, "solved": k}
                                                                        for m, t, k in rows],
                       "reasons": reasons}, f, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
