"""bayesgrasp command line: grasp planning under uncertainty.

Sub-commands:
  demo        the main job: plan, grasp, update the belief, re-plan, on a built-in mug
  plan        the same loop for any object (built-in or mesh file) at a given true pose
  episode     the same loop with your robot executing: new, observe (joints, lifted), show
  experiment  the thesis's experiments (pub2, baselines, pub4, entropy_order, landscapes)
  grasp       close the hand on an object from a top grasp, an approach direction or a hand pose
  category    grasp a new member of a known category for a task (Eq. 4.1)
  fuse        vision then touch: per-model poses and weights from the fingers (Eqs. 4.4-4.6)
  register    simulated depth view, table segmentation, registration against models
  objects     list the built-in objects
  touch       what one touch tells about an object's pose and size (Pub. I)

Comma-separated numbers may start with a minus sign: ``--top -0.01,0,0``.
"""
from __future__ import annotations

import argparse
import os
import sys

from . import category, episode, experiment, fuse, grasp, objects, plan, register, touch
from .args import CliError, join_negative_values

COMMANDS = (grasp, plan, episode, category, fuse, experiment, register, objects, touch)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="bayesgrasp", description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for command in COMMANDS:
        command.add(sub)
    return parser


def main(argv=None) -> int:
    parser = build_parser()
    args = parser.parse_args(join_negative_values(sys.argv[1:] if argv is None else list(argv)))
    if args.command is None:
        parser.print_help()
        return 0
    try:
        return args.run(args)
    except (CliError, ValueError, FileNotFoundError) as e:
        print(f"bayesgrasp {args.command}: error: {e}", file=sys.stderr)
        return 2
    except BrokenPipeError:  # output piped into e.g. `head`, which stopped reading
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0


if __name__ == "__main__":
    sys.exit(main())
