"""Episodes on disk for a new object of a known category (thesis ch. 4), the robot outside:

- :class:`CategoryTaskEpisode` (Pub. V, §4.2): one view, registration against the category's
  training models, Eq. 4.1's task grasp; the robot executes it and reports joints and lift. Pub. V
  plans once from the view, so the episode ends with that one grasp (for re-planning from touch,
  take the vision-then-touch episode).
- :class:`FusionEpisode` (Pub. VI, §4.3): the same view gives w_i(0) and p_i(0); each reading of
  the fingers updates every model's pose and weight (Eqs. 4.4-4.5) and the next grasp maximises
  stability x task (Eq. 4.6), as :class:`~.fusion_trial.FusionTrial` in ``vision`` mode.

The view (the object's cloud in the table frame and the camera centre) is stored once as
``view.npz`` beside ``episode.json``, whose state carries its SHA-256; the demonstrated grasps
used are stored in the state. Opening an episode registers the view again and replays the log;
every replayed grasp must equal the recorded one (see :mod:`.outside_loop`).
"""
from __future__ import annotations

import hashlib
from pathlib import Path
from typing import Optional, Sequence

import numpy as np

from ..cache import atomic_write
from ..models.task_grasps import grasp_from_json, grasp_to_json
from ..models.tasks import task_rule
from ..planners.category import THESIS_METHODS
from ..planners.fusion import METHOD as FUSION, FusionSettings
from .category import Observation, demonstrated, plan_and_execute, see, training_models
from .category_result import TaskGraspResult
from .context import RunContext
from .outside_loop import (STATE_FILE, DiskEpisode, EpisodeError, PoseEpisode, open_state, particles_digest,
                           predicted_top_grasp, settings_json)
from .fusion_trial import FusionTrial
from .reach import table_reach, top_reach, with_arm

VIEW_FILE = "view.npz"
CATEGORY_METHODS = THESIS_METHODS   # the planners that plan once from a view (fusion: its own episode)
#: every method a category episode takes: the task grasp's (one grasp) and vision then touch
EPISODE_CATEGORY_METHODS = CATEGORY_METHODS + (FUSION,)


# ---- the stored view ----------------------------------------------------------------------------
def _view_bytes_digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def _write_view(directory: Path, observation: Observation) -> str:
    """``view.npz`` written atomically; returns its SHA-256."""
    def write(tmp: Path) -> None:
        with open(tmp, "wb") as f:
            np.savez(f, cloud=np.asarray(observation.cloud, float), viewpoint=np.asarray(observation.viewpoint, float))
    directory.mkdir(parents=True, exist_ok=True)
    atomic_write(directory / VIEW_FILE, write)
    return _view_bytes_digest(directory / VIEW_FILE)


def _read_view(directory: Path, digest: str) -> Observation:
    path = directory / VIEW_FILE
    if not path.is_file():
        raise EpisodeError(f"{directory}: the episode's view ({VIEW_FILE}) is missing")
    if _view_bytes_digest(path) != digest:
        raise EpisodeError(f"{path}: damaged (its checksum does not match the episode's)")
    with np.load(path) as z:
        return Observation(z["cloud"], z["viewpoint"])


def _check_observation(observation: Observation) -> None:
    P = np.asarray(observation.cloud, float)
    if P.ndim != 2 or P.shape[1] != 3 or len(P) < 10 or not np.all(np.isfinite(P)):
        raise EpisodeError(f"view: expected an (N, 3) finite cloud with N >= 10, got shape {P.shape}")


class _CategoryBase(DiskEpisode):
    """What both category episodes share: the stored view, its registrations, the task's grasps."""

    def __init__(self, directory: Path, state: dict, ctx: RunContext, observation: Optional[Observation] = None):
        super().__init__(directory, state, ctx)
        self.observation = observation if observation is not None else _read_view(self.directory, state["view_sha256"])
        self.grasps = [grasp_from_json(g) for g in state["task_grasps"]]

    @classmethod
    def _new_state(cls, directory: Path, observation: Observation, category: str, task: str, ctx: RunContext,
                   attempts: int, exclude: Sequence[str], seed: int, grasps, arm=None) -> dict:
        if (directory / STATE_FILE).exists():
            raise EpisodeError(f"{directory}: already holds an episode (remove it or pick another --dir)")
        _check_observation(observation)
        try:
            rule = task_rule(category, task)
            models = training_models(category, exclude)
        except ValueError as e:
            raise EpisodeError(str(e)) from None
        state = cls._base_state(cls.kind, ctx, attempts, seed, arm)
        grasps = demonstrated(models, rule, ctx) if grasps is None else grasps
        grasps = [g for g in grasps if g.task == task and g.model in models]
        if not grasps:
            raise EpisodeError(f"--task-grasps: no demonstrated {task} grasp on the training models {models}")
        state.update({"category": category, "task": task, "exclude": list(exclude), "view_sha256": None,
                      "task_grasps": [grasp_to_json(g) for g in grasps]})
        return state

    def _start(self) -> None:
        """Plans the first grasp and writes the view and the state (nothing when planning fails)."""
        def write_view():
            self.state["view_sha256"] = _write_view(self.directory, self.observation)
        self._create(before_write=write_view)

    def _see(self):
        ep = see(None, (0.0, 0.0, 0.0), self.state["category"], exclude=self.state["exclude"], seed=self.state["seed"],
                 observation=self.observation)
        if not any(r.success for r in ep.registrations):
            raise EpisodeError("no training model registered to the view (is the object in view, of this category?)")
        return ep


# ---- one task grasp (Pub. V) --------------------------------------------------------------------
class CategoryTaskEpisode(_CategoryBase):
    """Eq. 4.1's task grasp from one view, executed by the robot: one attempt (Pub. V)."""

    kind = "category"

    def __init__(self, directory: Path, state: dict, ctx: RunContext, observation: Optional[Observation] = None):
        super().__init__(directory, state, ctx, observation)
        self.plan = None
        self._replay()

    @classmethod
    def new(cls, directory, observation: Observation, category: str, task: str, ctx: RunContext,
            method: str = "laplace", exclude: Sequence[str] = (), seed: int = 0, grasps=None,
            arm=None) -> "CategoryTaskEpisode":
        """``arm``: the arm the hand is on (stored): Eq. 4.1 over the grasps it reaches against the
        table, and the grasp carries its ``arm``."""
        directory = Path(directory)
        if method not in CATEGORY_METHODS:
            raise EpisodeError(f"--method: with --category one of {', '.join(EPISODE_CATEGORY_METHODS)}; "
                               f"got {method!r}")
        state = cls._new_state(directory, observation, category, task, ctx, 1, exclude, seed, grasps, arm)
        state["method"] = method
        episode = cls(directory, state, ctx, observation)
        episode._start()
        return episode

    def _planned(self) -> TaskGraspResult:
        s = self.state
        return plan_and_execute(self._see(), s["category"], s["task"], s["method"], self.ctx, seed=s["seed"],
                                grasps=self.grasps, reach=None if self.arm is None else table_reach(self.arm))

    def _replay(self) -> None:
        if self.state["steps"] or self.state["next"] is not None:
            self.plan = self._planned()
            recorded = (self.state["steps"][0] if self.state["steps"] else self.state["next"])["planned_pose"]
            self._check_replayed("the task grasp", self.plan.planned_pose, recorded)

    def _executed(self, nxt: dict) -> dict:
        return {"planned_pose": nxt["planned_pose"]}

    def _absorb(self, step: dict, q: np.ndarray) -> None:
        """Pub. V has no update from touch: the reading is recorded, the episode ends."""

    def _plan_next(self) -> None:
        r = self.plan = self._planned()
        if not r.plan.ok:
            raise EpisodeError(f"no task grasp: {r.outcome.reason or 'the plan failed'}")
        p = r.plan
        grasp = r.planned_grasp(self.hand)
        if self.arm is not None:      # against the table (the object's mesh is not known)
            grasp = with_arm(self.arm, grasp)
        self.state["next"] = {"attempt": 1, "kind": "task", "planned_pose": r.planned_pose, "grasp": grasp,
                              "objective": p.objective, "weights": p.weights,
                              "contributions": p.contributions, "dominant_model": p.dominant_model}

    def belief(self) -> dict:
        """The registrations' weights and contributions to the planned grasp."""
        if self.plan is None:
            return {"weights": None, "contributions": None, "dominant_model": None}
        p = self.plan.plan
        return {"weights": p.weights, "contributions": p.contributions, "dominant_model": p.dominant_model}


# ---- vision then touch (Pub. VI) ----------------------------------------------------------------
class FusionEpisode(_CategoryBase):
    """Vision, then touch (Pub. VI): per-model weights and poses updated by each reading."""

    kind = "fusion"

    def __init__(self, directory: Path, state: dict, ctx: RunContext, observation: Optional[Observation] = None):
        super().__init__(directory, state, ctx, observation)
        s = state
        settings = FusionSettings(**s["fusion"])
        try:
            self.trial = FusionTrial(None, (0.0, 0.0, 0.0), ctx, task=s["task"], settings=settings,
                                     exclude=s["exclude"], seed=s["seed"], grasps=self.grasps,
                                     category=s["category"], observation=self.observation)
        except ValueError as e:
            raise EpisodeError(str(e)) from None
        if self.arm is not None:      # Eq. 4.6 over the top grasps the arm reaches
            self.trial.reach = top_reach(self.arm, self.hand, self.observation.cloud)
        keys = [m.info.get("key") for m in self.trial.models]
        if s.get("models_keys") is None:
            s["models_keys"] = keys
        elif keys != s["models_keys"]:
            raise EpisodeError(f"{self.directory}: the episode was planned with other models: same --hand, --cache "
                               "and --set as at `episode new`")
        _, self.planner = self.trial.start()
        self._replay()

    @classmethod
    def new(cls, directory, observation: Observation, category: str, task: str, ctx: RunContext,
            attempts: int = 4, exclude: Sequence[str] = (), seed: int = 0, grasps=None,
            settings: Optional[FusionSettings] = None, arm=None) -> "FusionEpisode":
        """``arm``: the arm the hand is on (stored): Eq. 4.6 over the top grasps it reaches against
        the table, and each grasp carries its ``arm``."""
        directory = Path(directory)
        state = cls._new_state(directory, observation, category, task, ctx, attempts, exclude, seed, grasps, arm)
        s = settings or FusionSettings()
        state.update({"method": FUSION, "models_keys": None,
                      "fusion": settings_json(s)})
        episode = cls(directory, state, ctx, observation)
        episode._start()
        return episode

    def _replay(self) -> None:
        """Round 0 from the view (the task term), then one update and re-plan per logged reading."""
        for step in self.state["steps"]:
            self._check_replayed(f"round {step['attempt'] - 1}", self.planner.plan().action.tolist(),
                                 step["top_grasp"])
            if step["lifted"]:
                return
            self.planner.observe(np.asarray(step["top_grasp"], float), self._measurement(step["joints"]))
        if self.state["next"] is not None:
            self._check_replayed("the pending grasp", self.planner.plan().action.tolist(),
                                 self.state["next"]["top_grasp"])

    def _measurement(self, joints) -> np.ndarray:
        return np.asarray(joints, float)[self.trial.models[0].joint_index]

    def _absorb(self, step: dict, q: np.ndarray) -> None:
        up = self.planner.observe(np.asarray(step["top_grasp"], float), self._measurement(q))
        step["underflow"] = bool(up.underflow)
        step["belief_after"] = self.belief()

    def _plan_next(self) -> None:
        plan = self.planner.plan()
        w = self.planner.belief.weights
        best = int(np.argmax(w))
        grasp = predicted_top_grasp(self.hand, self.ctx.hand, self.trial.names[best], self.planner.belief.poses[best],
                                    plan.action, self.trial.spread)
        if self.arm is not None:      # against the table, as the planner's reach
            grasp = with_arm(self.arm, grasp)
        self.state["next"] = {"attempt": len(self.state["steps"]) + 1, "round": len(self.state["steps"]),
                              "kind": "vision" if plan.round == 1 else "touch", "top_grasp": plan.action.tolist(),
                              "objective": plan.objective, "stability": plan.stability, "task": plan.task,
                              "grasp": grasp, "belief": self.belief()}

    def belief(self) -> dict:
        """Each training model's weight and planar pose, and their SHA-256 (bit-for-bit checks)."""
        b = self.planner.belief
        return {"weights": dict(zip(self.trial.names, b.weights.tolist())),
                "poses": dict(zip(self.trial.names, b.poses.tolist())),
                "particles_sha256": particles_digest(b.weights, b.poses)}


#: Episode kinds by their state's "kind".
KINDS = {k.kind: k for k in (PoseEpisode, CategoryTaskEpisode, FusionEpisode)}


def open_episode(directory, cache_dir: Optional[str] = None, progress=None) -> DiskEpisode:
    """Any kind of episode in ``directory``: pose (Pub. II-IV), category task (Pub. V) or vision
    then touch (Pub. VI)."""
    state, ctx = open_state(directory, cache_dir, progress)
    kind = KINDS.get(state.get("kind"))
    if kind is None:
        raise EpisodeError(f"{directory}: an episode of unknown kind {state.get('kind')!r}")
    return kind(directory, state, ctx)
