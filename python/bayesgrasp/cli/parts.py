"""``bayesgrasp parts``: write part labels for a mesh of your own by simple geometric rules."""
from __future__ import annotations

from collections import Counter


def add(sub) -> None:
    p = sub.add_parser("parts", help="label a mesh's triangles by rules and write MESH.parts.json beside it",
                       description="Writes <stem>.parts.json beside the mesh: one part per triangle of the file, in "
                                   "file order. Each --rule NAME:AXIS<VALUE or NAME:AXIS>VALUE (AXIS x, y, z or r, "
                                   "the distance from the vertical axis; metres, in the frame the object is grasped "
                                   "in: xy box centred, lowest point at z = 0) claims the triangles whose centroid "
                                   "meets it and no earlier rule; the rest are --default.")
    p.add_argument("mesh", help="OBJ, STL or PLY file")
    p.add_argument("--rule", action="append", required=True, metavar="NAME:AXIS<>VALUE",
                   help="e.g. rim:z>0.075 or handle:r>0.045 (repeat; the first rule a triangle meets wins)")
    p.add_argument("--default", default="body", help="part of the triangles no rule claims (default body)")
    p.add_argument("--units", default=None, choices=["m", "cm", "mm"], help="length unit of the mesh file (default m)")
    p.set_defaults(run=run)


def run(args) -> int:
    from ..objects import load_mesh
    from ..objects.part_rules import parse_rule, write_label_file
    from .args import CliError

    try:
        rules = [parse_rule(r) for r in args.rule]
    except ValueError as e:
        raise CliError(f"--rule: {e}") from None
    try:
        path = write_label_file(args.mesh, rules, args.default, units=args.units)
    except (ValueError, FileNotFoundError) as e:
        raise CliError(f"{args.mesh}: {e}") from None
    obj = load_mesh(args.mesh, units=args.units)          # read back as every command will
    counts = Counter(obj.part_of_faces(range(obj.n_faces)))
    print(f"wrote {path}: " + ", ".join(f"{n} {counts.get(n, 0)}" for n in obj.part_names) + " triangles")
    return 0
