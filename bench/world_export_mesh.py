"""Writes a built-in object's mesh (object frame: centred, standing on z = 0) as an OBJ file, for
the C++ benchmarks (bench_sim --mesh=FILE).

    python bench/world_export_mesh.py mug bench/results/builtin_mug.obj
"""
import sys
from pathlib import Path

from bayesgrasp.objects import Scene


def main(name="mug", out="bench/results/builtin_mug.obj"):
    obj = Scene.single(name).canonical_object(0)
    Path(out).parent.mkdir(parents=True, exist_ok=True)
    with open(out, "w") as f:
        f.writelines(f"v {x:.9g} {y:.9g} {z:.9g}\n" for x, y, z in obj.vertices)
        f.writelines(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in obj.faces)
    print(f"{name}: {len(obj.faces)} triangles -> {out}")


if __name__ == "__main__":
    main(*sys.argv[1:])
