"""bayesgrasp command line: grasp planning under uncertainty.

Sub-commands:
  demo        the main job: plan, grasp, update the belief, re-plan, on a built-in mug
  plan        the same loop for any object (built-in or mesh file) at a given true pose
  experiment  the thesis's experiments (pub2, baselines, pub4, entropy_order, landscapes)
  grasp       close the hand on an object at a top-grasp pose; quality and lift test
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

    d = sub.add_parser("demo", help="the main job: grasping a mug whose pose is uncertain")
    d.add_argument("--object", default="mug", help="built-in object name or mesh file")
    d.add_argument("--method", default="explore", choices=["stability", "explore", "ml_pose", "open_loop"])
    d.add_argument("--out", default="out/demo", help="directory for the PNG and results")
    d.add_argument("--seed", type=int, default=0)
    d.add_argument("--cache", default=None, help="model cache directory (default: $BAYESGRASP_CACHE/models, "
                                                  "$BAYESGRASP_CACHE defaulting to ~/.cache/bayesgrasp)")

    p = sub.add_parser("plan", help="run the planning loop on an object at a hidden true pose")
    p.add_argument("--object", required=True, help="built-in object name or mesh file")
    p.add_argument("--true-pose", required=True, metavar="X,Y,YAW", help="the hidden pose: metres, metres, radians")
    p.add_argument("--method", default="explore", choices=["stability", "explore", "ml_pose", "open_loop"])
    p.add_argument("--estimate", default=None, metavar="X,Y,YAW",
                   help="the initial pose estimate (default: true pose + uniform noise within the belief)")
    p.add_argument("--attempts", type=int, default=4)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--noise", type=float, default=0.0, help="joint-angle measurement noise std (rad)")
    p.add_argument("--hand", default="barrett_bh8", help="hand file name or path")
    p.add_argument("--cache", default=None, help="model cache directory")
    p.add_argument("--png", default=None, help="write a PNG of the belief's evolution")
    p.add_argument("--json", action="store_true", help="print one JSON object")

    e = sub.add_parser("experiment", help="run (or resume) one of the thesis's experiments")
    e.add_argument("name", help="pub2, baselines, pub4, entropy_order or landscapes")
    e.add_argument("--runs", type=int, default=None, help="runs per object (default: the experiment's)")
    e.add_argument("--workers", type=int, default=1, help="worker processes")
    e.add_argument("--out", default=None, help="output directory (default: out/experiments/NAME)")
    e.add_argument("--objects", nargs="+", default=None, help="objects (default: the experiment's)")
    e.add_argument("--seed", type=int, default=0, help="base seed")
    e.add_argument("--cache", default=None, help="model cache directory")
    e.add_argument("--no-lift", action="store_true", help="skip the lift tests (faster)")

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
