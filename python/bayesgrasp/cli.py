"""bayesgrasp command line: grasp planning under uncertainty.

Sub-commands:
  grasp     close the hand on an object at a top-grasp pose; quality and lift test
  demo      the main job on a built-in object
  register  simulated depth view, table segmentation, registration against models
  objects   list the built-in objects
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path


class CliError(Exception):
    """A user error: printed as one line, exit status 2."""


def _floats(text: str, n: int, what: str) -> list[float]:
    try:
        values = [float(v) for v in text.split(",")]
    except ValueError:
        raise CliError(f"{what}: expected {n} comma-separated numbers, got {text!r}") from None
    if len(values) != n:
        raise CliError(f"{what}: expected {n} comma-separated numbers, got {len(values)}")
    if not all(map(lambda v: v == v and abs(v) != float("inf"), values)):
        raise CliError(f"{what}: values must be finite, got {text!r}")
    return values


def _out_dir(path: str) -> Path:
    out = Path(path)
    try:
        out.mkdir(parents=True, exist_ok=True)
        probe = out / ".write-test"
        probe.write_text("")
        probe.unlink()
    except OSError as e:
        raise CliError(f"--out: cannot write to {out}: {e.strerror or e}") from None
    return out


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="bayesgrasp", description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")

    g = sub.add_parser("grasp", help="close the hand at a top-grasp pose and report the result")
    g.add_argument("--object", required=True, help="built-in object name (see `bayesgrasp objects`) or mesh file")
    g.add_argument("--top", required=True, metavar="X,Y,YAW",
                   help="top grasp relative to the object's origin: metres, metres, radians")
    g.add_argument("--object-pose", default="0,0,0", metavar="X,Y,YAW", help="object pose on the table")
    g.add_argument("--spread", type=float, default=None, help="finger spread (radians); default: the hand's")
    g.add_argument("--hand", default="barrett_bh8", help="hand file name or path")
    g.add_argument("--keep-origin", action="store_true", help="keep a loaded mesh's own origin")
    g.add_argument("--no-lift", action="store_true", help="skip the physical lift test")
    g.add_argument("--json", action="store_true", help="print one JSON object")

    d = sub.add_parser("demo", help="the main job on a built-in object")
    d.add_argument("--object", default="mug")
    d.add_argument("--out", default="out/demo", help="directory for the PNG and results")
    d.add_argument("--seed", type=int, default=0)

    r = sub.add_parser("register", help="render a view of an object, segment it and register it against models")
    r.add_argument("--scene-object", required=True, help="object placed in the scene (built-in name or mesh file)")
    r.add_argument("--pose", default="0,0,0", metavar="X,Y,YAW", help="its pose on the table")
    r.add_argument("--models", required=True, nargs="+", metavar="NAME_OR_PATH", help="models to register against")
    r.add_argument("--voxel", type=float, default=0.005, help="voxel size (m); all radii scale from it")
    r.add_argument("--seed", type=int, default=0)
    r.add_argument("--png", default=None, help="write a PNG of the cloud over each registered model")
    r.add_argument("--json", action="store_true", help="print one JSON object")

    sub.add_parser("objects", help="list the built-in objects")
    return parser


def main(argv=None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if args.command is None:
        parser.print_help()
        return 0
    from . import commands  # imported late: keeps `--help` fast
    try:
        return getattr(commands, args.command)(args)
    except CliError as e:
        print(f"bayesgrasp {args.command}: error: {e}", file=sys.stderr)
        return 2
    except (ValueError, FileNotFoundError) as e:
        print(f"bayesgrasp {args.command}: error: {e}", file=sys.stderr)
        return 2
    except BrokenPipeError:  # output piped into e.g. `head`, which stopped reading
        import os
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0


if __name__ == "__main__":
    sys.exit(main())
