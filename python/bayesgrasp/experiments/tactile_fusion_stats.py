"""pub6's statistics (:mod:`.tactile_fusion`): the thesis's accounting of the trials (better / worse,
unstable -> stable, cumulative success by round, the vision-only baseline) beside its figures, and
one row per trial and round."""
from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import List, Tuple

from ..loop.fusion_trial import ROUNDS
from .category_stats import wilson


@dataclass(frozen=True)
class Transitions:
    """The thesis's accounting of pub6's trials (Pub. VI), counts of trials:

    trials : int
    better, worse, same_both_unstable : int — round 1's grasp against G(0) (lifted, then epsilon)
    unstable_to_stable, stable_to_unstable : int — G(0) -> round 1
    still_unstable_after_round_1 : int; became_stable_round_2, became_stable_round_3 : int — of those
    cumulative_success_by_round : list of int — trials lifted by round 0, 1, 2, 3
    vision_only_success : int — the vision-only baseline's grasp lifted
    success_after_round_3 : int
    ci_after_round_3, ci_vision_only : (float, float) — 95% Wilson intervals of the two rates
    """

    trials: int
    better: int
    worse: int
    same_both_unstable: int
    unstable_to_stable: int
    stable_to_unstable: int
    still_unstable_after_round_1: int
    became_stable_round_2: int
    became_stable_round_3: int
    cumulative_success_by_round: List[int]
    vision_only_success: int
    success_after_round_3: int
    ci_after_round_3: Tuple[float, float]
    ci_vision_only: Tuple[float, float]

    def to_dict(self) -> dict:
        return asdict(self)


def transitions(results: list) -> Transitions:
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
    return Transitions(n, better, worse, same, up, down, len(still), later[0], later[1] - later[0], cumulative,
                       vision, cumulative[-1], wilson(cumulative[-1], n), wilson(vision, n))


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
