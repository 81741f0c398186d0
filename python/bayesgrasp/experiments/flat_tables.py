"""Stored runs as plain SQL tables: queryable without JSON functions.

The ``runs`` table of a results file keeps each run's result as JSON text (the source of truth,
written as each run finishes). :func:`flatten` derives from it, in the same file:

* ``run_rows``: one row per run: ``experiment, object, run_index, seed`` and one column per
  top-level field of the result, except the lists of records;
* one table per top-level field that holds a list of records (e.g. ``attempts``): one row per
  record, ``experiment, object, run_index, seed, position`` (0-based) and one column per field
  of the records.

Values that are lists or records themselves (a pose, a belief summary) are kept as JSON text in
their column. Column names are the field names with anything but letters, digits and ``_``
replaced by ``_``. The derived tables are rebuilt from ``runs`` each time (a few thousand runs
take well under a second), so they never disagree with it.
"""
from __future__ import annotations

import json
import re
import sqlite3
from typing import Dict, List

KEY_COLUMNS = ("experiment", "object", "run_index", "seed")
RESERVED = set(KEY_COLUMNS) | {"runs", "settings", "run_rows", "position"}


def _name(key: str) -> str:
    n = re.sub(r"[^A-Za-z0-9_]", "_", str(key))
    return n if n and not n[0].isdigit() else f"f_{n}"


def _cell(v):
    if v is None or isinstance(v, (int, float, str)):
        return int(v) if isinstance(v, bool) else v
    return json.dumps(v)


def _is_records(v) -> bool:
    return isinstance(v, list) and len(v) > 0 and all(isinstance(x, dict) for x in v)


def _table(db: sqlite3.Connection, name: str, keys: List[str], columns: List[str], rows: List[tuple]) -> None:
    db.execute(f'DROP TABLE IF EXISTS "{name}"')
    cols = ", ".join(f'"{c}"' for c in keys + columns)
    db.execute(f'CREATE TABLE "{name}" ({cols})')
    if rows:
        marks = ", ".join("?" * (len(keys) + len(columns)))
        db.executemany(f'INSERT INTO "{name}" VALUES ({marks})', rows)


def flatten(db: sqlite3.Connection) -> None:
    """Rebuilds ``run_rows`` and the per-record tables from ``runs``."""
    runs = db.execute("SELECT experiment, object, run_index, seed, result FROM runs"
                      " ORDER BY experiment, object, run_index").fetchall()
    scalars: Dict[str, None] = {}
    records: Dict[str, Dict[str, None]] = {}
    parsed = []
    for *key, text in runs:
        r = json.loads(text)
        parsed.append((tuple(key), r))
        for k, v in r.items():
            if _is_records(v):
                cols = records.setdefault(_name(k), {})
                for rec in v:
                    for f in rec:
                        cols.setdefault(_name(f), None)
            else:
                scalars.setdefault(_name(k), None)
    for t in records:
        if t in RESERVED:
            raise ValueError(f"a result field is named {t!r}, which the results tables reserve")
    scalar_cols = [c for c in scalars if c not in RESERVED]
    rows = []
    for key, r in parsed:
        named = {_name(k): v for k, v in r.items()}
        rows.append(key + tuple(_cell(named.get(c)) for c in scalar_cols))
    _table(db, "run_rows", list(KEY_COLUMNS), scalar_cols, rows)
    for t, cols in records.items():
        cols = [c for c in cols if c not in RESERVED]
        trows = []
        for key, r in parsed:
            for k, v in r.items():
                if _name(k) == t and _is_records(v):
                    for i, rec in enumerate(v):
                        named = {_name(f): x for f, x in rec.items()}
                        trows.append(key + (i,) + tuple(_cell(named.get(c)) for c in cols))
        _table(db, t, list(KEY_COLUMNS) + ["position"], cols, trows)
    db.commit()
