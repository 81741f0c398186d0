"""The closed loop of thesis Figs. 3.1 and 3.4 with the robot outside: an episode on disk.

``new`` writes the belief's settings to a directory and plans the first grasp; the robot executes
it and ``observe`` takes what its fingers read and whether the object came up, updates the belief
(Pub. II-IV) and plans the next grasp. The planner is the one :func:`~.episode.run_episode` uses,
with the same seeds, so an outside loop whose robot is the simulator gives the in-process loop's
grasps and beliefs bit for bit.

The state on disk (``episode.json``) is the episode's settings and its log of observations; the
belief is rebuilt by replaying the log through the planner (plan, observe, ...), and every
replayed grasp must equal the recorded one, which also catches other models or another version.
The file is versioned, carries the SHA-256 of its content, and is replaced atomically; a lock
file keeps two writers apart. A call that fails leaves the directory as it was.
"""
from __future__ import annotations

import dataclasses
import fcntl
import hashlib
import json
from contextlib import contextmanager
from pathlib import Path
from typing import Optional, Sequence, Union

import numpy as np

from .. import __version__
from ..cache import atomic_write_text
from ..hand import Hand
from ..io.grasp_schema import hand_grasp_record
from ..models import GraspModels, ModelSettings, relative_top_grasps
from ..objects import ObjectModel, load_object
from ..planners import PlannerSettings, make_planner
from ..world import World
from .context import RunContext

STATE_FILE = "episode.json"
LOCK_FILE = ".lock"
FORMAT = 1
METHODS = ("stability", "explore")
JOINT_LIMIT_SLACK = 0.02   # rad a reading may lie beyond the hand file's limits (encoder noise)


class EpisodeError(ValueError):
    """A refused episode call (bad input, damaged or foreign state, a busy episode)."""


# ---- the state file -----------------------------------------------------------------------------
def _digest(state: dict) -> str:
    return hashlib.sha256(json.dumps(state, sort_keys=True).encode()).hexdigest()


def _write(directory: Path, state: dict) -> None:
    atomic_write_text(directory / STATE_FILE, json.dumps({"sha256": _digest(state), "state": state}, indent=1))


def _read(directory: Path) -> dict:
    path = directory / STATE_FILE
    if not path.is_file():
        raise EpisodeError(f"{directory}: no episode here (no {STATE_FILE}; start one with `episode new`)")
    try:
        doc = json.loads(path.read_text())
        state, digest = doc["state"], doc["sha256"]
    except (OSError, ValueError, KeyError, TypeError) as e:
        raise EpisodeError(f"{path}: damaged or half-written ({type(e).__name__}); the episode cannot be read") from None
    if _digest(state) != digest:
        raise EpisodeError(f"{path}: damaged (its checksum does not match its content)")
    if state.get("format") != FORMAT or state.get("bayesgrasp") != __version__:
        raise EpisodeError(f"{path}: written by bayesgrasp {state.get('bayesgrasp')} (state format "
                           f"{state.get('format')}); this is {__version__} (format {FORMAT}): start a new episode")
    return state


@contextmanager
def _locked(directory: Path):
    """Holds the episode's lock file; a second writer is refused at once."""
    directory.mkdir(parents=True, exist_ok=True)
    with open(directory / LOCK_FILE, "a") as f:
        try:
            fcntl.flock(f, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            raise EpisodeError(f"{directory}: another process is writing this episode; try again when it is done") \
                from None
        try:
            yield
        finally:
            fcntl.flock(f, fcntl.LOCK_UN)


# ---- checked inputs -----------------------------------------------------------------------------
def check_joints(joints, hand: Hand) -> np.ndarray:
    """The robot's joint reading: one finite angle (rad) per hand joint, within the hand's limits."""
    q = np.asarray(joints, dtype=float).ravel()
    names = hand.joint_names
    if q.size != len(names):
        raise EpisodeError(f"--joints: {hand.name} has {len(names)} joints ({', '.join(names)}), got {q.size} values")
    if not np.all(np.isfinite(q)):
        raise EpisodeError(f"--joints: values must be finite, got {q.tolist()}")
    lim = np.asarray(hand.joint_limits, dtype=float)
    bad = [i for i in range(q.size) if not lim[i, 0] - JOINT_LIMIT_SLACK <= q[i] <= lim[i, 1] + JOINT_LIMIT_SLACK]
    if bad:
        i = bad[0]
        raise EpisodeError(f"--joints: {names[i]} = {q[i]:g} lies outside its limits [{lim[i, 0]:.3f}, {lim[i, 1]:.3f}] "
                           "rad (degrees instead of radians?)")
    return q


def check_lifted(text: Union[str, bool]) -> bool:
    if isinstance(text, bool):
        return text
    t = str(text).strip().lower()
    if t in ("yes", "true", "1"):
        return True
    if t in ("no", "false", "0"):
        return False
    raise EpisodeError(f"--lifted: yes or no, got {text!r}")


# ---- the episode --------------------------------------------------------------------------------
class PoseEpisode:
    """An episode under pose uncertainty (Pub. II-IV) whose grasps a robot outside executes.

    ``PoseEpisode.new(directory, "mug", estimate, ctx)`` starts it; ``episode.next`` is the grasp
    to execute; ``episode.observe(joints, lifted)`` feeds back the robot's reading (every hand
    joint, rad) and the lift verdict and returns the next grasp (None when the episode ended);
    ``PoseEpisode.open(directory)`` resumes it in a later process."""

    def __init__(self, directory: Path, state: dict, ctx: RunContext, obj: Optional[ObjectModel] = None):
        self.directory, self.state, self.ctx = Path(directory), state, ctx
        self.object = obj if obj is not None else load_object(state["object"])
        self.hand = Hand.load(ctx.hand)
        self.models: GraspModels = ctx.models(obj if obj is not None else state["object"])
        if self.models.info.get("key") != state["models_key"]:
            raise EpisodeError(f"{self.directory}: the episode was planned with other models (key "
                               f"{state['models_key']}, now {self.models.info.get('key')}): same --hand, --cache "
                               "and --set as at `episode new`")
        self.planner = self._replay()

    # ---- making and opening ----
    @classmethod
    def new(cls, directory, obj: Union[str, ObjectModel], estimate: Sequence[float], ctx: RunContext,
            method: str = "explore", attempts: int = 4, seed: int = 0,
            planner: Optional[PlannerSettings] = None) -> "PoseEpisode":
        directory = Path(directory)
        if method not in METHODS:
            raise EpisodeError(f"--method: one of {', '.join(METHODS)}; got {method!r}")
        if attempts < 1:
            raise EpisodeError(f"--attempts: must be at least 1, got {attempts}")
        if (directory / STATE_FILE).exists():
            raise EpisodeError(f"{directory}: already holds an episode (remove it or pick another --dir)")
        if ctx.success != "lift":
            raise EpisodeError("--success: an episode's success is the robot's lift verdict (success 'lift')")
        est = np.asarray(estimate, dtype=float).ravel()
        if est.shape != (3,) or not np.all(np.isfinite(est)):
            raise EpisodeError(f"--estimate: expected three finite numbers (x, y, yaw), got {estimate}")
        settings = planner or PlannerSettings()
        obj_model = load_object(obj) if isinstance(obj, str) else obj
        models = ctx.models(obj if isinstance(obj, str) else obj_model)
        state = {"format": FORMAT, "bayesgrasp": __version__, "kind": "pose",
                 "object": obj if isinstance(obj, str) else obj_model.name, "hand": ctx.hand,
                 "models_key": models.info.get("key"), "cache": ctx.cache_dir,
                 "model_settings": None if ctx.model_settings is None else dataclasses.asdict(ctx.model_settings), "method": method, "attempts": int(attempts), "seed": int(seed),
                 "estimate": est.tolist(), "planner": _planner_json(settings), "steps": [], "next": None,
                 "status": "open"}
        episode = cls(directory, state, ctx, obj_model)
        with _locked(directory):
            if (directory / STATE_FILE).exists():
                raise EpisodeError(f"{directory}: already holds an episode (remove it or pick another --dir)")
            episode._plan_next()
            _write(directory, episode.state)
        return episode

    @classmethod
    def open(cls, directory, cache_dir: Optional[str] = None, progress=None) -> "PoseEpisode":
        """The episode in ``directory``, with the hand, success criterion and model settings it
        was started with (the model cache: ``cache_dir``, default the one at ``new``)."""
        directory = Path(directory)
        state = _read(directory)
        ms = state["model_settings"]
        ctx = RunContext(hand=state["hand"], cache_dir=cache_dir or state["cache"], progress=progress,
                         model_settings=None if ms is None else ModelSettings(**ms))
        return cls(directory, state, ctx)

    # ---- the loop ----
    @property
    def next(self) -> Optional[dict]:
        return self.state["next"]

    @property
    def finished(self) -> bool:
        return self.state["status"] != "open"

    def observe(self, joints, lifted) -> Optional[dict]:
        """The robot executed :attr:`next`; its fingers read ``joints`` and the object came up
        (``lifted``) or not. Updates the belief (unless it was lifted: the episode ends), plans
        the next grasp and writes the state; on any error nothing is written."""
        if self.finished:
            raise EpisodeError(f"{self.directory}: the episode is finished ({self.state['status']}); nothing to observe")
        q = check_joints(joints, self.hand)
        up = check_lifted(lifted)
        with _locked(self.directory):
            if _read(self.directory) != self.state:
                raise EpisodeError(f"{self.directory}: changed by another process since it was opened; open it again")
            state = json.loads(json.dumps(self.state))
            action = np.asarray(state["next"]["top_grasp"], dtype=float)
            measurement = q[self.models.joint_index]
            step = {"attempt": len(state["steps"]) + 1, "top_grasp": action.tolist(), "joints": q.tolist(),
                    "lifted": up}
            if not up:
                self.planner.observe(action, measurement, stable=False)
                step["belief_after"] = self.planner.summary()
            state["steps"].append(step)
            self.state = state
            if up:
                state["status"], state["next"] = "success", None
            elif len(state["steps"]) >= state["attempts"]:
                state["status"], state["next"] = "failed", None
            else:
                self._plan_next()
            _write(self.directory, state)
        return self.next

    def belief(self) -> dict:
        """The belief now: the summary, and the SHA-256 of its particles and weights (bit-for-bit checks)."""
        b = self.planner.belief
        out = self.planner.summary()
        out["particles_sha256"] = hashlib.sha256(np.ascontiguousarray(b.particles).tobytes()
                                                 + np.ascontiguousarray(b.weights).tobytes()).hexdigest()
        return out

    # ---- named steps ----
    def _make_planner(self):
        s = self.state
        rng = np.random.default_rng(s["seed"])   # run_episode's: with an estimate given, one draw for the planner
        return make_planner(s["method"], self.models, np.asarray(s["estimate"], dtype=float),
                            PlannerSettings(**s["planner"]), seed=int(rng.integers(2**31)))

    def _replay(self):
        """The planner after the logged steps: every replayed plan must give the logged grasp."""
        planner = self._make_planner()
        for step in self.state["steps"]:
            if step["lifted"]:
                break
            plan = planner.plan()
            if plan.action.tolist() != step["top_grasp"]:
                raise EpisodeError(f"{self.directory}: replaying attempt {step['attempt']} planned another grasp than "
                                   "the one recorded (other models, settings or version)")
            planner.observe(plan.action, np.asarray(step["joints"])[self.models.joint_index], stable=False)
        if self.state["next"] is not None:
            plan = planner.plan()
            if plan.action.tolist() != self.state["next"]["top_grasp"]:
                raise EpisodeError(f"{self.directory}: replaying the pending grasp planned another one than the one "
                                   "recorded (other models, settings or version)")
        return planner

    def _plan_next(self) -> None:
        plan = self.planner.plan()
        self.state["next"] = {"attempt": len(self.state["steps"]) + 1, "kind": plan.kind,
                              "top_grasp": plan.action.tolist(), "predicted_stability": float(plan.predicted_stability),
                              "expected_entropy": plan.expected_entropy,
                              "grasp": self._predicted_grasp(plan.action), "belief": self.planner.summary()}

    def _predicted_grasp(self, action: np.ndarray) -> dict:
        """The top grasp as the schema's world-frame grasp: where the hand closes and how, simulated
        on the object at the belief's mean pose (the robot descends along -z until contact)."""
        mean = self.planner.belief.mean()
        try:
            world = World.single(self.object, pose=mean, hand=self.ctx.hand)
        except ValueError:   # the mean pose is off the table: the palm at the object's height
            T = Hand.top_grasp_pose(*action, float(self.object.vertices[:, 2].max()))
            return hand_grasp_record(self.hand, T, self.hand.open_joints(self.models.spread), self.models.spread)
        rel = relative_top_grasps(action, mean)[0, 0]
        g = world.grasp_batch(rel[None, :], spread=self.models.spread, lift=False)
        return hand_grasp_record(self.hand, g.hand_pose[0], g.joint_angles[0], self.models.spread)


def _planner_json(settings: PlannerSettings) -> dict:
    return {k: (list(v) if isinstance(v, tuple) else v) for k, v in dataclasses.asdict(settings).items()}
