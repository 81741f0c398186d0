"""From an empty model cache (issue 34's first calls): the README's `category` and `fuse` examples
and `plan` on a mesh file no cache has seen (the library's mug stretched by 0.1% along x, written
as OBJ), each with a fresh BAYESGRASP_CACHE; wall time and the longest silence on stderr (progress
bars count as output). Uses the .venv's bayesgrasp and all cores.

    .venv/bin/python bench/cold_cache.py [--only category,fuse,plan]
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
    a = ap.parse_args()
    print("| command | triangles | exit | wall s | longest stderr silence s | after the line |")
    print("|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as d:
        mesh = os.path.join(d, "mug_new.obj")
        tri = new_mesh(mesh)
        for name in a.only.split(","):
            cache = os.path.join(d, f"cache_{name}")
            env = dict(os.environ, BAYESGRASP_CACHE=cache)
            args = [BG] + [x.replace("{mesh}", mesh) for x in COMMANDS[name]]
            rc, wall, silence, after = timed(args, env)
            print(f"| `{' '.join(args[1:]).replace(mesh, 'mug_new.obj')}` | {tri if name == 'plan' else ''} | {rc} | "
                  f"{wall:.1f} | {silence:.1f} | {after} |", flush=True)


if __name__ == "__main__":
    main()
