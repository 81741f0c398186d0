"""bayesgrasp command line: grasp planning under uncertainty.

Sub-commands:
  demo        the main job: plan, grasp, update the belief, re-plan, on a built-in mug
  plan        the same loop for any object (built-in or mesh file) at a given true pose
  episode     the same loop with your robot executing: new, observe (joints, lifted), show
  serve       the episode loop as an HTTP JSON service for a robot's stack (token, TLS)
  experiment  the thesis's experiments (pub2, baselines, pub4, entropy_order, landscapes)
  results     an experiment's stored results as SQL tables (--sql QUERY, --csv)
  grasp       close the hand on an object from a top grasp, an approach direction or a hand pose
  category    grasp a new member of a known category for a task (Eq. 4.1)
  fuse        vision then touch: per-model poses and weights from the fingers (Eqs. 4.4-4.6)
  register    simulated depth view, table segmentation, registration against models
  objects     list the built-in objects
  parts       label a mesh's triangles by simple rules (its part label file)
  touch       what one touch tells about an object's pose and size (Pub. I)

Comma-separated numbers may start with a minus sign: ``--top -0.01,0,0``.
"""
from __future__ import annotations

import argparse
import os
import sys
import warnings

from . import category, episode, experiment, fuse, grasp, objects, parts, plan, register, results, serve, touch, view
from .. import __version__
from .args import CliError, join_negative_values

COMMANDS = (grasp, plan, episode, serve, category, fuse, experiment, results, register, objects, parts, touch, view)


class HelpFormatter(argparse.RawDescriptionHelpFormatter):
    """Descriptions as written; every option's default appended to its help unless the help
    already tells it (or the default is None / False: nothing to tell)."""

    def _get_help_string(self, action):
        h = action.help or ""
        if ("default" in h.lower() or action.default in (None, False, argparse.SUPPRESS)
                or not action.option_strings or action.default == []):
            return h
        return h + " (default: %(default)s)"


class Parser(argparse.ArgumentParser):
    """Every (sub-)parser shows its defaults (:class:`HelpFormatter`)."""

    def __init__(self, *a, **kw):
        kw.setdefault("formatter_class", HelpFormatter)
        super().__init__(*a, **kw)


def build_parser() -> argparse.ArgumentParser:
    parser = Parser(prog="bayesgrasp", description=__doc__)
    parser.add_argument("--version", action="version", version=f"bayesgrasp {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=Parser)
    for command in COMMANDS:
        command.add(sub)
    return parser


def _one_line_warning(message, category, filename, lineno, line=None) -> str:
    """A warning as the command's user reads it: one line, no source location."""
    return f"bayesgrasp: warning: {message}\n"


def main(argv=None) -> int:
    parser = build_parser()
    args = parser.parse_args(join_negative_values(sys.argv[1:] if argv is None else list(argv)))
    if args.command is None:
        parser.print_help()
        return 0
    formatwarning, warnings.formatwarning = warnings.formatwarning, _one_line_warning
    try:
        return args.run(args)
    except (CliError, ValueError, FileNotFoundError) as e:
        print(f"bayesgrasp {args.command}: error: {e}", file=sys.stderr)
        return 2
    except BrokenPipeError:  # output piped into e.g. `head`, which stopped reading
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0
    finally:
        warnings.formatwarning = formatwarning


if __name__ == "__main__":
    sys.exit(main())
