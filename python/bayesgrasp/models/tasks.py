"""Tasks and their rules, as data (``data/tasks/<category>.json``, like the hand files).

A rule says which approach directions a task allows and which parts of the object the hand may
touch. Directions are in the object's frame; the approach direction ``d`` is the direction the
hand moves in (the hand frame's +z, out of the palm), so ``-d`` points to where it comes from.

A category's file may set ``"table": false``: its objects are then presented held off the table
(on a holder the simulator does not model, as objects float in the thesis's GraspIt! set-up); a
tool lying flat on a table leaves no room for the fingers under its handle (1.4-2.5 cm high), so
the tools' files do. Approach constraints (all given must hold; and with a table the hand does
not come from under it, ``-d`` has z >= 0):

* ``from_axis {axis, max_angle_deg}``: the angle between ``-d`` and ``axis`` is at most the limit
  (mug top: the hand comes from above);
* ``from_horizontal {max_tilt_deg}``: ``-d`` is within the limit of the horizontal plane;
* ``from_azimuth {axis, min_angle_deg | max_angle_deg}``: the horizontal angle between ``-d`` and
  ``axis`` (mug side: at least 60 degrees away from the handle at +x);
* ``across_axis {axis, min_angle_deg}``: ``d`` makes at least this angle with the line of ``axis``
  (tools: across the handle).

Contact constraints: ``allowed`` parts (an object contact anywhere else breaks the rule),
``min_object_contacts``, and ``min_part_contacts`` per part. ``targets`` names the parts a grasp
generator aims at.
"""
from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Dict, List, Mapping, Optional, Sequence, Tuple

import numpy as np

TASK_DIR = Path(__file__).resolve().parents[1] / "data" / "tasks"

_APPROACH_KEYS = {"from_axis": {"axis", "max_angle_deg"}, "from_horizontal": {"max_tilt_deg"},
                  "from_azimuth": {"axis", "min_angle_deg", "max_angle_deg"}, "across_axis": {"axis", "min_angle_deg"}}
_CONTACT_KEYS = {"allowed", "min_object_contacts", "min_part_contacts"}
_TASK_KEYS = {"description", "approach", "contacts", "targets"}


def _unit(v, what: str) -> np.ndarray:
    a = np.asarray(v, dtype=float)
    if a.shape != (3,) or not np.all(np.isfinite(a)) or np.linalg.norm(a) < 1e-12:
        raise ValueError(f"{what}: expected a non-zero 3-vector, got {v!r}")
    return a / np.linalg.norm(a)


def _angle_deg(value, what: str, lo: float = 0.0, hi: float = 180.0) -> float:
    if not isinstance(value, (int, float)) or not (lo <= value <= hi):
        raise ValueError(f"{what}: expected an angle in [{lo}, {hi}] degrees, got {value!r}")
    return float(value)


@dataclass(frozen=True)
class TaskRule:
    """One task of a category: its approach constraints and contact constraints (see the module)."""

    category: str
    name: str
    description: str
    approach: Mapping[str, Mapping[str, object]]
    allowed_parts: Tuple[str, ...]
    min_object_contacts: int = 1
    min_part_contacts: Mapping[str, int] = field(default_factory=dict)
    targets: Tuple[str, ...] = ()
    table: bool = True            # the object rests on the table (False: held off it, see the module)

    def approach_ok(self, directions) -> np.ndarray:
        """(N,) bool: approach directions (N, 3) in the object frame that satisfy the rule."""
        d = np.atleast_2d(np.asarray(directions, dtype=float))
        d = d / np.linalg.norm(d, axis=1, keepdims=True)
        src = -d
        ok = src[:, 2] >= -1e-9 if self.table else np.ones(len(d), bool)  # never from under a table
        for kind, c in self.approach.items():
            if kind == "from_axis":
                ok &= np.degrees(np.arccos(np.clip(src @ c["axis"], -1, 1))) <= c["max_angle_deg"]
            elif kind == "from_horizontal":
                ok &= np.degrees(np.abs(np.arcsin(np.clip(src[:, 2], -1, 1)))) <= c["max_tilt_deg"]
            elif kind == "from_azimuth":
                a = np.degrees(np.abs(_wrap(np.arctan2(src[:, 1], src[:, 0]) - np.arctan2(c["axis"][1], c["axis"][0]))))
                flat = np.hypot(src[:, 0], src[:, 1]) > 1e-9   # straight down/up: no azimuth
                if "min_angle_deg" in c:
                    ok &= flat & (a >= c["min_angle_deg"])
                if "max_angle_deg" in c:
                    ok &= flat & (a <= c["max_angle_deg"])
            elif kind == "across_axis":
                ok &= np.degrees(np.arccos(np.clip(np.abs(d @ c["axis"]), 0, 1))) >= c["min_angle_deg"]
        return ok

    def contacts_ok(self, contact_parts: Sequence[str]) -> bool:
        """Whether one grasp's object contacts (the part name of each) satisfy the rule."""
        parts = list(contact_parts)
        if len(parts) < self.min_object_contacts:
            return False
        if any(p not in self.allowed_parts for p in parts):
            return False
        return all(parts.count(p) >= n for p, n in self.min_part_contacts.items())


@dataclass(frozen=True)
class TaskGrasp:
    """A demonstrated grasp of a training model for a task: the hand pose (4x4, model frame) and
    spread, its epsilon and whether the lift test held it."""

    model: str
    task: str
    pose: np.ndarray
    spread: float
    epsilon: float
    lifted: bool


def _wrap(a):
    return np.mod(np.asarray(a) + np.pi, 2 * np.pi) - np.pi


def _approach(raw, what: str) -> Dict[str, Dict[str, object]]:
    if not isinstance(raw, dict):
        raise ValueError(f"{what}: expected an object of approach constraints")
    out: Dict[str, Dict[str, object]] = {}
    for kind, c in raw.items():
        if kind not in _APPROACH_KEYS:
            raise ValueError(f"{what}: unknown constraint {kind!r} (known: {', '.join(_APPROACH_KEYS)})")
        if not isinstance(c, dict) or set(c) - _APPROACH_KEYS[kind]:
            raise ValueError(f"{what}.{kind}: keys must be among {sorted(_APPROACH_KEYS[kind])}, got {c!r}")
        v: Dict[str, object] = {}
        if "axis" in _APPROACH_KEYS[kind]:
            if "axis" not in c:
                raise ValueError(f"{what}.{kind}: needs an axis")
            v["axis"] = _unit(c["axis"], f"{what}.{kind}.axis")
        for key in ("max_angle_deg", "min_angle_deg", "max_tilt_deg"):
            if key in c:
                v[key] = _angle_deg(c[key], f"{what}.{kind}.{key}", hi=90.0 if key == "max_tilt_deg" else 180.0)
        if not any(k.endswith("_deg") for k in v):
            raise ValueError(f"{what}.{kind}: needs an angle limit")
        out[kind] = v
    return out


def _rule(category: str, name: str, raw, parts: Sequence[str], what: str, table: bool = True) -> TaskRule:
    if not isinstance(raw, dict) or set(raw) - _TASK_KEYS or "contacts" not in raw or "approach" not in raw:
        raise ValueError(f"{what}: needs 'approach' and 'contacts' (and optionally 'description', 'targets'); "
                         f"keys must be among {sorted(_TASK_KEYS)}")
    c = raw["contacts"]
    if not isinstance(c, dict) or set(c) - _CONTACT_KEYS or "allowed" not in c:
        raise ValueError(f"{what}.contacts: needs 'allowed'; keys must be among {sorted(_CONTACT_KEYS)}")

    def known(names, key):
        names = tuple(names)
        bad = [n for n in names if n not in parts]
        if bad:
            raise ValueError(f"{what}.{key}: unknown parts {bad} (the category's parts: {list(parts)})")
        return names

    allowed = known(c["allowed"], "contacts.allowed")
    per_part = dict(c.get("min_part_contacts", {}))
    known(per_part, "contacts.min_part_contacts")
    n = c.get("min_object_contacts", 1)
    if not isinstance(n, int) or n < 0 or any(not isinstance(v, int) or v < 0 for v in per_part.values()):
        raise ValueError(f"{what}.contacts: contact counts must be non-negative integers")
    return TaskRule(category, name, str(raw.get("description", "")), _approach(raw["approach"], f"{what}.approach"),
                    allowed, n, per_part, known(raw.get("targets", ()), "targets"), table)


def load_task_file(path) -> Dict[str, TaskRule]:
    """Every task of one category's rule file, by name."""
    p = Path(path)
    try:
        doc = json.loads(p.read_text())
    except (OSError, ValueError) as e:
        raise ValueError(f"task file {p}: cannot read ({e})") from None
    if not isinstance(doc, dict) or not {"category", "parts", "tasks"} <= set(doc):
        raise ValueError(f"task file {p}: needs 'category', 'parts' and 'tasks'")
    if set(doc) - {"category", "parts", "tasks", "table"}:
        raise ValueError(f"task file {p}: unknown keys {sorted(set(doc) - {'category', 'parts', 'tasks', 'table'})}")
    table = doc.get("table", True)
    if not isinstance(table, bool):
        raise ValueError(f"task file {p}: 'table' must be true or false, got {table!r}")
    cat, parts = str(doc["category"]), [str(x) for x in doc["parts"]]
    if not isinstance(doc["tasks"], dict) or not doc["tasks"]:
        raise ValueError(f"task file {p}: 'tasks' must name at least one task")
    return {name: _rule(cat, name, raw, parts, f"{p.name}: task {name!r}", table) for name, raw in doc["tasks"].items()}


def task_categories() -> List[str]:
    """Categories with a built-in task file."""
    return sorted(f.stem for f in TASK_DIR.glob("*.json"))


def load_tasks(category: str, path: Optional[str] = None) -> Dict[str, TaskRule]:
    """The tasks of ``category`` (from its built-in file, or from ``path``)."""
    if path is None:
        f = TASK_DIR / f"{category}.json"
        if not f.is_file():
            raise ValueError(f"category: no tasks for {category!r} (categories with tasks: "
                             f"{', '.join(task_categories())})")
        path = f
    return load_task_file(path)


def task_rule(category: str, task: str) -> TaskRule:
    """One task's rule; ValueError naming the known tasks for an unknown one."""
    tasks = load_tasks(category)
    if task not in tasks:
        raise ValueError(f"task: {category!r} has no task {task!r} (its tasks: {', '.join(tasks)})")
    return tasks[task]
