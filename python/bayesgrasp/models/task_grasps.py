"""Demonstrated task grasps of the training models (thesis §4.2: "task-specific grasps stored as
object pose + hand pose with an automatically computed epsilon"), generated from the task rules
(:mod:`.tasks`) with the simulator, kept as data.

For each model and task: candidate approaches are drawn - a direction allowed by the rule (uniform
on the sphere, rejected outside the rule's cone or band), a roll uniform in [0, 2 pi), a target
point on a triangle of the rule's target parts (area-weighted) - at each candidate spread; the
simulator approaches and closes; grasps whose object contacts break the rule (a part not allowed,
too few contacts, too few on a required part), that started in collision or stopped on the table
are dropped; the best by epsilon are lift-tested, and the best ``keep`` that the lift test holds
(by epsilon) are stored: model, task, 6-DoF hand pose in the model's frame, spread, epsilon,
lifted. The set is cached per (model mesh, hand, rule, settings); a user can add hand-made grasps
in the same JSON format (:func:`load_task_grasp_file`).
"""
from __future__ import annotations

import hashlib
import json
import zlib
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Callable, List, Optional, Sequence, Union

import numpy as np

from .. import DEFAULT_HAND
from ..cache import atomic_write_text, load_cached
from ..objects import ObjectModel, load_object
from ..world import World
from ..objects.mass import cache_salt
from .settings import CACHE_VERSION
from .training import lift_tests_in_chunks
from .tasks import TaskGrasp, TaskRule

Say = Callable[[str], None]

#: Spreads (rad) the generator tries by default.
TASK_SPREADS = tuple(float(np.radians(d)) for d in (0.0, 30.0, 60.0, 90.0))


@dataclass(frozen=True)
class TaskGraspSettings:
    """candidates: approaches simulated per spread; spreads (rad); lift_tests: the best candidates
    by epsilon lift-tested per model and task; keep: grasps stored; standoff (m); seed."""

    candidates: int = 1500
    spreads: Sequence[float] = TASK_SPREADS
    lift_tests: int = 40
    keep: int = 5
    standoff: float = 0.0
    seed: int = 0

    def __post_init__(self):
        if self.candidates < 1 or self.lift_tests < 1 or self.keep < 1:
            raise ValueError("candidates, lift_tests, keep: must be at least 1")
        if not self.spreads or not all(np.isfinite(s) and 0 <= s <= np.pi for s in self.spreads):
            raise ValueError(f"spreads: need at least one spread in [0, pi], got {self.spreads}")


def _unit_rows(rng: np.random.Generator, n: int) -> np.ndarray:
    v = rng.normal(size=(n, 3))
    return v / np.linalg.norm(v, axis=1, keepdims=True)


def sample_directions(rule: TaskRule, n: int, rng: np.random.Generator, max_draws: int = 200) -> np.ndarray:
    """n approach directions allowed by the rule (rejection sampling, uniform on the sphere)."""
    out: List[np.ndarray] = []
    have = 0
    for _ in range(max_draws):
        d = _unit_rows(rng, 4 * n)
        d = d[rule.approach_ok(d)]
        out.append(d)
        have += len(d)
        if have >= n:
            return np.vstack(out)[:n]
    raise ValueError(f"task {rule.category}/{rule.name}: its approach constraints admit (almost) no direction")


def sample_rolls(hand, directions: np.ndarray, rng: np.random.Generator, spread_deg: float = 20.0) -> np.ndarray:
    """Rolls about each approach direction. A hand coming from the side with its fingers spread
    vertically reaches into the table, so for directions less than 45 deg from the horizontal the
    roll puts the hand's y axis (the fingers' line at spread 0) horizontal - one of the two such
    rolls at random, jittered by ``spread_deg`` - and is uniform otherwise."""
    out = rng.uniform(0, 2 * np.pi, len(directions))
    for i, d in enumerate(directions):
        if abs(d[2]) > np.sin(np.radians(45)):
            continue
        a = hand.approach_pose(d, 0.0, np.zeros(3))[2, 1]
        b = hand.approach_pose(d, np.pi / 2, np.zeros(3))[2, 1]
        out[i] = np.arctan2(-a, b) + np.pi * rng.integers(2) + np.radians(spread_deg) * rng.normal()
    return out


def sample_targets(obj: ObjectModel, parts: Sequence[str], n: int, rng: np.random.Generator) -> np.ndarray:
    """n points on the object's triangles of the given parts (all triangles if none), area-weighted."""
    V, F = obj.vertices, obj.faces
    tri = np.arange(len(F))
    if parts:
        if obj.parts is None:
            raise ValueError(f"object '{obj.name}' has no part labels; the task needs {list(parts)}")
        ids = [obj.part_names.index(p) for p in parts if p in obj.part_names]
        tri = tri[np.isin(obj.parts, ids)]
        if not len(tri):
            raise ValueError(f"object '{obj.name}' has no triangles of the parts {list(parts)}")
    a = 0.5 * np.linalg.norm(np.cross(V[F[tri, 1]] - V[F[tri, 0]], V[F[tri, 2]] - V[F[tri, 0]]), axis=1)
    pick = tri[rng.choice(len(tri), size=n, p=a / a.sum())]
    u, v = rng.uniform(size=(2, n))
    flip = u + v > 1
    u[flip], v[flip] = 1 - u[flip], 1 - v[flip]
    P = V[F[pick]]
    return P[:, 0] + u[:, None] * (P[:, 1] - P[:, 0]) + v[:, None] * (P[:, 2] - P[:, 0])


def object_contact_parts(batch, i: int) -> List[str]:
    """The part names of grasp i's object contacts in a World grasp batch (table contacts left out)."""
    off = np.asarray(batch.contacts.offsets)
    on_table = np.asarray(batch.contacts.on_table, bool)[off[i]:off[i + 1]]
    parts = batch.contact_part[off[i]:off[i + 1]]
    return [str(p) for p, t in zip(parts, on_table) if not t]


def _rule_ok(batch, rule: TaskRule) -> np.ndarray:
    """Per grasp of a world batch: started free, touched the object (not stopped by the table),
    object contacts as the rule allows."""
    ok = ~np.asarray(batch.collision_at_start, bool) & ~np.asarray(batch.stopped_by_table, bool)
    for i in np.flatnonzero(ok):
        ok[i] = rule.contacts_ok(object_contact_parts(batch, i))
    return ok


def every_finger_touches(batch, hand) -> np.ndarray:
    """Per grasp of a world batch: every finger has a link on the object (table contacts left
    out). A parallel jaw's two point contacts never make force closure in the point-contact
    model (nothing resists turning about the line through them), so for a gripper with jaws
    this replaces epsilon > 0 as the candidate filter; the lift test then decides."""
    off = np.asarray(batch.contacts.offsets)
    link = np.asarray(batch.contacts.link)
    on_table = np.asarray(batch.contacts.on_table, bool)
    fingers = [set(int(l) for l in links) for links in hand.phalanx_links]
    out = np.zeros(len(off) - 1, bool)
    for i in range(len(out)):
        touched = {int(l) for l, t in zip(link[off[i]:off[i + 1]], on_table[off[i]:off[i + 1]]) if not t}
        out[i] = all(f & touched for f in fingers)
    return out


def _lifted(world: World, grasps: Sequence[tuple]) -> np.ndarray:
    """(n,) bool: the lift test of each (epsilon, spread, pose) grasp, one batch per spread."""
    out = np.zeros(len(grasps), dtype=bool)
    for spread in sorted({g[1] for g in grasps}):
        rows = [k for k, g in enumerate(grasps) if g[1] == spread]
        poses = np.array([grasps[k][2] for k in rows])
        out[rows] = np.asarray(world.grasp_poses(poses, spread=spread, lift=True).lifted, bool)
    return out


def generate_task_grasps(obj: Union[str, ObjectModel], rule: TaskRule, hand: str = DEFAULT_HAND,
                         settings: Optional[TaskGraspSettings] = None, say: Optional[Say] = None) -> List[TaskGrasp]:
    """The demonstrated grasps of one model for one task (see the module docstring)."""
    s = settings or TaskGraspSettings()
    say = say or (lambda m: None)
    o = load_object(obj)
    world = World.single(o, pose=(0.0, 0.0, 0.0), hand=hand, table=rule.table)
    rng = np.random.default_rng([s.seed, zlib.crc32(f"{o.name}/{rule.name}".encode())])
    found = []   # (epsilon, spread, pose) of grasps that satisfy the rule
    jaws = bool(world.hand.prismatic_joints.any())
    for k, spread in enumerate(s.spreads):
        say(f"task grasps {o.name}/{rule.name}: closing {s.candidates} approaches at spread "
            f"{np.degrees(spread):.0f} deg ({k + 1}/{len(s.spreads)})")
        d = sample_directions(rule, s.candidates, rng)
        t = sample_targets(o, rule.targets, s.candidates, rng)
        roll = sample_rolls(world.hand, d, rng)
        b = world.approach_batch(d, t, roll, spread=spread, standoff=s.standoff)
        held = every_finger_touches(b, world.hand) if jaws else np.asarray(b.epsilon) > 0
        ok = _rule_ok(b, rule) & held
        found += [(float(b.epsilon[i]), float(spread), np.asarray(b.hand_pose_object[i])) for i in np.flatnonzero(ok)]
    found.sort(key=lambda x: -x[0])
    tested = found[:s.lift_tests]
    say(f"task grasps {o.name}/{rule.name}: {len(found)} candidates obey the rule; lift-testing {len(tested)}")
    held = lift_tests_in_chunks(lambda rows: _lifted(world, [tested[i] for i in rows]), np.arange(len(tested)), say)
    out = [TaskGrasp(o.name, rule.name, tested[i][2], tested[i][1], tested[i][0], True)
           for spread in sorted({f[1] for f in tested}) for i in range(len(tested))
           if tested[i][1] == spread and held[i]]
    out.sort(key=lambda g: -g.epsilon)
    return out[:s.keep]


# ---- storage ---------------------------------------------------------------------------------------
def grasp_to_json(g: TaskGrasp) -> dict:
    return {"model": g.model, "task": g.task, "pose": np.asarray(g.pose).tolist(), "spread": g.spread,
            "epsilon": g.epsilon, "lifted": g.lifted}


def grasp_from_json(d: dict, where: str = "task grasp") -> TaskGrasp:
    for key in ("model", "task", "pose", "spread"):
        if key not in d:
            raise ValueError(f"{where}: missing '{key}'")
    T = np.asarray(d["pose"], dtype=float)
    if T.shape != (4, 4) or not np.all(np.isfinite(T)):
        raise ValueError(f"{where}: 'pose' must be a finite 4x4")
    R = T[:3, :3]
    if not np.allclose(R.T @ R, np.eye(3), atol=1e-6) or np.linalg.det(R) < 0 or not np.allclose(T[3], [0, 0, 0, 1]):
        raise ValueError(f"{where}: 'pose' is not a rigid transform")
    return TaskGrasp(str(d["model"]), str(d["task"]), T, float(d["spread"]), float(d.get("epsilon", 0.0)),
                     bool(d.get("lifted", False)))


def load_task_grasp_file(path) -> List[TaskGrasp]:
    """Task grasps from a JSON file: ``{"grasps": [{"model", "task", "pose" (4x4, model frame),
    "spread", "epsilon", "lifted"}, ...]}`` - the generator's cache format, and the format of
    hand-made grasps a user adds."""
    p = Path(path)
    try:
        doc = json.loads(p.read_text())
    except (OSError, ValueError) as e:
        raise ValueError(f"task grasps {p}: cannot read ({e})") from None
    if not isinstance(doc, dict) or not isinstance(doc.get("grasps"), list):
        raise ValueError(f"task grasps {p}: expected an object with a list 'grasps'")
    return [grasp_from_json(d, f"task grasps {p}: entry {i}") for i, d in enumerate(doc["grasps"])]


def _key(obj: ObjectModel, hand_text: str, rule: TaskRule, s: TaskGraspSettings) -> str:
    h = hashlib.sha256(f"v{CACHE_VERSION}".encode())
    h.update(np.ascontiguousarray(obj.vertices, dtype=np.float64).tobytes())
    h.update(np.ascontiguousarray(obj.faces, dtype=np.int64).tobytes())
    h.update(hand_text.encode())
    h.update(cache_salt(obj))      # the lift test's mass, where it is not the closed mesh's
    h.update(repr(rule).encode())
    h.update(json.dumps(asdict(s), sort_keys=True, default=list).encode())
    return h.hexdigest()[:20]


def task_grasps(models: Sequence[Union[str, ObjectModel]], rule: TaskRule, hand: str = DEFAULT_HAND,
                settings: Optional[TaskGraspSettings] = None, cache_dir=None, say: Optional[Say] = None) -> List[TaskGrasp]:
    """Every model's demonstrated grasps for the task, generated once and cached as JSON."""
    from ..hand import Hand

    s = settings or TaskGraspSettings()
    hand_text = Hand.load(hand).text
    out: List[TaskGrasp] = []
    for m in models:
        o = load_object(m)
        f = None if cache_dir is None else Path(cache_dir) / f"task_{_key(o, hand_text, rule, s)}.json"
        cached = None if f is None else load_cached(f, "task grasp cache file", load_task_grasp_file)
        if cached is not None:
            out += cached
            continue
        grasps = generate_task_grasps(o, rule, hand, s, say)
        if f is not None:
            atomic_write_text(f, json.dumps({"model": o.name, "task": rule.name,
                                             "grasps": [grasp_to_json(g) for g in grasps]}, indent=1))
        out += grasps
    return out
