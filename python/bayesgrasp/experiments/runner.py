"""Run-by-run experiment execution with resume, worker processes and a progress bar.

Every run is a pure function of (experiment, object, run index, seed) and the settings it runs
under: the runner hands the function those four values, stores what it returns (a typed
record's ``to_dict()``, or a JSON-serialisable dict) in an SQLite file as soon as the run finishes, and skips runs already
stored when started again. So an interrupted experiment resumes where it stopped and loses
nothing, and the same runs go to any engine (:mod:`.engines`: local processes or Ray tasks)
without touching the planners.
The settings (package and cache versions, hand, success criterion, lift test, model settings)
are stored beside the runs; resuming under other settings is refused with the differences named.
"""
from __future__ import annotations

import hashlib
import json
import sqlite3
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Dict, Iterable, Optional, Sequence

from tqdm import tqdm


@dataclass(frozen=True)
class RunKey:
    experiment: str
    object: str
    run_index: int
    seed: int


def run_seed(base_seed: int, experiment: str, obj: str, run_index: int) -> int:
    """A 63-bit seed derived deterministically from the run's identity."""
    h = hashlib.sha256(f"{base_seed}/{experiment}/{obj}/{run_index}".encode()).digest()
    return int.from_bytes(h[:8], "little") >> 1


class ResultStore:
    """Per-run results in an SQLite file (one row per finished run)."""

    def __init__(self, path: str | Path):
        self.path = Path(path)
        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            self._db = sqlite3.connect(str(self.path))
            self._db.execute(
                "CREATE TABLE IF NOT EXISTS runs (experiment TEXT, object TEXT, run_index INTEGER,"
                " seed INTEGER, result TEXT, PRIMARY KEY (experiment, object, run_index, seed))")
            self._db.execute("CREATE TABLE IF NOT EXISTS settings (experiment TEXT PRIMARY KEY, settings TEXT)")
            self._db.commit()
        except (OSError, sqlite3.Error) as e:
            raise ValueError(f"cannot write results to {self.path}: {e}") from e

    def done(self, experiment: str) -> set[RunKey]:
        rows = self._db.execute(
            "SELECT experiment, object, run_index, seed FROM runs WHERE experiment = ?", (experiment,))
        return {RunKey(*r) for r in rows}

    def settings(self, experiment: str) -> dict | None:
        """The settings the experiment's stored runs were made with (None: none recorded)."""
        row = self._db.execute("SELECT settings FROM settings WHERE experiment = ?", (experiment,)).fetchone()
        return None if row is None else json.loads(row[0])

    def check_settings(self, experiment: str, settings: dict) -> None:
        """Records `settings` for the experiment, or refuses (ValueError, nothing changed) when
        runs are stored under other settings or under none recorded: a resume must not mix runs
        made differently."""
        stored = self.settings(experiment)
        if stored is None:
            n = self._db.execute("SELECT COUNT(*) FROM runs WHERE experiment = ?", (experiment,)).fetchone()[0]
            if n:
                raise ValueError(f"{self.path} holds {n} runs of {experiment} stored without their settings (an "
                                 f"older bayesgrasp): they cannot be resumed safely; use another --out or delete "
                                 f"the file to start again")
            self._db.execute("INSERT INTO settings VALUES (?, ?)", (experiment, json.dumps(settings, sort_keys=True)))
            self._db.commit()
            return
        diff = settings_difference(stored, settings)
        if diff:
            raise ValueError(f"{self.path} holds runs of {experiment} made with other settings ("
                             + "; ".join(diff) + "): resuming would mix them; use another --out, or the same "
                             "settings, or delete the file to start again")

    def add(self, key: RunKey, result: dict) -> None:
        self._db.execute("INSERT OR REPLACE INTO runs VALUES (?, ?, ?, ?, ?)",
                         (key.experiment, key.object, key.run_index, key.seed, json.dumps(result)))
        self._db.commit()

    def results(self, experiment: str) -> list[tuple[RunKey, dict]]:
        rows = self._db.execute(
            "SELECT experiment, object, run_index, seed, result FROM runs WHERE experiment = ?"
            " ORDER BY object, run_index", (experiment,))
        return [(RunKey(*r[:4]), json.loads(r[4])) for r in rows]

    def flatten(self) -> None:
        """Rebuilds the plain SQL tables derived from the runs (:mod:`.flat_tables`): run_rows and
        one table per list of records (attempts, ...)."""
        from .flat_tables import flatten
        flatten(self._db)

    def close(self) -> None:
        self._db.close()


def settings_difference(stored: dict, now: dict, prefix: str = "") -> list[str]:
    """'key: stored X, now Y' for every (dotted) key whose value differs, sorted."""
    out = []
    for k in sorted(set(stored) | set(now)):
        a, b = stored.get(k, "(unset)"), now.get(k, "(unset)")
        if isinstance(a, dict) and isinstance(b, dict):
            out += settings_difference(a, b, f"{prefix}{k}.")
        elif a != b:
            out.append(f"{prefix}{k}: stored {json.dumps(a)}, now {json.dumps(b)}")
    return out


def _run(job):
    """One run: ``job`` is (fn, RunKey); returns fn(experiment, object, run_index, seed) as JSON
    (a typed result through its ``to_dict()``, in the worker: it may hold what does not pickle)."""
    fn, key = job
    result = fn(key.experiment, key.object, key.run_index, key.seed)
    return result.to_dict() if hasattr(result, "to_dict") else result


@dataclass(frozen=True)
class Series:
    """One series of runs: ``fn(experiment, object, run_index, seed)`` for every object and run
    index (``fn`` a module-level function or a partial of one: it is sent to workers). The seeds
    derive from ``seed_name`` (default: ``experiment``): the points of a sweep share it, so every
    point meets the same problems."""

    experiment: str
    objects: tuple
    runs: int
    fn: Callable[[str, str, int, int], Any]
    seed_name: Optional[str] = None

    def keys(self, base_seed: int) -> list:
        name = self.seed_name or self.experiment
        return [RunKey(self.experiment, o, i, run_seed(base_seed, name, o, i))
                for o in self.objects for i in range(self.runs)]


def run_all(series: Sequence[Series], store: ResultStore, base_seed: int = 0, engine=None, progress: bool = True,
            settings: Optional[dict] = None) -> Dict[str, list]:
    """Runs every series' runs not yet in ``store`` on ``engine`` (default: this process),
    saving each result as soon as it arrives, with one progress bar (runs done / total, rate,
    ETA) on stderr for all of them. ``settings``: what else the results depend on
    (:meth:`ResultStore.check_settings`: recorded with the first run, a resume with other values
    is refused). Returns {experiment: every stored (RunKey, result) of its runs}."""
    from .engines import LocalEngine

    engine = engine or LocalEngine(1)
    for s in series:
        if s.runs < 1:
            raise ValueError(f"runs must be at least 1, got {s.runs}")
        if settings is not None:
            store.check_settings(s.experiment, settings)
    keys = {s.experiment: s.keys(base_seed) for s in series}
    total = sum(len(k) for k in keys.values())
    todo = []
    for s in series:
        done = store.done(s.experiment)
        todo += [(s.fn, k) for k in keys[s.experiment] if k not in done]
    bar = tqdm(total=total, initial=total - len(todo), desc="+".join(keys), unit="run", disable=not progress,
               file=sys.stderr)
    try:
        for (_, key), result in engine.map(_run, todo):
            store.add(key, result)
            bar.update()
    except KeyboardInterrupt:
        bar.close()
        n = sum(len(store.done(e)) for e in keys)
        print(f"\ninterrupted: {n} of {total} runs saved in {store.path}; run again to resume", file=sys.stderr)
        raise
    bar.close()
    out = {}
    for e, ks in keys.items():
        wanted = set(ks)
        out[e] = [(k, r) for k, r in store.results(e) if k in wanted]
    return out


def run_experiment(experiment: str, objects: Iterable[str], runs: int, fn: Callable[[str, str, int, int], dict],
                   store: ResultStore, base_seed: int = 0, workers: int = 1,
                   progress: bool = True, settings: dict | None = None, engine=None) -> list[tuple[RunKey, dict]]:
    """One series (:func:`run_all`): ``fn(experiment, object, run_index, seed)`` for every object
    and run index not yet in ``store``, on ``engine`` (default: ``workers`` local processes).
    Returns every stored result of the series' runs."""
    from .engines import LocalEngine

    if runs < 1:
        raise ValueError(f"runs must be at least 1, got {runs}")
    if workers < 1:
        raise ValueError(f"workers must be at least 1, got {workers}")
    series = Series(experiment, tuple(objects), int(runs), fn)
    return run_all([series], store, base_seed, engine or LocalEngine(workers), progress, settings)[experiment]
