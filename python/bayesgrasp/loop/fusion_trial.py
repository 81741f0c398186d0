"""One trial of vision, then touch (thesis §4.3, Pub. VI): the episode behind ``bayesgrasp fuse``,
the robot-outside :class:`~.outside_loop_category.FusionEpisode` and the experiment ``pub6``
(:mod:`bayesgrasp.experiments.tactile_fusion`).

A held-out mug at a table pose; the category's other models are the training models, each with
its measurement and stability GP models over top grasps and its demonstrated top task grasps.
Vision (one camera view, registration against them) gives w_i(0) (the normalised phi(delta_i))
and p_i(0) (each registration's planar part). G(0) is drawn at random above the object (mode
``random``) or planned from the vision belief alone (mode ``vision``); then up to ``ROUNDS``
tactile rounds: execute, read the joint angles, update every p_i (Eq. 4.4) and w_i (Eq. 4.5),
re-plan with stability x task (Eq. 4.6), execute. Success = lifted.
"""
from __future__ import annotations

from typing import Optional, Sequence

import numpy as np

from ..belief.model_mixture import ModelMixtureBelief
from ..models import ModelSettings, relative_top_grasps
from ..models.tasks import task_rule
from ..planners.fusion import PART_TERMS, FusionPlanner, FusionSettings
from ..planners.protocol import Reading
from ..progress import heartbeat
from ..world import World
from .category import demonstrated, see
from .context import RunContext
from .fusion_result import FusionResult, FusionRound, TopGraspExecution

ROUNDS = 3   # tactile rounds after G(0)


def planar_top_grasps(grasps) -> np.ndarray:
    """Demonstrated grasps as planar top grasps (x, y, yaw) in the model's frame: the hand's
    position and, for a palm-down hand (approach -z, roll = yaw), the yaw of its x axis."""
    rows = [(g.pose[0, 3], g.pose[1, 3], np.arctan2(g.pose[1, 0], g.pose[0, 0])) for g in grasps]
    return np.array(rows, dtype=float).reshape(-1, 3)


def planar_pose(T: np.ndarray) -> np.ndarray:
    """A registration's planar part: (x, y, yaw of the model's x axis)."""
    return np.array([T[0, 3], T[1, 3], np.arctan2(T[1, 0], T[0, 0])])


def top_grasp(world: World, action: np.ndarray, true_pose: np.ndarray, spread: float) -> TopGraspExecution:
    """The world top grasp (x, y, yaw) executed on the object at its true pose, lift-tested."""
    rel = relative_top_grasps(action, true_pose)[0]
    b = world.grasp_batch(rel, spread=spread, lift=True)
    return TopGraspExecution(np.array(action, dtype=float), bool(b.lifted[0]), float(b.epsilon[0]),
                             np.asarray(b.joint_angles[0], float), np.asarray(b.hand_pose[0], float))


class FusionTrial:
    """One trial's fixed parts: the models, their task grasps, the vision belief."""

    def __init__(self, obj: str, pose, ctx: RunContext, task: str = "top", settings: Optional[FusionSettings] = None,
                 exclude: Sequence[str] = (), eye_offset=None, seed: int = 0,
                 model_settings: Optional[ModelSettings] = None, grasps: Optional[Sequence] = None,
                 category: Optional[str] = None, observation=None):
        """``observation``: the vision step's cloud from a camera (a
        :class:`~bayesgrasp.loop.category.Observation` in the table frame) instead of a
        simulated view of ``obj``; ``obj`` at ``pose`` is then the simulated stand-in the grasps
        are executed on (None: no stand-in, a robot outside executes them; see
        :mod:`~bayesgrasp.loop.outside_loop`)."""
        cat = category or (obj.split("/")[0] if "/" in str(obj) else "mug")
        self.obj, self.pose, self.ctx, self.seed = obj, np.asarray(pose, float), ctx, seed
        kw = {} if eye_offset is None else {"eye_offset": eye_offset}
        ctx.say(f"fuse: registering the {cat} models to the view")
        self.episode = see(obj, pose, cat, exclude=tuple(exclude) or (obj,), seed=seed, observation=observation, **kw)
        if not any(r.success for r in self.episode.registrations):
            raise ValueError("no training model registered to the cloud: there is no vision belief to start from")
        self.names = self.episode.models
        self.models = ctx.models_of(self.names, model_settings)
        rule = self.rule = task_rule(cat, task)
        grasps = demonstrated(self.names, rule, ctx) if grasps is None else grasps
        self.task_grasps = [planar_top_grasps([g for g in grasps if g.model == m]) for m in self.names]
        regs = self.episode.registrations
        self.w0 = np.array([r.phi if r.success else 0.0 for r in regs])
        self.p0 = np.array([planar_pose(r.transform) for r in regs])
        self.settings = settings or FusionSettings()
        self.world = None if obj is None else World.single(obj, pose=pose, hand=ctx.hand_model)
        self.spread = float(np.median([m.spread for m in self.models]))
        self._warped: Optional[list] = None     # the models warped onto the view, when first needed
        #: the planner's reach (:attr:`FusionPlanner.reach`: the top grasps an arm reaches), or None
        self.reach = None

    def belief(self) -> ModelMixtureBelief:
        w = self.w0 if self.w0.sum() > 0 else np.ones(len(self.w0))
        return ModelMixtureBelief(self.names, self.models, w, self.p0, self.settings, seed=self.seed)

    def start(self):
        """The trial's random stream and the planner on the vision belief (seeded from the stream;
        the belief is its ``belief``)."""
        rng = np.random.default_rng(self.seed)
        part = self.part_check if self.settings.task_term in PART_TERMS else None
        planner = FusionPlanner(self.belief(), self.task_grasps, seed=int(rng.integers(2**31)), part_check=part)
        planner.reach = self.reach
        return rng, planner

    def part_check(self, grasps: np.ndarray, belief: ModelMixtureBelief):
        """The part check of top grasps (K, 3) over the models at the belief's poses and weights
        (held left to compute lazily)."""
        from ..planners.part_check import check_top_grasps

        hand = self.ctx.hand_model
        shapes = self.warped_models() if self.settings.task_term == "warped" else None
        return check_top_grasps(hand, self.rule, grasps, self.names, belief.poses, belief.weights, self.spread,
                                resolve=False, shapes=shapes)

    def warped_models(self) -> list:
        """The training models warped onto the view (task term "warped"), once per trial: each
        from its registration, the cloud reduced to one point per 5 mm voxel as the category
        planner reduces it."""
        if self._warped is None:
            from ..planners.category import CategorySettings, voxel_points, warp_models

            s = CategorySettings()
            cloud = voxel_points(np.asarray(self.episode.observation.cloud, float), s.clearance_voxel)
            self._warped = warp_models(self.episode.registrations, self.w0, cloud, s.warp_samples, self.seed)
        return self._warped

    def random_grasp(self, rng: np.random.Generator) -> np.ndarray:
        """G(0) at random in the area above the object: its centre +-3 cm, any yaw."""
        c = self.world.object.com[:2]
        cx, cy = self.pose[0] + np.cos(self.pose[2]) * c[0] - np.sin(self.pose[2]) * c[1], \
            self.pose[1] + np.sin(self.pose[2]) * c[0] + np.cos(self.pose[2]) * c[1]
        return np.array([cx + rng.uniform(-0.03, 0.03), cy + rng.uniform(-0.03, 0.03), rng.uniform(-np.pi, np.pi)])

    def run(self, mode: str = "random", rounds: int = ROUNDS, on_round=None, stop_at_lift: bool = False) -> FusionResult:
        """G(0) (random or vision-planned) and up to ``rounds`` tactile rounds, until a grasp after
        round 1 is lifted (the thesis's protocol always runs round 1); ``stop_at_lift``: from the
        first lifted grasp on, round 0 included (the robot's rule: the object is up)."""
        rng, planner = self.start()
        belief = planner.belief
        if mode != "random":
            self.ctx.say("fuse: round 0: planning on the vision belief (Eq. 4.6)")
        with heartbeat(self.ctx.progress, "fuse: planning"):
            g0 = self.random_grasp(rng) if mode == "random" else planner.plan().action
        self.ctx.say(f"fuse: round 0: executing the {'random' if mode == 'random' else 'planned'} grasp and lift-testing it")
        records = [self._round(0, g0, belief)]
        if on_round:
            on_round(records[-1])
        for t in range(1, rounds + 1):
            last = records[-1]
            if (t > 1 or stop_at_lift) and any(r.lifted for r in records):
                break
            self.ctx.say(f"fuse: round {t}: the belief after the joint angles (Eq. 4.5), the next grasp (Eq. 4.6)")
            up = planner.observe(last.execution.action, Reading(last.measurement, held=bool(last.lifted)))
            with heartbeat(self.ctx.progress, f"fuse: round {t}"):
                plan = planner.plan()
            records.append(self._round(t, plan.action, belief, plan, up.underflow))
            if on_round:
                on_round(records[-1])
        return FusionResult(mode, records, list(self.names), self.w0)

    def measurement(self, e: TopGraspExecution) -> np.ndarray:
        """The modelled joint angles of an executed grasp (what the models read)."""
        return e.joint_angles[self.models[0].joint_index]

    def _round(self, t: int, action, belief: ModelMixtureBelief, plan=None, underflow: bool = False) -> FusionRound:
        """Round ``t``: ``action`` executed, with the belief it was planned from (copied now)."""
        e = top_grasp(self.world, np.asarray(action, float), self.pose, self.spread)
        return FusionRound(t, e, self.measurement(e), belief.weights.tolist(), belief.poses.tolist(), underflow, plan)
