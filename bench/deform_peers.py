"""Non-rigid registration (Coherent Point Drift) against its peers on the same clouds: our C++ CPD
(bayesgrasp.vision.coherent_point_drift, Nystrom low rank) and pycpd 2.0.0 and probreg 0.3.8
(PyPI), one thread each. The clouds are what the warped category method sees: a held-out mug's
simulated view (voxel 5 mm) and another mug's surface samples (800) placed by the rigid
registration. Same CPD settings everywhere: beta = 2 model RMS radii, lambda = 2 (in the model's
normalised units; pycpd's alpha = lambda / s^2 in metres), w = 0.1, at most 100 iterations.
Each result's residual is the RMS distance from each observed point to the nearest moved model
point; "same residual" is read from it.

    BAYESGRASP_PY bench/deform_peers.py data DIR        # the clouds (needs bayesgrasp)
    BAYESGRASP_PY bench/deform_peers.py ours DIR OUT    # our CPD
    BENCH_PY      bench/deform_peers.py peers DIR OUT [OURS]   # pycpd, probreg (OURS: as many iterations as ours)
    python        bench/deform_peers.py report OUT...   # the table (medians, ratios)
"""
import json
import sys
import time
from pathlib import Path

import numpy as np

BETA, LAMBDA, W, ITER, TOL = 2.0, 2.0, 0.1, 100, 1e-3
REPEATS = 3


def rms_nearest(X, T):
    from scipy.spatial import cKDTree

    return float(np.sqrt(np.mean(cKDTree(T).query(X)[0] ** 2)))


def rms_radius(Y):
    return float(np.sqrt(np.mean(np.sum((Y - Y.mean(0)) ** 2, axis=1))))


def data(out: Path, cases: int = 6) -> None:
    """Case k: mug/k seen from view 1000 + k, mug/(k+1) mod 7 registered onto it, its 800 surface
    samples moved there."""
    from bayesgrasp.loop.category import observe
    from bayesgrasp.experiments.category_grasping import view
    from bayesgrasp.objects import load_object
    from bayesgrasp.planners.category import voxel_points
    from bayesgrasp.vision import model_samples, register

    out.mkdir(parents=True, exist_ok=True)
    for k in range(cases):
        seen, model = f"mug/{k}", f"mug/{(k + 1) % 7}"
        pose, eye = view(1000 + k)
        o = observe(seen, pose, eye, seed=k)
        r = register(o.cloud, [load_object(model)], viewpoint=o.viewpoint, names=[model])[0]
        P, _ = model_samples(load_object(model), samples=800, seed=k)
        T = np.asarray(r.transform)
        np.savez(out / f"case{k}.npz", Y=P @ T[:3, :3].T + T[:3, 3], X=voxel_points(np.asarray(o.cloud), 0.005),
                 seen=seen, model=model)
        print(f"case {k}: {model} onto {seen}'s view, {len(P)} model points, registered: {r.success}")


def _cases(d: Path):
    for f in sorted(Path(d).glob("case*.npz")):
        z = np.load(f)
        yield f.stem, z["Y"], z["X"]


def _timed(fn):
    times, out = [], None
    for _ in range(REPEATS):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return float(np.median(times)), out


def ours(d: Path, out: Path) -> None:
    from bayesgrasp.vision import coherent_point_drift

    rows = []
    for name, Y, X in _cases(d):
        t, r = _timed(lambda: coherent_point_drift(Y, X, beta=BETA, lam=LAMBDA, outlier_weight=W,
                                                   max_iterations=ITER, tolerance=TOL, threads=1))
        rows.append({"case": name, "M": len(Y), "N": len(X), "seconds": t, "iterations": r.iterations,
                     "residual": rms_nearest(X, r.moved), "before": rms_nearest(X, Y)})
        print(f"ours {name}: {t * 1000:.0f} ms, {r.iterations} iterations, residual {rows[-1]['residual'] * 1000:.2f} mm")
    Path(out).write_text(json.dumps({"planner": "bayesgrasp", "rows": rows}, indent=1))


def peers(d: Path, out: Path, ours_file: Path = None) -> None:
    """The peers run exactly as many EM iterations as ours took on each case (their tolerances are
    absolute, in squared metres: at 1e-3 both stop after 2 iterations on these clouds), so the
    times compare the same work and the residuals say whether it reached the same fit."""
    import probreg
    from probreg import cpd as pcpd
    from pycpd import DeformableRegistration

    iters = {}
    if ours_file is not None and Path(ours_file).is_file():
        iters = {r["case"]: r["iterations"] for r in json.loads(Path(ours_file).read_text())["rows"]}
    rows = []
    for name, Y, X in _cases(d):
        s = rms_radius(Y)
        n = int(iters.get(name, ITER))

        def run_pycpd():
            reg = DeformableRegistration(X=X, Y=Y, alpha=LAMBDA / s ** 2, beta=BETA * s, w=W,
                                         max_iterations=n, tolerance=0.0)
            TY, _ = reg.register()
            return TY, reg.iteration

        def run_probreg():
            r = pcpd.registration_cpd(Y, X, tf_type_name="nonrigid", w=W, beta=BETA * s, lmd=LAMBDA / s ** 2,
                                      maxiter=n, tol=0.0)
            return r.transformation.transform(Y), n

        for peer, fn in (("pycpd", run_pycpd), ("probreg", run_probreg)):
            t, (TY, ran) = _timed(fn)
            rows.append({"case": name, "peer": peer, "seconds": t, "iterations": ran,
                         "residual": rms_nearest(X, np.asarray(TY))})
            print(f"{peer} {name}: {t * 1000:.0f} ms, residual {rows[-1]['residual'] * 1000:.2f} mm")
    import pycpd
    Path(out).write_text(json.dumps({"versions": {"pycpd": getattr(pycpd, "__version__", "2.0.0"),
                                                  "probreg": getattr(probreg, "__version__", "0.3.8")},
                                     "rows": rows}, indent=1))


def report(*files) -> None:
    ours_rows, peer_rows = {}, {}
    for f in files:
        doc = json.loads(Path(f).read_text())
        for r in doc["rows"]:
            if "peer" in r:
                peer_rows.setdefault(r["peer"], {})[r["case"]] = r
            else:
                ours_rows[r["case"]] = r
    print("| case | M x N | ours ms (residual mm) | " + " | ".join(f"{p} ms (residual mm), ratio" for p in peer_rows) + " |")
    print("|---|---|---|" + "---|" * len(peer_rows))
    ratios = {p: [] for p in peer_rows}
    for c, o in sorted(ours_rows.items()):
        cells = []
        for p, rows in peer_rows.items():
            r = rows.get(c)
            if r:
                ratios[p].append(r["seconds"] / o["seconds"])
                cells.append(f"{r['seconds'] * 1000:.0f} ({r['residual'] * 1000:.2f}), {ratios[p][-1]:.1f}x")
            else:
                cells.append("-")
        print(f"| {c} | {o['M']} x {o['N']} | {o['seconds'] * 1000:.0f} ({o['residual'] * 1000:.2f}) | "
              + " | ".join(cells) + " |")
    med = np.median([o["seconds"] for o in ours_rows.values()])
    print(f"\nours: median {med * 1000:.0f} ms; " + "; ".join(
        f"{p}: median ratio {np.median(v):.1f}x" for p, v in ratios.items() if v))


if __name__ == "__main__":
    cmd, args = sys.argv[1], sys.argv[2:]
    {"data": lambda: data(Path(args[0])), "ours": lambda: ours(Path(args[0]), Path(args[1])),
     "peers": lambda: peers(Path(args[0]), Path(args[1]), Path(args[2]) if len(args) > 2 else None), "report": lambda: report(*args)}[cmd]()
