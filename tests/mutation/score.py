"""Mutation score per module from a mutmut work directory (tests/mutation/run.sh).

    python tests/mutation/score.py WORKDIR

Reads ``mutmut results --all true`` (run in WORKDIR) and prints, per module, the mutants killed,
survived, without a covering test and timed out, and the score killed / (killed + survived +
no tests): a mutant that no test runs counts as a survivor.
"""
from __future__ import annotations

import collections
import subprocess
import sys
from pathlib import Path

def tally(lines):
    by = collections.defaultdict(collections.Counter)
    for line in lines:
        if ":" not in line or "__mutmut_" not in line:
            continue
        key, status = line.strip().rsplit(": ", 1)
        # bayesgrasp.belief.x_fn__mutmut_3 or bayesgrasp.belief.xǁClassǁfn__mutmut_3
        parts = key.split(".")
        mod = ".".join(parts[: next(i for i, p in enumerate(parts) if "__mutmut_" in p)])
        by[mod][status] += 1
    return by


def main(argv=None) -> int:
    argv = argv if argv is not None else sys.argv[1:]
    work = Path(argv[0]) if argv else Path(".")
    exe = Path(sys.executable).with_name("mutmut")
    out = subprocess.run([str(exe), "results", "--all", "true"], cwd=work, capture_output=True, text=True,
                         check=True).stdout
    by = tally(out.splitlines())
    print(f"{'module':32s} {'killed':>7s} {'survived':>9s} {'no tests':>9s} {'timeout':>8s} {'score':>7s}")
    for mod in sorted(by):
        c = by[mod]
        den = c["killed"] + c["survived"] + c["no tests"]
        score = c["killed"] / den if den else float("nan")
        print(f"{mod:32s} {c['killed']:7d} {c['survived']:9d} {c['no tests']:9d} {c['timeout']:8d} {score:7.1%}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
