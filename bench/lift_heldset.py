"""Exports closed grasps with our lift test's verdicts for an independent replay (bench/lift_mujoco.py).

Grasps (all closed by our contact simulator, kept when force closure: epsilon > 0, no collision
at the start):
  * top grasps on a grid (x, y over the object's footprint, 8 yaws) on the five Pub. II objects
    (cube, cylinder, mug, mug2, pitcher), ``--per-object`` drawn at random from the force-closure ones;
  * random approaches on category objects (mug/0..6, bottle/0..10): directions from the side and
    above, aimed near the object's centre with random roll, ``--per-category-object`` each.
Per object one ``.npz`` (no pickle) in ``--out``: the mesh, convex pieces (concave objects), mass
properties, friction and density, the hand's link shapes and joints, and per grasp the hand pose,
closed joints, link poses, our verdict (lifted) and its quantities (hold_displacement: moved in
the palm frame from the end of the lift to the end; height_gain: the centre of mass's world rise),
displacement (after the squeeze to the end), shape used and breakaway state; the lift options'
finger_torque (0: the hand file's torque_nm). ``--sweep-torques 0.25,0.5,1,2,3`` also stores our
verdicts at each torque (every driven joint) and at the hand's own (sweep_torques, sweep_lifted
(T, N); the last row "hand"), for bench/lift_torque_mujoco.py. ``--objects`` restricts the objects
(names of both lists; the random picks of the later objects then differ). With ``--held-share N``
it also prints the held share of N force-closure top grasps per Pub. II object.
``--executed DIR,...`` adds the grasps the planners executed in stored experiments (each DIR an
experiment's output with its results.sqlite): ``pub2`` attempts per grasp family (sources
``executed_top`` / ``executed_side``, re-closed from the attempt's relative grasp and variant)
and category task grasps of mugs and bottles (``executed_category``, re-closed along the stored
hand pose in the object's frame); every executed grasp that touched the object without starting
in collision (force closure or not: the lift test decides those too), at most ``--per-executed``
per object and source, and our re-closed verdict is checked against the stored one.

    BAYESGRASP_CORE_DIR=build/dev/bayesgrasp_core PYTHONPATH=python python bench/lift_heldset.py --out bench/results/heldset
"""
import argparse
import json
import os
import sys
import time

import sqlite3
from types import SimpleNamespace

import numpy as np

from bayesgrasp import physics
from bayesgrasp.hand import Hand
from bayesgrasp.models import Variant
from bayesgrasp.world import World

PUB2 = ["cube", "cylinder", "mug", "mug2", "pitcher"]
CATEGORY = [f"mug/{i}" for i in range(7)] + [f"bottle/{i}" for i in range(11)]


def top_grid(w, n_xy=9):
    lo, hi = w.object.vertices.min(0), w.object.vertices.max(0)
    xs, ys = np.linspace(lo[0], hi[0], n_xy), np.linspace(lo[1], hi[1], n_xy)
    yaws = np.radians(np.arange(0, 180, 22.5))
    return np.array([[x, y, t] for x in xs for y in ys for t in yaws])


def approaches(w, n, rng):
    """n random approaches (object frame): directions with z <= 0.3 (side to top-down)."""
    lo, hi = w.object.vertices.min(0), w.object.vertices.max(0)
    centre = 0.5 * (lo + hi)
    d = rng.normal(size=(4 * n, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    d = d[d[:, 2] <= 0.3][:n]
    if len(d) < n:
        d = np.vstack([d, np.tile([0.0, 0.0, -1.0], (n - len(d), 1))])
    targets = centre + rng.uniform(-0.3, 0.3, size=(n, 3)) * (hi - lo)
    rolls = rng.uniform(0, np.pi, size=n)
    return d, targets, rolls


def force_closure(b):
    return np.flatnonzero((np.asarray(b.epsilon) > 0) & ~np.asarray(b.collision_at_start, bool))


def _stored_runs(result_dir):
    db = sqlite3.connect(f"file:{os.path.join(result_dir, 'results.sqlite')}?mode=ro", uri=True)
    try:
        return [(e, o, json.loads(t)) for e, o, t in db.execute("SELECT experiment, object, result FROM runs")]
    finally:
        db.close()


def executed_grasps(result_dirs):
    """{(object, source): [(kind, data, stored lifted)]}: pub2 attempts ("rel", (relative grasp,
    variant dict)) and category task grasps of table-standing objects ("pose", (4x4 hand pose in
    the object's frame, spread)), from stored runs."""
    out = {}
    for d in result_dirs:
        for exp, obj, r in _stored_runs(d):
            for a in r.get("attempts", []):
                if "variant" in a and a.get("lifted") is not None:
                    out.setdefault((obj, f"executed_{a['family']}"), []).append(
                        ("rel", (a["relative_grasp"], a["variant"]), bool(a["lifted"])))
            if "tasks" in r and obj.split("/")[0] in ("mug", "bottle"):
                T = World.single(obj, pose=tuple(r["pose"])).scene.object_pose(0)
                for methods in r["tasks"].values():
                    for g in methods.values():
                        if g.get("executed") and g.get("lifted") is not None:
                            H = np.linalg.solve(T, np.asarray(g["hand_pose"], float))
                            out.setdefault((obj, "executed_category"), []).append(("pose", (H, g["spread"]),
                                                                                   bool(g["lifted"])))
    return out


def reclose(w, items):
    """The stored grasps closed again in ``w`` (object at pose 0): a batch-like namespace with
    hand_pose, joint_angles, epsilon, collision_at_start, lifted (ours, re-tested)."""
    T0 = w.scene.object_pose(w.object_index)
    rows = []
    for kind, data, _ in items:
        if kind == "rel":
            rel, variant = data
            g = Variant(**variant).grasp(w, rel, lift=True)
        else:
            H = T0 @ data[0]
            g = w.approach(H[:3, 2], H[:3, 3], Hand.approach_roll(H), spread=data[1], frame="world", lift=True)
        rows.append(g)
    return SimpleNamespace(hand_pose=np.array([g.hand_pose for g in rows]),
                           joint_angles=np.array([g.joint_angles for g in rows]),
                           epsilon=np.array([g.epsilon for g in rows]),
                           collision_at_start=np.array([g.collision_at_start for g in rows], bool),
                           lifted=np.array([bool(g.lifted) for g in rows]),
                           touched=np.array([any(not c.on_table for c in g.contacts) for g in rows], bool))


def export(w, name, b, idx, source, out, sweep=()):
    tester = w.lift_tester()
    P, J = b.hand_pose[idx], b.joint_angles[idx]
    r = tester.run_batch(P, J, threads=1)
    br = np.array([tester.run(P[i], J[i]).breakaway for i in range(len(idx))]) if len(idx) else np.zeros((0, 3))
    hand = w.hand
    L = hand.num_links
    links = np.array([hand.link_poses(J[i], P[i]) for i in range(len(idx))]).reshape(len(idx), L, 4, 4)
    obj, T = w.object, w.scene.object_pose(w.object_index)
    pieces = []
    if tester.num_pieces > 0:
        pieces = [p @ T[:3, :3].T + T[:3, 3] for p in physics.convex_decomposition(obj.vertices, obj.faces)]
    sweep_lifted = []  # our verdicts at each torque of the sweep, then at the hand file's (0)
    for t in (list(sweep) + [0.0]) if sweep else []:
        st = physics.LiftTester(w.hand.path, w.vertices, w.faces, convex_pieces=pieces or None, mu=w.mu,
                                density=obj.density, table=w.table, finger_torque=float(t))
        sweep_lifted.append(np.asarray(st.run_batch(P, J, threads=1).lifted, bool))
    shapes = []  # per link: type (0 box, 1 capsule), center, half_extents, p0, p1, radius
    for li, ss in enumerate(hand.link_shapes()):
        for s in ss:
            shapes.append([li, 1 if s.type == "capsule" else 0, *np.asarray(s.center), *np.asarray(s.half_extents),
                           *np.asarray(s.p0), *np.asarray(s.p1), float(s.radius)])
    core = hand.core
    fingers = []
    for f, links_f in enumerate(core.phalanx_links):
        fingers.append(list(links_f))
    m = tester._t
    data = dict(
        name=np.array(name), source=np.array([source] * len(idx)),
        V=w.vertices, F=np.asarray(w.faces), num_pieces=np.array(len(pieces)),
        mass=np.array(m.mass), com=np.asarray(m.com), mu=np.array(w.mu), density=np.array(obj.density),
        hand_pose=P, joints=J, link_poses=links, lifted=np.asarray(r.lifted), displacement=np.asarray(r.displacement),
        hold_displacement=np.asarray(r.hold_displacement), height_gain=np.asarray(r.height_gain),
        finite=np.asarray(r.finite), finger_torque=np.array(float(physics.make_options().finger_torque)),  # World.lift_tester's
        shape=np.array(r.shape), breakaway=br, epsilon=np.asarray(b.epsilon)[idx],
        link_shapes=np.array(shapes, float), joint_limits=np.asarray(hand.joint_limits),
        finger_links=np.array(fingers, int), link_names=np.array(hand.links),
        hand_json=np.array(open(hand.path).read()),
    )
    if sweep:
        data["sweep_torques"] = np.array([float(t) for t in sweep] + [0.0])  # 0: the hand file's
        data["sweep_lifted"] = np.array(sweep_lifted, bool).reshape(len(sweep) + 1, len(idx))
    for i, p in enumerate(pieces):
        data[f"piece_{i}"] = p
    safe = name.replace("/", "_")
    path = os.path.join(out, f"{safe}_{source}.npz")
    np.savez(path, **data)
    return r


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--out", default="bench/results/heldset")
    ap.add_argument("--per-object", type=int, default=40)
    ap.add_argument("--per-category-object", type=int, default=10)
    ap.add_argument("--held-share", type=int, default=0,
                    help="also print the held share of N force-closure top grasps per Pub. II object (a finer grid)")
    ap.add_argument("--held-share-only", action="store_true", help="only the held shares, no export")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--objects", default=None,
                    help="comma-separated objects to export (default: all; e.g. cube,mug/0)")
    ap.add_argument("--executed", default="",
                    help="comma-separated experiment output directories whose executed grasps to add")
    ap.add_argument("--per-executed", type=int, default=40, help="executed grasps per object and source at most")
    ap.add_argument("--sweep-torques", default="",
                    help="N m, comma-separated: also store our verdicts at each torque and the hand's (e.g. 0.25,0.5,1,2,3)")
    a = ap.parse_args()
    sweep = [float(t) for t in a.sweep_torques.split(",") if t.strip()]
    if any(not (np.isfinite(t) and t > 0) for t in sweep):
        ap.error("--sweep-torques: torques must be > 0")
    wanted = None if a.objects is None else [o.strip() for o in a.objects.split(",") if o.strip()]
    unknown = [o for o in wanted or [] if o not in PUB2 + CATEGORY]
    if unknown:
        ap.error(f"--objects: unknown {unknown} (known: {PUB2 + CATEGORY})")
    os.makedirs(a.out, exist_ok=True)
    rng = np.random.default_rng(a.seed)
    total, summary = 0, {}
    for name in PUB2:
        if wanted is not None and name not in wanted:
            continue
        t0 = time.time()
        w = World.single(name)
        b = w.grasp_batch(top_grid(w), threads=0)
        fc = force_closure(b)
        if a.held_share:
            hb = w.grasp_batch(top_grid(w, 15), threads=0)
            hfc = force_closure(hb)
            sel = np.random.default_rng(a.seed).choice(hfc, size=min(a.held_share, len(hfc)), replace=False)
            r = w.lift_tester().run_batch(hb.hand_pose[sel], hb.joint_angles[sel], threads=0)
            summary[name] = dict(force_closure=int(len(sel)), held=int(np.sum(r.lifted)))
            print(f"held share {name}: {int(np.sum(r.lifted))}/{len(sel)} = {np.mean(r.lifted):.3f}", flush=True)
        if a.held_share_only:
            continue
        idx = rng.choice(fc, size=min(a.per_object, len(fc)), replace=False)
        r = export(w, name, b, idx, "top", a.out, sweep)
        total += len(idx)
        print(f"{name}: {len(fc)} force-closure top grasps, exported {len(idx)}, lifted {int(np.sum(r.lifted))} "
              f"({time.time() - t0:.1f} s)", file=sys.stderr, flush=True)
    for name in [] if a.held_share_only or a.per_category_object <= 0 else CATEGORY:
        if wanted is not None and name not in wanted:
            continue
        w = World.single(name)
        d, tg, rolls = approaches(w, 12 * a.per_category_object, rng)
        b = w.approach_batch(d, tg, rolls, threads=0)
        fc = force_closure(b)
        idx = fc[: a.per_category_object]
        if len(idx) == 0:
            continue
        r = export(w, name, b, idx, "approach", a.out, sweep)
        total += len(idx)
        print(f"{name}: {len(fc)} force-closure approaches, exported {len(idx)}, lifted {int(np.sum(r.lifted))}",
              file=sys.stderr, flush=True)
    executed = executed_grasps([d for d in a.executed.split(",") if d.strip()]) if a.executed else {}
    for (name, source), items in sorted(executed.items()):
        w = World.single(name)
        b = reclose(w, items)
        stored = np.array([it[2] for it in items])
        fc = force_closure(b)
        touched = np.flatnonzero(b.touched & ~b.collision_at_start)
        idx = rng.choice(touched, size=min(a.per_executed, len(touched)), replace=False) if len(touched) else touched
        if len(idx) == 0:
            continue
        r = export(w, name, b, idx, source, a.out, sweep)
        total += len(idx)
        print(f"{name} {source}: {len(items)} executed, {len(touched)} touched, {len(fc)} force closure, exported "
              f"{len(idx)} (force closure {int(np.sum(np.asarray(b.epsilon)[idx] > 0))}), lifted "
              f"{int(np.sum(r.lifted))}; re-closed verdict = stored on {int(np.sum(b.lifted == stored))}/{len(items)}",
              file=sys.stderr, flush=True)
    print(f"exported {total} grasps to {a.out}", file=sys.stderr)
    if summary:
        with open(os.path.join(a.out, "held_share.json"), "w") as f:
            json.dump(summary, f, indent=1)


if __name__ == "__main__":
    main()
