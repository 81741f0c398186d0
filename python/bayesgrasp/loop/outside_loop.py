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
from ..hand import Hand, builtin_hands
from ..arm import Arm
from ..io.grasp_schema import hand_grasp_record
from ..models import GraspModels, ModelSettings, relative_top_grasps
from ..objects import ObjectModel, load_object, object_params
from ..planners import PlannerSettings, Reading, make_planner
from ..planners.registry import EPISODE_METHODS
from ..world import World
from ..planners.reach import ActionReach
from .context import RunContext
from .reach import arm_from_state, arm_state, with_arm

STATE_FILE = "episode.json"
LOCK_FILE = ".lock"
FORMAT = 1
METHODS = EPISODE_METHODS   # the pose methods an episode offers, as the registry declares them
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


def check_builtin_object(name: str, what: str = "object") -> str:
    """``name`` if it is a built-in object's (``mug``, ``mug/3``): never a file."""
    if not isinstance(name, str) or object_params(name) is None:
        raise EpisodeError(f"{what}: not a built-in object name, got {name!r} (see `bayesgrasp objects`)")
    return name


def check_builtin_hand(name: str, what: str = "hand") -> str:
    """``name`` if it is a built-in hand's (``barrett_bh8``, ``barrett_bh8.urdf``): never a file."""
    if name not in builtin_hands():
        raise EpisodeError(f"{what}: not a built-in hand, got {name!r} (built-in: {', '.join(builtin_hands())})")
    return name


def check_lifted(text: Union[str, bool]) -> bool:
    if isinstance(text, bool):
        return text
    t = str(text).strip().lower()
    if t in ("yes", "true", "1"):
        return True
    if t in ("no", "false", "0"):
        return False
    raise EpisodeError(f"--lifted: yes or no, got {text!r}")


# ---- what every episode on disk shares ----------------------------------------------------------
class DiskEpisode:
    """An episode on disk whose grasps a robot outside executes: ``next`` is the grasp to execute,
    ``observe(joints, lifted)`` feeds back the robot's reading (every hand joint, rad) and the lift
    verdict and returns the next grasp (None when the episode ended). A kind supplies
    ``_replay`` (its planner after the logged steps), ``_absorb`` (one reading into the belief),
    ``_plan_next`` and ``belief``. ``open`` resumes one in a later process (any kind:
    :func:`~.outside_loop_category.open_episode`)."""

    kind = ""

    def __init__(self, directory: Path, state: dict, ctx: RunContext):
        self.directory, self.state, self.ctx = Path(directory), state, ctx
        self.hand = ctx.hand_model
        #: the arm the hand is on (``episode new --robot``), as stored at ``new``; None: free-floating
        self.arm = None
        if "arm" in state:
            try:
                self.arm = arm_from_state(state["arm"], str(self.directory))
            except ValueError as e:
                raise EpisodeError(str(e)) from None

    @staticmethod
    def _base_state(kind: str, ctx: RunContext, attempts: int, seed: int, arm: Optional[Arm] = None) -> dict:
        """The state every kind starts from; with ``arm``, its ``arm`` (an episode without one has no key)."""
        if attempts < 1:
            raise EpisodeError(f"--attempts: must be at least 1, got {attempts}")
        if ctx.success != "lift":
            raise EpisodeError("--success: an episode's success is the robot's lift verdict (success 'lift')")
        if arm is not None and not isinstance(arm, Arm):
            raise EpisodeError(f"--robot: expected a bayesgrasp.arm.Arm, got {type(arm).__name__}")
        state = {"format": FORMAT, "bayesgrasp": __version__, "kind": kind, "hand": ctx.hand, "cache": ctx.cache_dir,
                 "model_settings": None if ctx.model_settings is None else dataclasses.asdict(ctx.model_settings),
                 "attempts": int(attempts), "seed": int(seed), "steps": [], "next": None, "status": "open"}
        if arm is not None:
            state["arm"] = arm_state(arm)
        return state

    @classmethod
    def open(cls, directory, cache_dir: Optional[str] = None, progress=None) -> "DiskEpisode":
        """The episode in ``directory``, with the hand, success criterion and model settings it
        was started with (the model cache: ``cache_dir``, default the one at ``new``)."""
        state, ctx = open_state(directory, cache_dir, progress)
        if state.get("kind") != cls.kind:
            raise EpisodeError(f"{directory}: a {state.get('kind')} episode, not a {cls.kind} one")
        return cls(directory, state, ctx)

    def _create(self, before_write=None) -> None:
        """Plans the first grasp and writes the new episode (refused if the directory holds one)."""
        with _locked(self.directory):
            if (self.directory / STATE_FILE).exists():
                raise EpisodeError(f"{self.directory}: already holds an episode (remove it or pick another --dir)")
            self._plan_next()
            if before_write:
                before_write()
            _write(self.directory, self.state)

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
            step = {"attempt": len(state["steps"]) + 1, **self._executed(state["next"]), "joints": q.tolist(),
                    "lifted": up}
            if not up:
                self._absorb(step, q)
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

    def _executed(self, nxt: dict) -> dict:
        """What a step records of the grasp the robot executed (default: its top grasp)."""
        return {"top_grasp": nxt["top_grasp"]}

    def _check_replayed(self, what: str, planned, recorded) -> None:
        if planned != recorded:
            raise EpisodeError(f"{self.directory}: replaying {what} planned another grasp than the one recorded "
                               "(other models, settings or version)")


def open_state(directory, cache_dir: Optional[str] = None, progress=None):
    """An episode's checked state and the run context it was started with."""
    state = _read(Path(directory))
    ms = state["model_settings"]
    ctx = RunContext(hand=state["hand"], cache_dir=cache_dir or state["cache"], progress=progress,
                     model_settings=None if ms is None else ModelSettings(**ms))
    return state, ctx


def predicted_top_grasp(hand: Hand, hand_name: str, obj, pose, action, spread: float) -> dict:
    """A top grasp (x, y, yaw) as the schema's world-frame grasp: where the hand closes and how,
    simulated on ``obj`` at ``pose`` (the robot descends along -z until contact)."""
    obj = load_object(obj) if isinstance(obj, str) else obj
    try:
        world = World.single(obj, pose=pose, hand=hand_name)
    except ValueError:   # the pose is off the table: the palm at the object's height
        T = Hand.top_grasp_pose(*action, float(obj.vertices[:, 2].max()))
        return hand_grasp_record(hand, T, hand.open_joints(spread), spread)
    rel = relative_top_grasps(np.asarray(action, float), np.asarray(pose, float))[0, 0]
    g = world.grasp_batch(rel[None, :], spread=spread, lift=False)
    return hand_grasp_record(hand, g.hand_pose[0], g.joint_angles[0], spread)


def particles_digest(*arrays) -> str:
    """SHA-256 of a belief's arrays (bit-for-bit checks)."""
    return hashlib.sha256(b"".join(np.ascontiguousarray(a, dtype=float).tobytes() for a in arrays)).hexdigest()


def _stored_name(obj: ObjectModel) -> str:
    """How an episode's state names an object to load it again: a mesh file by its path, a
    built-in by its name."""
    return obj.source if obj.source and Path(obj.source).is_file() else obj.name


# ---- the pose-uncertainty episode (Pub. II-IV) --------------------------------------------------
class PoseEpisode(DiskEpisode):
    """An episode under pose uncertainty (Pub. II-IV): ``PoseEpisode.new(directory, "mug",
    estimate, ctx)`` starts it; ``PoseEpisode.open(directory)`` resumes it."""

    kind = "pose"

    def __init__(self, directory: Path, state: dict, ctx: RunContext, obj: Optional[ObjectModel] = None):
        super().__init__(directory, state, ctx)
        units = state.get("units")                      # a mesh file in mm or cm is read in its unit again
        self.object = obj if obj is not None else load_object(state["object"], units=units)
        self.models: GraspModels = ctx.models(obj if obj is not None else self.object if units else state["object"])
        if self.models.info.get("key") != state["models_key"]:
            raise EpisodeError(f"{self.directory}: the episode was planned with other models (key "
                               f"{state['models_key']}, now {self.models.info.get('key')}): same --hand, --cache "
                               "and --set as at `episode new`")
        self.planner = self._replay()

    @classmethod
    def new(cls, directory, obj: Union[str, ObjectModel], estimate: Sequence[float], ctx: RunContext,
            method: str = "explore", attempts: int = 4, seed: int = 0,
            planner: Optional[PlannerSettings] = None, units: Optional[str] = None,
            arm: Optional[Arm] = None) -> "PoseEpisode":
        """``obj``: a built-in name, a mesh file or an ObjectModel (a file's is stored by its path);
        ``units``: the mesh file's length unit, stored so that a later process reads it alike;
        ``arm``: the arm the hand is on (stored): the planner weighs only the grasps it reaches
        (while it has met a reachable one; else, as the planner documents, the most stable) and each
        grasp carries its ``arm``."""
        episode = cls._unwritten(Path(directory), obj, estimate, ctx, method, attempts, seed, planner, units, arm)
        episode._create()
        return episode

    @classmethod
    def first_grasp(cls, obj: Union[str, ObjectModel], estimate: Sequence[float], ctx: RunContext,
                    method: str = "explore", seed: int = 0, planner: Optional[PlannerSettings] = None) -> dict:
        """The grasp :meth:`new` would plan first (its ``next``), written nowhere: a one-shot question."""
        episode = cls._unwritten(Path("<one-shot>"), obj, estimate, ctx, method, 1, seed, planner, None, None)
        episode._plan_next()
        return episode.next

    @classmethod
    def _unwritten(cls, directory: Path, obj, estimate, ctx: RunContext, method: str, attempts: int, seed: int,
                   planner: Optional[PlannerSettings], units: Optional[str], arm: Optional[Arm]) -> "PoseEpisode":
        """The new episode with its planner, before its first plan and before anything is written."""
        if method not in METHODS:
            raise EpisodeError(f"--method: one of {', '.join(METHODS)}; got {method!r}")
        if (directory / STATE_FILE).exists():
            raise EpisodeError(f"{directory}: already holds an episode (remove it or pick another --dir)")
        state = cls._base_state(cls.kind, ctx, attempts, seed, arm)
        est = np.asarray(estimate, dtype=float).ravel()
        if est.shape != (3,) or not np.all(np.isfinite(est)):
            raise EpisodeError(f"--estimate: expected three finite numbers (x, y, yaw), got {estimate}")
        settings = planner or PlannerSettings()
        obj_model = load_object(obj, units=units) if isinstance(obj, str) else obj
        models = ctx.models(obj if isinstance(obj, str) and not units else obj_model)
        stored = obj if isinstance(obj, str) else _stored_name(obj_model)
        if units:
            state["units"] = units
        state.update({"object": stored, "models_key": models.info.get("key"),
                      "method": method, "estimate": est.tolist(), "planner": settings_json(settings)})
        return cls(directory, state, ctx, obj_model)

    def belief(self) -> dict:
        """The belief now: the summary, and the SHA-256 of its particles and weights (bit-for-bit checks)."""
        b = self.planner.belief
        out = self.planner.summary()
        out["particles_sha256"] = particles_digest(b.particles, b.weights)
        return out

    # ---- named steps ----
    def _make_planner(self):
        s = self.state
        rng = np.random.default_rng(s["seed"])   # run_episode's: with an estimate given, one draw for the planner
        planner = make_planner(s["method"], self.models, np.asarray(s["estimate"], dtype=float),
                               PlannerSettings(**s["planner"]), seed=int(rng.integers(2**31)))
        if self.arm is not None:      # Eqs. 3.1, 3.2 over the grasps the arm reaches
            planner.reach = ActionReach(self.arm, self.object, self.ctx.hand)
        return planner

    def _replay(self):
        """The planner after the logged steps: every replayed plan must give the logged grasp."""
        planner = self._make_planner()
        for step in self.state["steps"]:
            if step["lifted"]:
                break
            plan = planner.plan()
            self._check_replayed(f"attempt {step['attempt']}", plan.action.tolist(), step["top_grasp"])
            planner.observe(plan, Reading(np.asarray(step["joints"])[self.models.joint_index], held=False))
        if self.state["next"] is not None:
            self._check_replayed("the pending grasp", planner.plan().action.tolist(), self.state["next"]["top_grasp"])
        return planner

    def _absorb(self, step: dict, q: np.ndarray) -> None:
        grasp = np.asarray(step["top_grasp"], dtype=float)
        self.planner.observe(grasp, Reading(q[self.models.joint_index], held=False))
        step["belief_after"] = self.planner.summary()

    def _plan_next(self) -> None:
        plan = self.planner.plan()
        mean = self.planner.belief.mean()
        grasp = predicted_top_grasp(self.hand, self.ctx.hand, self.object, mean, plan.action, self.models.spread)
        if self.arm is not None:      # the arm checked against the table and the object at the belief's mean
            try:
                world = self.planner.reach.world(mean)
                mesh = (world.vertices, world.faces)
            except ValueError:        # the mean is off the table: the table only
                mesh = None
            grasp = with_arm(self.arm, grasp, mesh)
        self.state["next"] = {"attempt": len(self.state["steps"]) + 1, "kind": plan.kind,
                              "top_grasp": plan.action.tolist(), "predicted_stability": float(plan.predicted_stability),
                              "expected_entropy": plan.expected_entropy, "grasp": grasp,
                              "belief": self.planner.summary()}


def settings_json(settings) -> dict:
    """A settings dataclass as JSON (tuples as lists)."""
    return {k: (list(v) if isinstance(v, tuple) else v) for k, v in dataclasses.asdict(settings).items()}
