"""An experiment's stored run (a row of ``results.sqlite``, see
:class:`bayesgrasp.experiments.runner.ResultStore`) as a viewer scene.

Three kinds of run hold grasps to show:

* a pose-uncertainty episode (``pub2``, ``pub3``, ``pub4``, ...: ``attempts`` and ``true_pose``):
  one step per attempt, the hand where it closed, the contacts simulated again on the object at
  the run's true pose (kept only where that gives the stored hand pose and joints);
* a category run (``pub5``: ``tasks``): one step per (task, method), the models' registrations
  are not stored with their transforms, so the step shows the hand and its contacts;
* a vision-then-touch run (``pub6``: ``rounds`` and ``registrations``): one step per round, the
  models at their planar poses with their weights.

    keys = list_runs("out/pub2/results.sqlite")
    key, result = read_run("out/pub2/results.sqlite", series="pub2/stability", obj="mug", run=0)
    scene = scene_from_run(key, result)
"""
from __future__ import annotations

import json
import sqlite3
from pathlib import Path
from typing import List, Optional, Tuple

import numpy as np

from .. import DEFAULT_HAND
from .scene import Contact, ResultError, ResultScene, Step, _object, _planar_models, _verdict



def results_file(path) -> Path:
    """``path`` itself, or the ``results.sqlite`` inside a directory."""
    p = Path(path)
    return p / "results.sqlite" if p.is_dir() else p


def _connect(path) -> sqlite3.Connection:
    p = results_file(path)
    if not p.is_file():
        raise ResultError(f"{p}: no such results file")
    try:
        db = sqlite3.connect(f"file:{p}?mode=ro", uri=True)
        db.execute("SELECT experiment, object, run_index, seed, result FROM runs LIMIT 1")
    except sqlite3.Error as e:
        raise ResultError(f"{p}: not an experiment's results.sqlite ({e})") from None
    return db


def list_runs(path) -> List[Tuple[str, str, int]]:
    """(series, object, run index) of every stored run, sorted."""
    db = _connect(path)
    try:
        return sorted((str(s), str(o), int(k)) for s, o, k in db.execute("SELECT experiment, object, run_index FROM runs"))
    finally:
        db.close()


def _one_of(what: str, value, choices: list):
    if value is None:
        if len(choices) == 1:
            return choices[0]
        raise ResultError(f"several stored, pick one with --{what}: {', '.join(map(str, choices))}")
    if value not in choices:
        raise ResultError(f"--{what} {value!r}: not stored; stored: {', '.join(map(str, choices))}")
    return value


def read_run(path, series: Optional[str] = None, obj: Optional[str] = None, run: int = 0) -> Tuple[tuple, dict]:
    """The stored result of one run: ``series`` (the experiment's series, e.g. ``pub2/stability``)
    and ``obj`` may be left out where only one is stored; refused with the stored choices otherwise."""
    keys = list_runs(path)
    if not keys:
        raise ResultError(f"{results_file(path)}: no runs stored yet")
    series = _one_of("series", series, sorted({k[0] for k in keys}))
    obj = _one_of("object", obj, sorted({k[1] for k in keys if k[0] == series}))
    run = _one_of("run", int(run), sorted({k[2] for k in keys if k[:2] == (series, obj)}))
    db = _connect(path)
    try:
        text = db.execute("SELECT result FROM runs WHERE experiment = ? AND object = ? AND run_index = ?",
                          (series, obj, run)).fetchone()[0]
    finally:
        db.close()
    return (series, obj, run), json.loads(text)


def scene_from_run(key: tuple, result: dict, hand: str = DEFAULT_HAND) -> ResultScene:
    """The scene of one stored run (see the module's docstring); other runs are refused."""
    from ..hand import Hand

    h = Hand.load(hand)
    if "attempts" in result and "true_pose" in result:
        return _pose_run(key, result, h)
    if "tasks" in result and "category" in result:
        return _category_run(key, result, h)
    if "rounds" in result and "registrations" in result:
        return _fusion_run(key, result, h)
    raise ResultError(f"run {'/'.join(map(str, key))}: holds no grasps to show (keys: {', '.join(sorted(result)[:8])})")


def _spread(hand, q) -> float:
    """The finger spread of joints ``q`` (the hand's spread joint), or the hand's default."""
    names = hand.joint_names
    return float(q[names.index("spread")]) if "spread" in names else float(hand.core.spread_default)


def _record(hand, pose, q, spread=None) -> Optional[dict]:
    from ..io.grasp_schema import hand_grasp_record

    if pose is None:
        return None
    return hand_grasp_record(hand, pose, q, _spread(hand, q) if spread is None else spread)


def _resimulated_contacts(world, g, hand_pose, q) -> List[Contact]:
    """The contacts of a grasp simulated again, if it reproduces the stored hand pose and joints."""
    if not (np.allclose(g.hand_pose, hand_pose, atol=1e-9) and np.allclose(g.joint_angles, q, atol=1e-9)):
        return []
    return [Contact(np.asarray(c.point, float), np.asarray(c.normal, float), c.part or "", getattr(c, "link_name", "") or "")
            for c in g.contacts if not c.on_table]


def _pose_run(key, r: dict, hand) -> ResultScene:
    from ..world import World

    pose = np.asarray(r["true_pose"], float)
    world = World.single(r["object"], pose=pose, hand=hand)
    steps = []
    for a in r["attempts"]:
        q = np.asarray(a["joint_positions"], float)
        contacts = []
        if a.get("hand_pose") is not None and a.get("relative_grasp") is not None:
            g = world.grasp(*a["relative_grasp"], spread=_spread(hand, q), lift=False)
            contacts = _resimulated_contacts(world, g, a["hand_pose"], q)
        steps.append(Step(f"attempt {a['attempt']} ({a.get('kind', '')})", _record(hand, a.get("hand_pose"), q),
                          "lifted" if a.get("lifted") else _verdict(a.get("lifted")), contacts))
    return ResultScene("run", _object(r["object"]), pose, steps,
                       title=f"{'/'.join(map(str, key))}: {'success' if r.get('success') else 'no success'}")


def _category_run(key, r: dict, hand) -> ResultScene:
    from ..models.tasks import task_rule
    from ..world import World

    pose = np.asarray(r["pose"], float)
    steps = []
    for task, by_method in r["tasks"].items():
        rule = task_rule(r["category"], task)
        world = World.single(r["object"], pose=pose, hand=hand, table=rule.table)
        for method, out in by_method.items():
            label = f"{task} ({method}): {'success' if out.get('success') else out.get('failure') or 'failed'}"
            if not out.get("executed"):
                steps.append(Step(label, None, "not executed"))
                continue
            q = np.asarray(out["joint_angles"], float)
            A = np.asarray(out["pose"], float)
            g = world.approach(A[:3, 2], A[:3, 3], hand.approach_roll(A), spread=out["spread"], frame="world",
                               lift=False)
            steps.append(Step(label, _record(hand, out["hand_pose"], q, out["spread"]), _verdict(out.get("lifted")),
                              _resimulated_contacts(world, g, out["hand_pose"], q)))
    return ResultScene("run", _object(r["object"]), pose, steps, title=f"{'/'.join(map(str, key))}: category tasks")


def _fusion_run(key, r: dict, hand) -> ResultScene:
    names = [m["model"] for m in r["registrations"]]
    steps = []
    for rd in r["rounds"]:
        q = np.asarray(rd["joint_positions"], float)
        models = _planar_models(dict(zip(names, rd["poses"])), dict(zip(names, rd["weights"])))
        steps.append(Step(f"round {rd['round']}", _record(hand, rd["hand_pose"], q), _verdict(rd.get("lifted")),
                          models=models))
    return ResultScene("run", _object(r["object"]), np.asarray(r["pose"], float), steps,
                       title=f"{'/'.join(map(str, key))}: vision then touch ({r.get('mode', '')})")
