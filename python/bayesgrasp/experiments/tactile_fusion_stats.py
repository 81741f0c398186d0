"""pub6's statistics (:mod:`.tactile_fusion`): the thesis's accounting of the trials (better / worse,
unstable -> stable, cumulative success by round, the vision-only baseline) beside its figures, and
one row per trial and round."""
from __future__ import annotations

from typing import List

from ..loop.fusion_trial import ROUNDS
from .category_stats import wilson


def transitions(results: list) -> dict:
    """The thesis's accounting over trials (Pub. VI): after round 1, better / worse / same (both
    unstable); unstable -> stable, stable -> unstable; of the still unstable, how many became
    stable in rounds 2 and 3; cumulative success by round; the vision-only baseline."""
    n = len(results)
    better = worse = same = up = down = 0
    for _, r in results:
        r0, r1 = r["rounds"][0], r["rounds"][1] if len(r["rounds"]) > 1 else r["rounds"][0]
        a, b = (r0["lifted"], r0["epsilon"]), (r1["lifted"], r1["epsilon"])
        if not a[0] and not b[0] and abs(a[1] - b[1]) < 1e-3:
            same += 1
        elif b > a:
            better += 1
        else:
            worse += 1
        up += (not r0["lifted"]) and r1["lifted"]
        down += r0["lifted"] and not r1["lifted"]
    cumulative = []
    for t in range(ROUNDS + 1):
        cumulative.append(sum(any(x["lifted"] for x in r["rounds"][:t + 1]) for _, r in results))
    still = [r for _, r in results if not any(x["lifted"] for x in r["rounds"][:2])]
    later = [sum(any(x["lifted"] for x in r["rounds"][2:t + 1]) for r in still) for t in (2, 3)]
    vision = sum(r["vision_only"]["lifted"] for _, r in results)
    return {"trials": n, "better": better, "worse": worse, "same_both_unstable": same,
            "unstable_to_stable": up, "stable_to_unstable": down, "still_unstable_after_round_1": len(still),
            "became_stable_round_2": later[0], "became_stable_round_3": later[1] - later[0],
            "cumulative_success_by_round": cumulative, "vision_only_success": vision,
            "success_after_round_3": cumulative[-1], "ci_after_round_3": wilson(cumulative[-1], n),
            "ci_vision_only": wilson(vision, n)}


THESIS = {"better": 45, "worse": 34, "same_both_unstable": 21, "unstable_to_stable": 25, "stable_to_unstable": 21,
          "still_unstable_after_round_1": 42, "became_stable_round_2": 15, "became_stable_round_3": 5,
          "success_after_round_3": 78}


def round_rows(results: list) -> List[dict]:
    """One row per trial and round: the grasp's epsilon, whether it lifted, the heaviest model and
    its weight after the round's update."""
    rows = []
    for key, r in results:
        names = [g["model"] for g in r.get("registrations", [])]
        for x in r["rounds"]:
            w = dict(zip(names, x.get("weights", [])))
            best = max(w, key=w.get) if w else ""
            rows.append({"trial": str(key), "round": x.get("round"), "epsilon": x["epsilon"], "lifted": x["lifted"],
                         "top_model": best, "top_weight": w.get(best, "")})
    return rows
