"""What a result shows, independent of how it is drawn: the object at its pose on the table, the
camera's cloud, the registered models with their weights, and per step (an attempt, a fusion round,
an episode's grasp) the hand posed at the grasp with its fingers at the read joint angles, the
pre-grasp, the approach and the contacts with their normals.

:func:`scene_from_result` reads the JSON of ``grasp``, ``plan``, ``category``, ``fuse``,
``touch``, ``register`` and an episode (``episode show --json`` or ``episode.json``); anything else
is refused with the reason. World frame = the table frame (z up, table at z = 0).
"""
from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import List, Optional, Sequence

import numpy as np

from ..objects import ObjectModel, load_object


class ResultError(ValueError):
    """A file that is no bayesgrasp result, or one whose object cannot be loaded."""


@dataclass
class Contact:
    point: np.ndarray      # (3,) world
    normal: np.ndarray     # (3,) unit, world
    part: str = ""
    link: str = ""


@dataclass
class Step:
    """One grasp of the result: ``grasp`` a schema grasp record (world frame), or None."""

    label: str
    grasp: Optional[dict]
    outcome: str = ""                       # "lifted", "dropped", "planned", ...
    contacts: List[Contact] = field(default_factory=list)
    models: List[tuple] = field(default_factory=list)   # (name, 4x4 model-to-world or None, weight) overlays
    belief: Optional[dict] = None          # {"particles": [[x, y, yaw], ...], "weights": [...], "n": N}
    trace: Optional[dict] = None           # the lift test's trace (io.view_fields.lift_trace_json)


@dataclass
class ResultScene:
    kind: str
    object: Optional[ObjectModel]
    object_pose: Optional[np.ndarray]        # (x, y, yaw) on the table, or None (not known)
    steps: List[Step]
    cloud: Optional[np.ndarray] = None
    title: str = ""


def planar_transform(pose: Sequence[float]) -> np.ndarray:
    """(x, y, yaw) on the table as a 4x4."""
    x, y, yaw = (float(v) for v in pose)
    c, s = np.cos(yaw), np.sin(yaw)
    T = np.eye(4)
    T[:2, :2] = [[c, -s], [s, c]]
    T[:2, 3] = x, y
    return T


def _planar_models(named: dict, weights: dict) -> List[tuple]:
    """(name, 4x4, weight) overlays from planar poses (x, y, yaw) by model name."""
    return [(m, None if named.get(m) is None else planar_transform(named[m]), float(weights[m])) for m in weights]


def _registered(models) -> List[tuple]:
    """(name, 4x4, weight) overlays from registrations (a successful one's transform, else none)."""
    return [(m["model"], np.asarray(m["transform"], float) if m.get("transform") is not None and m.get("success", True)
             else None, float(m.get("weight", 0.0))) for m in models]


def _cloud(doc) -> Optional[np.ndarray]:
    c = doc.get("cloud")
    return None if not c else np.asarray(c, float).reshape(-1, 3)


def read_result(path) -> dict:
    p = Path(path)
    try:
        doc = json.loads(p.read_text())
    except OSError as e:
        raise ResultError(f"{p}: cannot read ({e.strerror})") from None
    except ValueError as e:
        raise ResultError(f"{p}: not JSON ({e})") from None
    if isinstance(doc, dict) and "state" in doc and "sha256" in doc:    # an episode.json
        doc = {"episode": str(p.parent), "kind": doc["state"].get("kind"), **doc["state"]}
    if not isinstance(doc, dict):
        raise ResultError(f"{p}: not a bayesgrasp result (a JSON object is expected)")
    return doc


def _object(name, units: Optional[str] = None) -> Optional[ObjectModel]:
    """The result's object, its mesh file read in the unit the command was given (``units``)."""
    if name is None:
        return None
    try:
        return load_object(name, units=units)
    except (OSError, ValueError, KeyError) as e:
        raise ResultError(f"object {name!r}: cannot be loaded ({e}); was its mesh file moved?") from None


def _contacts(items) -> List[Contact]:
    return [Contact(np.asarray(c["point"], float), np.asarray(c["normal"], float), c.get("part") or "",
                    c.get("link_name") or "") for c in items or [] if not c.get("on_table")]


def _verdict(lifted) -> str:
    return "planned" if lifted is None else ("lifted" if lifted else "not lifted")


def scene_from_result(doc: dict) -> ResultScene:
    """The scene of one command's JSON output (see the module's docstring)."""
    for key, make in _KINDS:
        if key(doc):
            return make(doc)
    raise ResultError("not a bayesgrasp result: no grasp, attempts, rounds, registrations or episode in it "
                      f"(keys: {', '.join(sorted(doc)[:8])})")


def _grasp(doc) -> ResultScene:
    step = Step("grasp", doc["grasp"], _verdict(doc.get("lifted")), _contacts(doc.get("contacts")),
                trace=doc.get("lift_trace"))
    return ResultScene("grasp", _object(doc["object"], doc.get("units")), np.asarray(doc.get("object_pose") or (0, 0, 0), float), [step],
                       title=f"{doc['object']}: {step.outcome}, epsilon {doc.get('epsilon', 0.0):.3f}")


def _plan(doc) -> ResultScene:
    steps = [Step(f"attempt {k + 1} ({a.get('plan_type', '')})", a["grasp"], _verdict(a.get("lifted")),
                  _contacts(a.get("contacts")), belief=a.get("belief")) for k, a in enumerate(doc["attempts"])]
    vision = doc.get("vision") or {}
    return ResultScene("plan", _object(doc["object"], doc.get("units")), np.asarray(doc["true_pose"], float), steps, cloud=_cloud(vision),
                       title=f"{doc['object']}: {'success' if doc.get('success') else 'no grasp lifted'}")


def _category(doc) -> ResultScene:
    pose = doc.get("object_pose")
    step = Step(f"{doc['task']} ({doc['method']})", doc["grasp"], _verdict(doc.get("lifted")),
                _contacts(doc.get("contacts")), _registered(doc.get("models", [])))
    return ResultScene("category", _object(doc.get("scene_object"), doc.get("units")), None if pose is None else np.asarray(pose, float),
                       [step], cloud=_cloud(doc), title=f"{doc.get('scene_object') or doc.get('scene')}, {doc['task']}: "
                                     f"{'success' if doc.get('success') else doc.get('failure') or 'planned'}")


def _fuse(doc) -> ResultScene:
    steps = [Step(f"round {r['round']}", r["grasp"], _verdict(r.get("lifted")),
                  models=_planar_models(r["poses"], r["weights"])) for r in doc["rounds"]]
    return ResultScene("fuse", _object(doc["scene_object"], doc.get("units")), np.asarray(doc["object_pose"], float), steps,
                       cloud=_cloud(doc),
                       title=f"{doc['scene_object']}: vision then touch, "
                             f"{'success' if doc.get('success') else 'no grasp lifted'}")


def _touch(doc) -> ResultScene:
    """The object at its true pose, the touch, and the model at the fitted estimate (weight 1)."""
    truth, est = doc["true_state"], doc["estimate"]
    step = Step("touch", doc.get("grasp"), "touched", models=[(doc["object"], planar_transform(est[:3]), 1.0)])
    return ResultScene("touch", _object(doc["object"], doc.get("units")), np.asarray(truth[:3], float), [step],
                       title=f"{doc['object']}: one touch, {doc.get('optimizer', '')} estimate overlaid")


def _register(doc) -> ResultScene:
    pose = doc.get("pose")
    return ResultScene("register", _object(doc.get("scene_object"), doc.get("units")), None if pose is None else np.asarray(pose, float),
                       [Step("registration", None, "", models=_registered(doc["models"]))], cloud=_cloud(doc),
                       title=f"{doc.get('scene')}: {len(doc['models'])} model(s) registered")


def _episode(doc) -> ResultScene:
    steps = []
    for s in doc.get("steps", []):
        steps.append(Step(f"attempt {s['attempt']}", s.get("grasp"), _verdict(s.get("lifted"))))
    nxt = doc.get("next")
    if nxt is not None:
        steps.append(Step(f"attempt {nxt['attempt']} (next)", nxt["grasp"], "planned"))
    obj = doc.get("object")
    pose = doc.get("estimate")
    return ResultScene("episode", _object(obj), None if pose is None else np.asarray(pose, float), steps,
                       title=f"episode {doc.get('episode', '')}: {doc.get('status', '')}")


_KINDS = [
    (lambda d: "episode" in d and "steps" in d, _episode),
    (lambda d: "rounds" in d and "scene_object" in d, _fuse),
    (lambda d: "attempts" in d and "true_pose" in d, _plan),
    (lambda d: "task" in d and "grasp" in d and "models" in d, _category),
    (lambda d: "readings" in d and "true_state" in d, _touch),
    (lambda d: "grasp" in d and "object" in d and "contacts" in d, _grasp),
    (lambda d: "models" in d and "scene" in d, _register),
]
