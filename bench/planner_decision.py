"""One planning decision with 500 particles (target: <= 250 ms on one core).

For each of the five Pub. II objects, beliefs are taken from real runs of the loop (the initial
belief, +-4 cm / +-45 deg uniform, and the belief after one failed grasp), and a decision is
timed with one thread:
  * stability: Eq. 3.1, PSO (32 x 30) over the tabulated P(S | A, O) (our default);
  * explore:   the exploration planner's whole decision (the stability search, then Eq. 3.2's
               PSO over the expected posterior weight entropy, 16 x 12, 50 measurement samples);
  * stability_both / explore_both: the same decisions searching both grasp families (top and
               side, each with its own models and table; the best wins);
  * peer:      the same stability search evaluating the FITC GP itself at every
               (candidate, particle) pair instead of the table (what a direct implementation
               does), fewer repetitions.
Also the table's error against the GP it tabulates, at random relative grasps.
Usage: python bench/planner_decision.py [--out bench/results/planner.json] [--reps 10]
"""
import argparse
import json
import os
import time

import numpy as np

from bayesgrasp.models import ModelSettings
from bayesgrasp.planners import ExplorationPlanner, Plan, PlannerSettings, Reading, StabilityPlanner, get_models
from bayesgrasp.experiments import EpisodeSettings, RunContext, run_episode

OBJECTS = ("cube", "cylinder", "mug", "mug2", "pitcher")


class GPStability(StabilityPlanner):
    """The stability planner with the GP evaluated at every pair (no table)."""

    def maximise_stability(self, poses, weights, family=None):
        from bayesgrasp import optim
        from bayesgrasp.models import relative_top_grasps

        s = self.settings
        family = self._family(family)
        models = self.family_models[family]
        low, high = self.action_bounds(poses)
        w = np.asarray(weights, dtype=float)
        init = np.clip(self._seed_actions(poses, w, s.pso_particles, family), low, high)

        def negative(X):
            return -(models.stability_probability(relative_top_grasps(X, poses)) @ w)

        r = optim.pso(negative, (low, high), n_particles=s.pso_particles, max_iter=s.pso_iter,
                      seed=int(self._rng.integers(2**31)), init=init)
        return r.x, -r.fun, r.nfev


def problem(obj, models, rng, seed):
    """A seeded decision problem: the planner's estimate (the truth off by up to 4 cm / 45 deg) and
    the observation of a failed first grasp from the real loop (action, joint angles and whether it held)."""
    pose = np.array([rng.uniform(-0.08, 0.08), rng.uniform(-0.08, 0.08), rng.uniform(-np.pi, np.pi)])
    est = pose + rng.uniform(-1, 1, 3) * np.array([0.04, 0.04, np.radians(45)])
    ep = run_episode(obj, pose, EpisodeSettings(method="stability", attempts=1, stop_when_stable=False),
                     RunContext(success="epsilon", lift=False), seed=seed, estimate=est, models=models)
    a0 = ep.to_dict()["attempts"][0]     # a top grasp: the executed Plan names its family for the two-family planners
    plan = Plan(np.array(a0["action"]), a0["kind"], a0["predicted_stability"], a0["predicted_stability"], family="top")
    return est, (plan, Reading(a0["joint_angles"], held=a0["stable"]))


def timed(planner_cls, models, est, seed, observe=None):
    p = planner_cls(models, est, PlannerSettings(threads=1), seed=seed)
    if observe is not None:
        p.observe(*observe)
    t0 = time.perf_counter()
    plan = p.plan()
    return time.perf_counter() - t0, plan


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--out", default="bench/results/planner.json")
    ap.add_argument("--reps", type=int, default=10)
    ap.add_argument("--cache", default=None)
    a = ap.parse_args()
    rng = np.random.default_rng(0)
    rows = {"stability": [], "explore": [], "stability_both": [], "explore_both": [], "peer_gp": [],
            "stability_same_as_peer": []}
    table_err = []
    for obj in OBJECTS:
        models = get_models(obj, cache_dir=a.cache)
        both = {"top": models, "side": get_models(obj, settings=ModelSettings(family="side"), cache_dir=a.cache)}
        tab = models.table()
        rel = np.column_stack([rng.uniform(-0.06, 0.06, 20000), rng.uniform(-0.06, 0.06, 20000),
                               rng.uniform(-np.pi, np.pi, 20000)])
        table_err.append(float(np.max(np.abs(tab.stability(rel) - models.stability_probability(rel)))))
        table_err.append(float(np.mean(np.abs(tab.stability(rel) - models.stability_probability(rel)))))
        for r in range(a.reps):
            est, obs = problem(obj, models, rng, r)   # a failed first grasp gives the second belief
            for observe in (None, obs):
                t, _ = timed(StabilityPlanner, models, est, r, observe)
                rows["stability"].append(t)
                t, _ = timed(ExplorationPlanner, models, est, r, observe)
                rows["explore"].append(t)
                t, _ = timed(StabilityPlanner, both, est, r, observe)
                rows["stability_both"].append(t)
                t, _ = timed(ExplorationPlanner, both, est, r, observe)
                rows["explore_both"].append(t)
            if r < max(2, a.reps // 5):
                t, _ = timed(GPStability, models, est, r)
                rows["peer_gp"].append(t)
                t, _ = timed(StabilityPlanner, models, est, r)
                rows["stability_same_as_peer"].append(t)
    med = {k: float(np.median(v)) for k, v in rows.items()}
    out = {"threads": os.environ.get("OMP_NUM_THREADS"), "particles": 500,
           "median_s": med, "p90_s": {k: float(np.percentile(v, 90)) for k, v in rows.items()},
           "n": {k: len(v) for k, v in rows.items()},
           "peer_ratio": med["peer_gp"] / med["stability_same_as_peer"],
           "table_vs_gp_max_abs_error_PS": max(table_err[0::2]), "table_vs_gp_mean_abs_error_PS": float(np.mean(table_err[1::2]))}
    os.makedirs(os.path.dirname(a.out), exist_ok=True)
    with open(a.out, "w") as f:
        json.dump(out, f, indent=1)
    print(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
