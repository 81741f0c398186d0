"""How fragile a lift verdict is to the hand's geometry (issue 55, item 6).

The same top grasps are executed again and lift-tested with the hand's geometry changed by one
amount at a time, within what we take as its manufacturing spread, and one variant outside it
(the third-party BH8 URDF's distal bend). A verdict is *fragile* when some in-spread variant flips
it (held -> dropped or dropped -> held).

Grasp set per object: lift_torque_sweep.py's grid of top grasps (x, y in +-5 cm, 8 yaws), the
``--grasps`` that grip under the nominal hand (epsilon > 0; for the jaw, whose two pads never
make force closure, both pads touching the object), evenly spaced through the grid's order; each
variant executes the same (x, y, yaw) as a robot would (it descends until its own first contact and
closes: a thicker finger stops higher) and the lift test judges them.

Assumed spread (no tolerances are published for either hand; the figures are ours, stated here):
  BH8   distal bend 42 deg +-2 deg (the breakaway coupling's slack and assembly), proximal and
        distal length +-1 mm (tip moved along the link), link radius +-1 mm (pads and covers);
        outside it: a 34 deg distal bend (the third-party URDF of issue 55).
  jaw   pad width (across the finger) 21 mm +-1 mm, finger length 54 mm +-1 mm.

    OMP_NUM_THREADS=1 .venv/bin/python bench/hand_sensitivity.py [--objects cube,cylinder,mug,mug2]
        [--grasps 30] [--hands bh8,jaw] [--out bench/results/hand_sensitivity.json]
"""
import argparse
import copy
import json
import sys
import time
from pathlib import Path

import numpy as np

from bayesgrasp.hand import Hand
from bayesgrasp.world import World

sys.path.insert(0, str(Path(__file__).resolve().parent))
from lift_torque_sweep import grid_grasps, top_grid  # noqa: E402

HANDS = {"bh8": "barrett_bh8", "jaw": "parallel_jaw.urdf"}


# ---- one change of geometry, on the hand file's JSON (every finger alike) ----

def _phalanges(doc: dict, name: str):
    for f in doc["fingers"]:
        for p in f["phalanges"]:
            if p["name"] == name:
                yield p


def distal_bend(delta_deg: float):
    """The distal's angle at proximal 0 (BH8: distal = proximal/3 + 42 deg) moved by delta_deg."""
    def apply(doc):
        for p in _phalanges(doc, "distal"):
            p["offset_deg"] += delta_deg
            p["lower_deg"] += delta_deg
        return doc
    return apply


def bend_to(deg: float):
    """The distal bend set to deg (the variant outside the spread)."""
    def apply(doc):
        d = deg - next(_phalanges(doc, "distal"))["offset_deg"]
        return distal_bend(d)(doc)
    return apply


def length(name: str, dl: float):
    """Phalanx `name` longer by dl (m): its length, and its shapes' far end moved along the link
    (a capsule's endpoint with the larger x; a convex shape's vertices stretched in x)."""
    def apply(doc):
        for p in _phalanges(doc, name):
            L = p["length"]
            p["length"] = L + dl
            for s in p["shapes"]:
                if s["type"] == "capsule":
                    far = "p1" if s["p1"][0] >= s["p0"][0] else "p0"
                    s[far][0] += dl
                elif s["type"] == "convex":
                    s["vertices"] = [[v[0] * (L + dl) / L, v[1], v[2]] for v in s["vertices"]]
                else:
                    raise ValueError(f"length: shape type {s['type']!r} not handled")
        return doc
    return apply


def radius(dr: float):
    """Every finger capsule's radius changed by dr (m)."""
    def apply(doc):
        for f in doc["fingers"]:
            for p in f["phalanges"]:
                for s in p["shapes"]:
                    if s["type"] == "capsule":
                        s["radius"] += dr
        return doc
    return apply


def pad_width(dw: float):
    """A jaw's pad wider by dw (m) across the finger (its convex shape's y, about its centre)."""
    def apply(doc):
        for p in _phalanges(doc, "jaw"):
            for s in p["shapes"]:
                ys = [v[1] for v in s["vertices"]]
                c, half = (max(ys) + min(ys)) / 2, (max(ys) - min(ys)) / 2
                s["vertices"] = [[v[0], c + (v[1] - c) * (half + dw / 2) / half, v[2]] for v in s["vertices"]]
        return doc
    return apply


MM, DEG = 1e-3, 1.0
# name -> (change, inside the spread?)
VARIANTS = {
    "bh8": {
        "distal bend -2 deg": (distal_bend(-2 * DEG), True),
        "distal bend +2 deg": (distal_bend(+2 * DEG), True),
        "proximal -1 mm": (length("proximal", -MM), True),
        "proximal +1 mm": (length("proximal", +MM), True),
        "distal -1 mm": (length("distal", -MM), True),
        "distal +1 mm": (length("distal", +MM), True),
        "link radius -1 mm": (radius(-MM), True),
        "link radius +1 mm": (radius(+MM), True),
        "distal bend 34 deg (third-party URDF)": (bend_to(34.0), False),
    },
    "jaw": {
        "pad width -1 mm": (pad_width(-MM), True),
        "pad width +1 mm": (pad_width(+MM), True),
        "finger length -1 mm": (length("jaw", -MM), True),
        "finger length +1 mm": (length("jaw", +MM), True),
    },
}


def variant_hand(nominal: Hand, change) -> Hand:
    return Hand.from_json(json.dumps(change(copy.deepcopy(json.loads(nominal.text)))))


def gripping(hand: Hand, obj: str, n: int) -> np.ndarray:
    """(n, 3) top grasps (x, y, yaw) of the grid, evenly spaced in its order, of those that grip
    with `hand`: epsilon > 0, or for a jaw hand (two pads never make force closure) every pad
    touching."""
    b = grid_grasps(World.single(obj, hand=hand))
    if hand.prismatic_joints.any():
        pads = [links[-1] for links in hand.phalanx_links]
        ok = np.all(np.asarray(b.link_contact, dtype=bool)[:, pads], axis=1)
    else:
        ok = b.epsilon > 0
    idx = np.flatnonzero(ok)
    return top_grid()[idx[np.unique(np.linspace(0, len(idx) - 1, min(n, len(idx))).astype(int))]]


def lifted_at(hand: Hand, obj: str, xyyaw: np.ndarray) -> np.ndarray:
    """The top grasps as a robot with this hand executes them: it descends to its own first
    contact and closes; then the lift test (one thread)."""
    b = World.single(obj, hand=hand).grasp_batch(xyyaw, lift=True, threads=1)
    return np.asarray(b.lifted, dtype=bool)


def measure(hand_key: str, obj: str, n: int) -> dict:
    nominal = Hand.load(HANDS[hand_key])
    G = gripping(nominal, obj, n)
    t0 = time.perf_counter()
    base = lifted_at(nominal, obj, G)
    rows, fragile = {}, np.zeros(len(G), dtype=bool)
    for name, (change, inside) in VARIANTS[hand_key].items():
        v = lifted_at(variant_hand(nominal, change), obj, G)
        flips = v != base
        if inside:
            fragile |= flips
        rows[name] = {"inside_spread": inside, "lifted": int(v.sum()), "held_to_dropped": int(np.sum(base & ~v)),
                      "dropped_to_held": int(np.sum(~base & v))}
        print(f"  {hand_key} {obj} {name}: lifted {int(v.sum())}/{len(G)} (nominal {int(base.sum())}), "
              f"flipped {int(flips.sum())}", file=sys.stderr, flush=True)
    return {"grasps": int(len(G)), "nominal_lifted": int(base.sum()), "variants": rows,
            "fragile": int(fragile.sum()), "fragile_held": int(np.sum(fragile & base)),
            "seconds": round(time.perf_counter() - t0, 1)}


def table(results: dict) -> str:
    out = []
    for hk, per_obj in results.items():
        names = list(VARIANTS[hk])
        out.append(f"\n**{hk}** (lifted of the grasps; in brackets held->dropped / dropped->held)\n")
        out.append("| object | grasps | nominal | " + " | ".join(names) + " | fragile (of them held) |")
        out.append("|---|---|---|" + "---|" * len(names) + "---|")
        for obj, r in per_obj.items():
            cells = [f"{v['lifted']} ({v['held_to_dropped']}/{v['dropped_to_held']})" for v in r["variants"].values()]
            out.append(f"| {obj} | {r['grasps']} | {r['nominal_lifted']} | " + " | ".join(cells)
                       + f" | {r['fragile']} ({r['fragile_held']}) |")
    return "\n".join(out)


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--objects", default="cube,cylinder,mug,mug2")
    ap.add_argument("--grasps", type=int, default=30)
    ap.add_argument("--hands", default="bh8,jaw")
    ap.add_argument("--out", default="bench/results/hand_sensitivity.json")
    a = ap.parse_args(argv)
    hands = a.hands.split(",")
    bad = [h for h in hands if h not in HANDS]
    if bad:
        ap.error(f"--hands: unknown {bad}; known: {', '.join(HANDS)}")
    if a.grasps < 1:
        ap.error("--grasps: must be >= 1")
    results = {}
    for hk in hands:
        results[hk] = {}
        for obj in a.objects.split(","):
            results[hk][obj] = measure(hk, obj, a.grasps)
            Path(a.out).parent.mkdir(parents=True, exist_ok=True)
            Path(a.out).write_text(json.dumps(results, indent=1))   # kept after each object
    print(table(results))


if __name__ == "__main__":
    main()
