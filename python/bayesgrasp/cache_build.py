"""Rebuilds the package's shipped cache (``bayesgrasp/data/cache``, see :mod:`bayesgrasp.cache`): runs
the first calls a new user makes (the demo, pub2, the README's category and fuse examples) in an
empty cache with the shipped one turned off, then keeps every entry they built (GP models, task
grasps, convex decompositions) and a ``MANIFEST.json`` naming the commands and the files.

Each entry is found later by its cache key (mesh, hand file, settings, cache version), so a shipped
file is used only where it is exactly what the command would build; a change that alters the key
simply leaves it unused until this is run again (``make shipped-cache``).

The commands build into ``--work`` (kept: an interrupted build resumes there, every entry already
built is a cache hit); the shipped folders are replaced only after every command succeeded.

    python -m bayesgrasp.cache_build [--out python/bayesgrasp/data/cache] [--work build/shipped-cache]
                                     [--only demo,pub2]
"""
from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

#: The first calls whose cache entries ship: name -> the CLI's arguments ({out}: a scratch folder).
COMMANDS = {
    "demo": ["demo", "--out", "{out}/demo"],
    "pub2": ["experiment", "pub2", "--runs", "1", "--workers", "2", "--out", "{out}/pub2"],
    "category_handle": ["category", "--category", "mug", "--task", "handle", "--scene-object", "mug/3",
                        "--object-pose", "0.02,-0.01,2.0", "--json"],
    "category_side": ["category", "--category", "mug", "--task", "side", "--scene-object", "mug/3",
                      "--object-pose", "0.01,0.02,0.7", "--method", "part-aware", "--json"],
    "category_bottle": ["category", "--category", "bottle", "--task", "side", "--scene-object", "bottle/4",
                        "--object-pose", "0,0,0.5", "--method", "baseline", "--json"],
    "fuse": ["fuse", "--category", "mug", "--task", "top", "--scene-object", "mug/3", "--object-pose",
             "0.01,0.02,0.7", "--json"],
}

#: The cache's folders that ship (models and task grasps, the lift test's decompositions).
FOLDERS = ("models", "task_grasps", "convex_decomposition")


def default_out() -> Path:
    return Path(__file__).resolve().parent / "data" / "cache"


def run_commands(names, cache: Path, scratch: Path) -> list:
    """Each command in a subprocess on the empty ``cache`` (the shipped one off); its wall seconds."""
    env = dict(os.environ, BAYESGRASP_CACHE=str(cache), BAYESGRASP_SHIPPED_CACHE="0")
    done = []
    for name in names:
        args = [sys.executable, "-m", "bayesgrasp.cli"] + [a.replace("{out}", str(scratch)) for a in COMMANDS[name]]
        print(f"[cache_build] {name}: {' '.join(args[3:])}", file=sys.stderr, flush=True)
        t0 = time.perf_counter()
        subprocess.run(args, env=env, stdout=subprocess.DEVNULL, check=True)
        done.append({"name": name, "args": COMMANDS[name], "seconds": round(time.perf_counter() - t0, 1)})
    return done


def keep(cache: Path, out: Path, commands: list) -> dict:
    """Replaces ``out``'s folders by the cache's (every file and its checksum), writes MANIFEST.json."""
    files = {}
    for folder in FOLDERS:
        src, dst = cache / folder, out / folder
        if dst.exists():
            shutil.rmtree(dst)
        if not src.is_dir():
            continue
        dst.mkdir(parents=True)
        for f in sorted(src.iterdir()):
            if f.is_file() and not f.name.startswith("."):
                shutil.copy2(f, dst / f.name)
                files.setdefault(folder, []).append(f.name)
    from . import __version__
    from .models.settings import CACHE_VERSION

    manifest = {"bayesgrasp": __version__, "cache_version": CACHE_VERSION, "commands": commands, "files": files}
    (out / "MANIFEST.json").write_text(json.dumps(manifest, indent=1) + "\n")
    return manifest


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", default=str(default_out()), help="the shipped cache folder (replaced)")
    ap.add_argument("--only", default=",".join(COMMANDS), help="commands to run (comma-separated)")
    ap.add_argument("--work", default="build/shipped-cache",
                    help="the empty cache the commands fill (kept, so an interrupted build resumes)")
    a = ap.parse_args(argv)
    names = [n for n in a.only.split(",") if n]
    unknown = [n for n in names if n not in COMMANDS]
    if unknown:
        ap.error(f"--only: unknown {unknown}; choose from {list(COMMANDS)}")
    work = Path(a.work)
    cache, scratch = work / "cache", work / "scratch"
    commands = run_commands(names, cache, scratch)
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    manifest = keep(cache, out, commands)
    n = sum(len(v) for v in manifest["files"].values())
    print(f"[cache_build] {n} files in {out}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
