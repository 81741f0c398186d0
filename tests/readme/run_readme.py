"""Runs every example of README.md in order on a clean copy of the clone and checks what its text
claims (``make readme``; see ``readme_examples.py`` for what is read and checked).

The copy holds the files git tracks (``git ls-files``) and a link to this clone's ``.venv``; the
examples run there with ``bash`` (shell) or the venv's Python, one after another, so a later
example sees what the earlier ones wrote, as a reader's would. Experiments run with ``--runs N``
(``--runs``, default 2) in place of their own count; everything else runs as written, on the
model cache of ``$BAYESGRASP_CACHE`` (default ``~/.cache/bayesgrasp``): the first run builds
every model the README uses, which takes hours on 2 cores; later runs take minutes.

Progress goes to stderr, one line per example with its time; ``--report FILE`` writes the
outcome of each as JSON. Exit 1 when any example fails.

    .venv/bin/python tests/readme/run_readme.py [--runs 2] [--only TEXT] [--from LINE] [--until LINE] [--list]
"""
from __future__ import annotations

import argparse
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from readme_examples import MAKE_DEMO, ROOT, Example, bayesgrasp_argv, expects_refusal, not_run, parse  # noqa: E402


def clean_copy(dest: Path) -> Path:
    """The tracked files of the clone in ``dest``, with its .venv linked."""
    files = subprocess.run(["git", "ls-files", "-z"], cwd=ROOT, capture_output=True, check=True).stdout.split(b"\0")
    for f in filter(None, files):
        src, dst = ROOT / f.decode(), dest / f.decode()
        if src.is_file():
            dst.parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(src, dst)
    (dest / ".venv").symlink_to(ROOT / ".venv")
    return dest


def command(e: Example, runs: int) -> str:
    """The shell text to run: experiments with ``--runs`` set to ``runs``."""
    if e.argv[:2] == ["make", "demo"]:
        return MAKE_DEMO                  # the demo's job; the set-up is this clone's
    text = e.text
    argv = bayesgrasp_argv(e) or []
    if argv[:1] == ["experiment"] and len(argv) > 1 and argv[1] != "list":
        text = re.sub(r"\s--runs\s+\d+", "", text) + f" --runs {runs}"
    return text


def check(e: Example, cwd: Path, p: subprocess.CompletedProcess, seconds: float) -> list:
    """The claims of ``e`` that its run does not bear out (empty: it did what its text says)."""
    if expects_refusal(e):
        ok = p.returncode == 2 and "--address" in p.stderr and seconds < 60
        return [] if ok else [f"expected a refusal naming --address within 60 s; exit {p.returncode} after "
                              f"{seconds:.0f} s"]
    if p.returncode != 0:
        return [f"exit {p.returncode}: {p.stderr.strip().splitlines()[-1] if p.stderr.strip() else ''}"]
    bad = []
    for c in e.claims:
        kind, _, arg = c.partition(":")
        if kind == "file" and not (cwd / arg).is_file():
            bad.append(f"{arg} not written")
        elif kind == "dir" and not (cwd / arg).is_dir():
            bad.append(f"{arg}/ not written")
        elif kind == "experiment":
            d = cwd / arg
            missing = [f for f in ("summary.md", "results.sqlite") if not (d / f).is_file()]
            if not list(d.glob("*.png")):
                missing.append("a PNG")
            if missing:
                bad.append(f"{arg}: no {', '.join(missing)}")
        elif kind == "sweep":
            missing = [f for f in ("sweep.md", "sweep.csv", "sweep.png", "results.sqlite") if not (cwd / arg / f).is_file()]
            if missing:
                bad.append(f"{arg}: no {', '.join(missing)}")
        elif kind == "lifted":
            out = p.stdout
            said = re.search(r"(?<!not )\blifted\b|\"lifted\": true", out)
            if not said or re.search(r"\bdropped\b|not lifted|\"lifted\": false", out):
                bad.append("its text says lifted; the output does not")
        elif kind == "prints":
            got = p.stdout.rstrip("\n").splitlines()
            if got != e.printed:
                bad.append("prints other lines than the README shows:\n    " + "\n    ".join(got))
    return bad


def run_one(e: Example, cwd: Path, runs: int, env: dict) -> dict:
    t0 = time.perf_counter()
    if e.kind == "python":
        p = subprocess.run([str(ROOT / ".venv" / "bin" / "python"), "-c", e.text], cwd=cwd, env=env,
                           capture_output=True, text=True)
    else:
        p = subprocess.run(["bash", "-c", command(e, runs)], cwd=cwd, env=env, capture_output=True, text=True,
                           timeout=6 * 3600)
    seconds = time.perf_counter() - t0
    bad = check(e, cwd, p, seconds)
    return {"line": e.line, "section": e.section, "example": e.text.strip()[:300], "seconds": round(seconds, 1),
            "exit": p.returncode, "ok": not bad, "problems": bad,
            "stderr_tail": p.stderr.strip().splitlines()[-3:] if bad else []}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--runs", type=int, default=2, help="runs per experiment in place of the README's")
    ap.add_argument("--only", default=None, help="run only examples whose text or section contains this")
    ap.add_argument("--from", dest="from_line", type=int, default=0, help="skip examples before this README line")
    ap.add_argument("--until", type=int, default=10**9, help="skip examples after this README line")
    ap.add_argument("--list", action="store_true", help="list the examples and their claims, run nothing")
    ap.add_argument("--report", default=None, help="write each example's outcome as JSON here")
    ap.add_argument("--keep", default=None, help="run in this directory (kept) instead of a temporary one")
    args = ap.parse_args(argv)

    examples = [e for e in parse() if args.from_line <= e.line <= args.until and
                (args.only is None or args.only in e.text or args.only in e.section)]
    if args.list:
        for e in examples:
            why = not_run(e)
            print(f"{e.label()}\n    claims: {', '.join(e.claims) or '-'}{'; not run: ' + why if why else ''}")
        return 0
    tmp = None
    if args.keep:
        cwd = Path(args.keep).resolve()
        if not (cwd / "README.md").is_file():
            cwd.mkdir(parents=True, exist_ok=True)
            clean_copy(cwd)
    else:
        tmp = tempfile.TemporaryDirectory(prefix="bayesgrasp-readme-")
        cwd = clean_copy(Path(tmp.name))
    env = dict(os.environ, PYTHONUNBUFFERED="1")
    results, t_all = [], time.perf_counter()
    try:
        for n, e in enumerate(examples, 1):
            why = not_run(e)
            if why:
                results.append({"line": e.line, "example": e.text.strip()[:300], "ok": None, "not_run": why})
                print(f"[{n}/{len(examples)}] not run ({why}): {e.label()}", file=sys.stderr)
                continue
            print(f"[{n}/{len(examples)}] {e.label()}", file=sys.stderr, flush=True)
            r = run_one(e, cwd, args.runs, env)
            results.append(r)
            print(f"    {'ok' if r['ok'] else 'FAILED'} in {r['seconds']:.0f} s" +
                  "".join(f"\n    {b}" for b in r["problems"]), file=sys.stderr, flush=True)
            if args.report:
                Path(args.report).write_text(json.dumps(results, indent=1))
    finally:
        if tmp is not None:
            tmp.cleanup()
    failed = [r for r in results if r.get("ok") is False]
    ran = [r for r in results if r.get("ok") is not None]
    print(f"README: {len(ran) - len(failed)} of {len(ran)} examples ran as their text says "
          f"({len(results) - len(ran)} not run) in {(time.perf_counter() - t_all) / 60:.1f} min", file=sys.stderr)
    for r in failed:
        print(f"  FAILED README:{r['line']}: {r['example'][:100]}: {'; '.join(r['problems'])}", file=sys.stderr)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
