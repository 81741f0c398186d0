"""``bayesgrasp results DIR``: an experiment's stored results as SQL tables.

Without ``--sql``: the tables (run_rows, attempts, ...), their rows and columns, and the settings
each series was run with. ``--sql QUERY``: the query's rows, as an aligned table or ``--csv``.
The query runs on a read-only connection: it cannot change the results.
"""
from __future__ import annotations

import csv
import json
import sqlite3
import sys
from pathlib import Path

from .args import CliError


def add(sub) -> None:
    r = sub.add_parser("results", help="query an experiment's stored results with SQL",
                       description=__doc__.split("\n", 2)[2].strip())
    r.add_argument("path", help="an experiment's output directory or its results.sqlite")
    r.add_argument("--sql", default=None, help="an SQL query, e.g. \"SELECT object, AVG(lifted) FROM attempts "
                                               "WHERE position = 0 GROUP BY object\"")
    r.add_argument("--csv", action="store_true", help="print the rows as CSV")
    r.set_defaults(run=run)


def _file(path: str) -> Path:
    p = Path(path)
    f = p / "results.sqlite" if p.is_dir() else p
    if not f.is_file():
        raise CliError(f"{path}: no results.sqlite there")
    try:
        db = sqlite3.connect(f"file:{f}?mode=ro", uri=True)
        db.execute("SELECT 1 FROM runs LIMIT 1")
        db.close()
    except sqlite3.Error:
        raise CliError(f"{f}: not a bayesgrasp results file (no runs table)") from None
    return f


def _refresh(f: Path) -> None:
    """Rebuilds the derived tables (files written before they existed have none)."""
    from ..experiments.runner import ResultStore
    store = ResultStore(f)
    try:
        store.flatten()
    finally:
        store.close()


def _overview(db: sqlite3.Connection) -> str:
    lines = []
    names = [r[0] for r in db.execute("SELECT name FROM sqlite_master WHERE type = 'table' ORDER BY name")]
    for t in names:
        n = db.execute(f'SELECT COUNT(*) FROM "{t}"').fetchone()[0]
        cols = [r[1] for r in db.execute(f'PRAGMA table_info("{t}")')]
        lines.append(f"{t} ({n} rows): {', '.join(cols)}")
    if "settings" in names:
        for series, text in db.execute("SELECT experiment, settings FROM settings ORDER BY experiment"):
            lines.append(f"settings of {series}: {json.dumps(json.loads(text), sort_keys=True)}")
    return "\n".join(lines)


def run(args) -> int:
    f = _file(args.path)
    try:
        _refresh(f)
    except (ValueError, sqlite3.Error) as e:
        raise CliError(f"{f}: {e}") from None
    db = sqlite3.connect(f"file:{f}?mode=ro", uri=True)
    try:
        if args.sql is None:
            print(_overview(db))
            return 0
        try:
            cur = db.execute(args.sql)
        except sqlite3.Error as e:
            raise CliError(f"--sql: {e}") from None
        header = [d[0] for d in cur.description or ()]
        rows = cur.fetchall()
    finally:
        db.close()
    if args.csv:
        w = csv.writer(sys.stdout, lineterminator="\n")
        w.writerow(header)
        w.writerows(rows)
        return 0
    text = [[str(h) for h in header]] + [["" if v is None else (f"{v:.6g}" if isinstance(v, float) else str(v))
                                          for v in r] for r in rows]
    widths = [max(len(r[i]) for r in text) for i in range(len(header))]
    for r in text:
        print("  ".join(v.ljust(w) for v, w in zip(r, widths)).rstrip())
    return 0
