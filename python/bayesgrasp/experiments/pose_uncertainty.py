"""The thesis's experiments on known objects under pose uncertainty (§3.2-3.3, Pub. II-IV).

Each experiment is a set of runs; each run is a pure function of (experiment, object, run
index, seed) that returns a typed record (:mod:`.run_records`), stored as JSON as soon as it finishes
(:mod:`bayesgrasp.experiments.runner`); :mod:`.report` writes the tables (Markdown and CSV) and
the plots. The experiments registered here:

* ``pub2`` - stability maximisation (Pub. II): cube, cylinder, mug, mug2, pitcher; random true
  poses; up to 4 attempts; success rate, predicted stability, epsilon, pose error and entropy
  per attempt.
* ``baselines`` - the same set-up for every planner: stability, explore, ml_pose, open_loop.
* ``pub4`` - exploration vs stability only (Pub. IV): cube, mug, cylinder; 4 grasps each run
  (fixed number, as in the thesis); epsilon and entropy per step.
* ``entropy_order`` - Fig. 3.6: three grasps (lowest, median and highest predicted expected
  entropy on a grid) executed from the same belief; does the realised entropy keep the order?
* ``landscapes`` - weight-based vs kernel-based expected-entropy landscapes over the grasp
  position (their correlation), and the 1,000 vs 10,000 sample comparison for the cube with
  uncertainty in x only.

True poses: x, y uniform in +-10 cm, yaw uniform; the same for every method at a given
(object, run index), so methods are compared on the same problems.
"""
from __future__ import annotations

from functools import partial
from pathlib import Path
from typing import List, Optional

import numpy as np

from ..belief import relative_planar_pose, weight_entropy
from ..loop.context import RunContext
from ..loop.episode import EpisodeSettings, run_episode
from ..loop.episode_result import EpisodeResult
from ..models import relative_top_grasps
from ..planners import PLANNERS, PlannerSettings, make_planner
from ..world import World
from .pose_uncertainty_plots import plot_belief_evolution
from .pose_uncertainty_report import write_entropy_order, write_episodes, write_landscapes
from .registry import Experiment, register
from .run_records import PICKS, EntropyGain, EntropyOrderRun, EntropyPick, LandscapesRun, OneDof
from .runner import run_seed

FIVE = ("cube", "cylinder", "mug", "mug2", "pitcher")
METHODS = tuple(PLANNERS)   # every pose planner, in the registry's order


def true_pose(seed: int) -> np.ndarray:
    """The hidden true pose of a run from its seed (:func:`.runner.run_seed`): every method of the
    experiment gets the same seed for the same (object, run), so the same problem."""
    rng = np.random.default_rng(seed)
    return np.array([rng.uniform(-0.1, 0.1), rng.uniform(-0.1, 0.1), rng.uniform(-np.pi, np.pi)])


# ---- run functions (module level: sent to worker processes) ----------------------------------------
def episode_run(experiment: str, obj: str, run_index: int, seed: int, *, method: str, stop_when_stable: bool,
                ctx: RunContext) -> EpisodeResult:
    """One closed-loop episode on the run's true pose (the same problem for every method)."""
    episode = EpisodeSettings(method=method, stop_when_stable=stop_when_stable)
    return run_episode(obj, true_pose(seed), episode, ctx, seed=seed)


def _initial_planner(obj: str, ctx: RunContext, seed: int, models=None, settings: Optional[PlannerSettings] = None):
    """A run's hidden true pose and an exploration planner on its initial belief (around a
    noisy estimate of that pose): (pose, models, planner, rng, settings); rng (seeded by
    ``seed``) has drawn the estimate and the planner's seed and serves the rest of the run."""
    pose = true_pose(seed)
    models = models or ctx.models(obj)
    rng = np.random.default_rng(seed)
    s = settings or ctx.planner_settings()
    est = pose + rng.uniform(-np.asarray(s.half_width), np.asarray(s.half_width))
    return pose, models, make_planner("explore", models, est, s, seed=int(rng.integers(2**31))), rng, s


def entropy_order_run(experiment: str, obj: str, run_index: int, seed: int, *, ctx: RunContext,
                      grid: int = 15) -> EntropyOrderRun:
    """Predict the expected entropy (Eq. 3.2) of a grid of grasps from the initial belief, execute
    the best, the median and the worst, and realise their weight entropies after reweighting."""
    pose, models, planner, _, _ = _initial_planner(obj, ctx, seed)
    cands = _grid_actions(planner, grid, yaw=planner.belief.mean()[2])
    h, se = planner.expected_entropy(cands, n_samples=200, seed=1)
    particles = planner.belief.particles.copy()
    order = np.argsort(h)
    world = World.single(obj, pose=pose, hand=ctx.hand_model)
    picks = []
    for name, i in zip(PICKS, (order[0], order[len(order) // 2], order[-1])):
        realised, _ = _reweighted(planner, models, world, pose, cands[i])
        picks.append(EntropyPick(name, cands[i], float(h[i]), realised))
    return EntropyOrderRun(pose, grid, cands, h, particles, tuple(picks))


def _reweighted(planner, models, world, pose, action):
    """Executes ``action`` at the true pose and reweights the planner's particles by the
    measurement likelihood (no resampling): (weight entropy, posterior-mean position error)."""
    rel = relative_top_grasps(action, pose)[0, 0]
    q = np.asarray(world.grasp_batch(rel[None, :], spread=models.spread).joint_angles[0])
    q = q[models.joint_index]
    P = planner.belief.particles
    lw = planner.belief.log_weights + models.log_likelihood(relative_planar_pose(np.asarray(action)[None, :], P), q)
    w = np.exp(lw - np.logaddexp.reduce(lw))
    return weight_entropy(lw), float(np.hypot(*(w @ P[:, :2] - pose[:2])))


def entropy_gain_run(obj: str, run_index: int, ctx: Optional[RunContext] = None, models=None) -> EntropyGain:
    """From one initial belief: the planner's most informative grasp (Eq. 3.2) and a random grasp
    in the same search box, each executed at the true pose; realised posterior weight entropies
    and posterior-mean position errors (before: the prior's)."""
    ctx = ctx or RunContext()
    pose, models, planner, rng, _ = _initial_planner(
        obj, ctx, run_seed(ctx.seed, "entropy_gain", obj, run_index), models,
        PlannerSettings(explore_stability_weight=0.0))  # Eq. 3.2 alone
    world = World.single(obj, pose=pose, hand=ctx.hand_model)
    informative, _, _ = planner.minimise_entropy()
    low, high = planner.action_bounds()
    random_action = rng.uniform(low, high)
    w0 = planner.belief.weights
    err0 = float(np.hypot(*(w0 @ planner.belief.particles[:, :2] - pose[:2])))
    h_i, e_i = _reweighted(planner, models, world, pose, informative)
    h_r, e_r = _reweighted(planner, models, world, pose, random_action)
    return EntropyGain(pose, err0, float(np.log(len(w0))), np.asarray(informative), h_i, e_i, random_action, h_r, e_r)


def _grid_actions(planner, n: int, yaw: float) -> np.ndarray:
    low, high = planner.action_bounds()
    xs = np.linspace(low[0], high[0], n)
    ys = np.linspace(low[1], high[1], n)
    X, Y = np.meshgrid(xs, ys, indexing="ij")
    return np.column_stack([X.ravel(), Y.ravel(), np.full(X.size, yaw)])


def landscapes_run(experiment: str, obj: str, run_index: int, seed: int, *, ctx: RunContext,
                   grid: int = 21) -> LandscapesRun:
    """Weight vs kernel expected-entropy landscapes over (x, y) at the belief's mean yaw; for the
    cube also the 1-D (x only) uncertainty case with 1,000 and 10,000 measurement samples."""
    pose, models, planner, rng, s = _initial_planner(obj, ctx, seed)
    cands = _grid_actions(planner, grid, yaw=planner.belief.mean()[2])
    hw, _ = planner.expected_entropy(cands, n_samples=200, seed=3, method="weight")
    hk, _ = planner.expected_entropy(cands, n_samples=200, seed=3, method="kernel")
    one_dof = None
    if obj == "cube":
        # 1-DOF: the belief varies in x only (the thesis's cube experiment).
        s1 = s.with_(half_width=(0.04, 1e-6, 1e-6))
        p1 = make_planner("explore", models, (pose[0] + rng.uniform(-0.04, 0.04), pose[1], pose[2]), s1,
                          seed=int(rng.integers(2**31)))
        xs = np.linspace(pose[0] - 0.07, pose[0] + 0.07, 141)
        acts = np.column_stack([xs, np.full_like(xs, pose[1]), np.full_like(xs, pose[2])])
        h1, _ = p1.expected_entropy(acts, n_samples=1000, seed=5)
        h10, _ = p1.expected_entropy(acts, n_samples=10000, seed=5)
        one_dof = OneDof(xs, np.asarray(h1), np.asarray(h10))
    return LandscapesRun(pose, grid, cands, np.asarray(hw), np.asarray(hk), one_dof)


# ---- the registered experiments ---------------------------------------------------------------------
def prepare_models(exp: Experiment, obj: str, ctx: RunContext) -> None:
    """One object's grasp models (each family's), built (or loaded) into the cache once."""
    ctx.family_models(obj)


def _episodes(exp: Experiment, method: str, ctx: RunContext):
    fn = partial(episode_run, method=method, stop_when_stable=(exp.name != "pub4"), ctx=ctx)
    return f"{exp.name}/{method}", fn


def _explore_runs(run_function):
    def make(exp: Experiment, method: str, ctx: RunContext):
        return exp.name, partial(run_function, ctx=ctx)
    return make


def belief_figures(exp: Experiment, objects: List[str], ctx: RunContext, out: Path) -> None:
    """Figs. 3.3 / 3.5: the belief's evolution in run 0 of each object (re-run: it is pure)."""
    method = exp.methods[0]
    lines = []
    for o in objects:
        seed = run_seed(ctx.seed, exp.seeds, o, 0)
        pose = true_pose(seed)
        episode = EpisodeSettings(method=method, stop_when_stable=(exp.name != "pub4"))
        r = run_episode(o, pose, episode, ctx, seed=seed, keep_planner=True)
        p = plot_belief_evolution(r.snapshots, pose, out / f"belief_{o}.png",
                                  f"{o}, {method}, run 0: true pose {np.round(pose, 3).tolist()}",
                                  [a.to_dict() for a in r.attempts])
        lines.append(f"![{o}]({p.name})")
    with open(out / "summary.md", "a") as f:
        f.write("\n## Belief evolution (run 0)\n\n" + "\n\n".join(lines) + "\n")


register(Experiment("pub2", FIVE, 100, "stability maximisation (Pub. II)", _episodes, write_episodes,
                    ("stability",), belief_figures, prepare_object=prepare_models))
register(Experiment("baselines", FIVE, 30, "all planners and the two baselines", _episodes, write_episodes,
                    METHODS, prepare_object=prepare_models))
register(Experiment("pub4", ("cube", "mug", "cylinder"), 30,
                    "exploration vs stability only, 4 grasps per run (Pub. IV)", _episodes, write_episodes,
                    ("explore", "stability"), belief_figures, prepare_object=prepare_models))
#: The entropy experiments read exact joint angles on the top family's models (no execution verdict).
EXPLORE_READS = ("success", "models", "planner")
register(Experiment("entropy_order", ("cube", "mug"), 30,
                    "predicted vs realised entropy order of three grasps (Fig. 3.6)", _explore_runs(entropy_order_run),
                    write_entropy_order, ("explore",), prepare_object=prepare_models, reads=EXPLORE_READS))
register(Experiment("landscapes", ("mug", "cube"), 3, "weight vs kernel entropy landscapes; 1,000 vs 10,000 samples",
                    _explore_runs(landscapes_run), write_landscapes, ("explore",), prepare_object=prepare_models,
                    reads=EXPLORE_READS))
