"""Compares two recordings of tests/golden/record.sh: every JSON (and JSON-lines) file under A
against its namesake under B, value by value.

    python tests/golden/compare.py BEFORE AFTER [--rtol 1e-12]

Wall-clock fields (keys naming seconds, times or dates) are skipped: they differ between any two
runs. Numbers compare to ``--rtol`` (0: bit for bit). Prints one line per difference, with the
file and the key path, and exits 1 if there is any.
"""
from __future__ import annotations

import argparse
import json
import math
import re
import sys
from pathlib import Path

# a wall-clock word as the whole key or one of its underscore-separated parts (plan_ms_median)
WALL_CLOCK = re.compile(r"(^|_)(seconds|time|times|elapsed|wall|date|timestamp|started|finished|ms|s)(_|$)")


def _load(path: Path):
    text = path.read_text()
    if path.suffix == ".jsonl":
        return [json.loads(line) for line in text.splitlines() if line.strip()]
    return json.loads(text)


def _diff(a, b, where: str, rtol: float, out: list) -> None:
    if isinstance(a, dict) and isinstance(b, dict):
        for k in sorted(set(a) | set(b)):
            if WALL_CLOCK.search(str(k)):
                continue
            if k not in a or k not in b:
                out.append(f"{where}.{k}: only in {'B' if k not in a else 'A'}")
                continue
            _diff(a[k], b[k], f"{where}.{k}", rtol, out)
    elif isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            out.append(f"{where}: {len(a)} items in A, {len(b)} in B")
        for i, (x, y) in enumerate(zip(a, b)):
            _diff(x, y, f"{where}[{i}]", rtol, out)
    elif isinstance(a, (int, float)) and isinstance(b, (int, float)) and not isinstance(a, bool):
        same = a == b or (isinstance(a, float) and isinstance(b, float) and math.isnan(a) and math.isnan(b))
        if not same and not (rtol > 0 and math.isclose(a, b, rel_tol=rtol, abs_tol=rtol)):
            out.append(f"{where}: {a!r} in A, {b!r} in B")
    elif a != b:
        out.append(f"{where}: {str(a)[:80]!r} in A, {str(b)[:80]!r} in B")


def compare(a_dir: Path, b_dir: Path, rtol: float = 0.0) -> list:
    out = []
    files = sorted(p.relative_to(a_dir) for p in a_dir.rglob("*") if p.suffix in (".json", ".jsonl"))
    if not files:
        out.append(f"{a_dir}: no JSON files")
    for rel in files:
        if not (b_dir / rel).exists():
            out.append(f"{rel}: missing in B")
            continue
        _diff(_load(a_dir / rel), _load(b_dir / rel), str(rel), rtol, out)
    return out


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("a", type=Path)
    p.add_argument("b", type=Path)
    p.add_argument("--rtol", type=float, default=0.0, help="relative tolerance for numbers (0: exact)")
    args = p.parse_args(argv)
    diffs = compare(args.a, args.b, args.rtol)
    for d in diffs:
        print(d)
    print(f"{len(diffs)} differences", file=sys.stderr)
    return 1 if diffs else 0


if __name__ == "__main__":
    sys.exit(main())
