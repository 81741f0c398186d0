"""From an empty model cache (issues 34 and 54's first calls): the README's `category` and `fuse`
examples, `plan` on a mesh file no cache has seen (the library's mug stretched by 0.1% along x,
written as OBJ), `experiment pub2` and the demo, each with a fresh BAYESGRASP_CACHE; wall time and
the longest silence on stderr (progress bars count as output); then (``--warm``) the same command
again in the same cache, and the ratio first / warm. The package's shipped cache stands behind the
empty one unless ``--no-shipped`` (BAYESGRASP_SHIPPED_CACHE=0: nothing built before). Uses the
.venv's bayesgrasp and all cores.

    .venv/bin/python bench/cold_cache.py [--only category,fuse,plan,pub2,demo] [--warm] [--no-shipped]
"""
import argparse
import os
import subprocess
import sys
import tempfile
import threading
import time

BG = os.path.join(os.path.dirname(sys.executable), "bayesgrasp")
COMMANDS = {
    "category": ["category", "--category", "mug", "--task", "handle", "--scene-object", "mug/3",
                 "--object-pose", "0.02,-0.01,2.0", "--json"],
    "fuse": ["fuse", "--category", "mug", "--task", "top", "--scene-object", "mug/3",
             "--object-pose", "0.01,0.02,0.7", "--json"],
    "plan": ["plan", "--object", "{mesh}", "--true-pose", "0.01,0,0.4", "--json"],
    "pub2": ["experiment", "pub2", "--workers", "2", "--out", "{dir}/pub2_{run}"],
    "demo": ["demo", "--out", "{dir}/demo_{run}"],
}


def new_mesh(path: str) -> int:
    """The library's mug stretched by 0.1% along x (no cache key matches it), as OBJ; its triangles."""
    import trimesh

    from bayesgrasp.planners.touch import canonical_object

    m = canonical_object("mug")
    v = m.vertices.copy()
    v[:, 0] *= 1.001
    trimesh.Trimesh(v, m.faces, process=False).export(path)
    return len(m.faces)


def timed(args, env):
    """Wall seconds, the longest gap between stderr output and the last line printed before it."""
    t0 = time.perf_counter()
    p = subprocess.Popen(args, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    last, gap, text, before = [t0], [0.0], [b""], [b"(start)"]

    def read():
        while True:
            b = p.stderr.read1(4096)
            if not b:
                return
            now = time.perf_counter()
            if now - last[0] > gap[0]:
                gap[0], before[0] = now - last[0], text[0]
            last[0] = now
            text[0] = (text[0] + b)[-300:]

    th = threading.Thread(target=read)
    th.start()
    rc = p.wait()
    th.join()
    end = time.perf_counter()
    if end - last[0] > gap[0]:
        gap[0], before[0] = end - last[0], text[0]
    lines = [x for x in before[0].decode(errors="replace").replace("\r", "\n").split("\n") if x.strip()]
    return rc, end - t0, gap[0], (lines[-1].strip() if lines else "(start)")[:80]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--only", default="category,fuse,plan")
    ap.add_argument("--warm", action="store_true", help="run each command again in its cache: the warm figure")
    ap.add_argument("--no-shipped", action="store_true", help="without the package's shipped cache")
    a = ap.parse_args()
    print("| command | triangles | exit | first: wall s | longest stderr silence s | after the line |"
          + (" warm: wall s | first / warm |" if a.warm else ""))
    print("|---|---|---|---|---|---|" + ("---|---|" if a.warm else ""))
    with tempfile.TemporaryDirectory() as d:
        mesh = os.path.join(d, "mug_new.obj")
        tri = new_mesh(mesh)
        for name in a.only.split(","):
            cache = os.path.join(d, f"cache_{name}")
            env = dict(os.environ, BAYESGRASP_CACHE=cache)
            if a.no_shipped:
                env["BAYESGRASP_SHIPPED_CACHE"] = "0"

            def command(run):
                return [BG] + [x.replace("{mesh}", mesh).replace("{dir}", d).replace("{run}", str(run))
                               for x in COMMANDS[name]]

            args = command(0)
            rc, wall, silence, after = timed(args, env)
            shown = " ".join(args[1:]).replace(mesh, "mug_new.obj").replace(d + "/", "")
            row = f"| `{shown}` | {tri if name == 'plan' else ''} | {rc} | {wall:.1f} | {silence:.1f} | {after} |"
            if a.warm:
                rc2, warm, _, _ = timed(command(1), env)
                row += f" {warm:.1f}{'' if rc2 == 0 else f' (exit {rc2})'} | {wall / warm:.1f}x |"
            print(row, flush=True)


if __name__ == "__main__":
    main()
