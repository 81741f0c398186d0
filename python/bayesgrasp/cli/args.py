"""Argument helpers shared by the sub-commands: user errors, comma-separated numbers (negative ones
included), output paths, and the run context built from the common options."""
from __future__ import annotations

import argparse
import math
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import List, Optional, Sequence, Tuple

from .. import DEFAULT_HAND
from ..arm import DEFAULT_BASE


class CliError(Exception):
    """A user error: printed as one line, exit status 2."""


# A value that argparse would take for an option because it starts with '-': a negative number or
# a comma-separated list of numbers whose first one is negative ("-0.01,0,0", "-1e-3", "-.5,2").
_NEGATIVE_VALUE = re.compile(r"^-(\d|\.\d|inf|nan)[^\s]*$", re.IGNORECASE)


def join_negative_values(argv: Sequence[str]) -> List[str]:
    """Rewrites ``--opt -0.01,0,0`` as ``--opt=-0.01,0,0`` so that argparse reads the value as the
    option's argument instead of an unknown option (argparse only accepts lone negative numbers)."""
    out: List[str] = []
    i = 0
    while i < len(argv):
        a = argv[i]
        if a.startswith("--") and "=" not in a and i + 1 < len(argv) and _NEGATIVE_VALUE.match(argv[i + 1]):
            out.append(f"{a}={argv[i + 1]}")
            i += 2
        else:
            out.append(a)
            i += 1
    return out


SEED_MAX = 2**63 - 1


def bounded_int(lo: int, hi: int):
    """An argparse type: an integer in [lo, hi]; argparse names the option in the error
    (``argument --seed: expected an integer in [0, 2^63 - 1], got '-1'``), before any work."""
    hi_text = "2^63 - 1" if hi == SEED_MAX else str(hi)

    def parse(text: str) -> int:
        try:
            v = int(text)
        except ValueError:
            v = None
        if v is None or not lo <= v <= hi:
            raise argparse.ArgumentTypeError(f"expected an integer in [{lo}, {hi_text}], got {text!r}")
        return v

    parse.__name__ = "integer"
    return parse


def floats(text: str, n: int, what: str) -> List[float]:
    """``n`` finite comma-separated numbers from ``text`` (``what`` names the option in errors)."""
    try:
        values = [float(v) for v in text.split(",")]
    except ValueError:
        raise CliError(f"{what}: expected {n} comma-separated numbers, got {text!r}") from None
    if len(values) != n:
        raise CliError(f"{what}: expected {n} comma-separated numbers, got {len(values)}")
    if not all(math.isfinite(v) for v in values):
        raise CliError(f"{what}: values must be finite, got {text!r}")
    return values


def out_dir(path: str, what: str = "--out") -> Path:
    """Creates ``path`` if needed and checks it is writable."""
    out = Path(path)
    try:
        out.mkdir(parents=True, exist_ok=True)
        probe = out / ".write-test"
        probe.write_text("")
        probe.unlink()
    except OSError as e:
        raise CliError(f"{what}: cannot write to {out}: {e.strerror or e}") from None
    return out


def output_file(path: Optional[str], what: str) -> Optional[Path]:
    """Checks that the directory of an output file is writable (before any long work)."""
    if not path:
        return None
    out_dir(str(Path(path).parent or "."), what)
    return Path(path)


def add_hand_option(p: argparse.ArgumentParser) -> None:
    """--hand, as every command takes it (RunContext.hand)."""
    p.add_argument("--hand", type=hand_name, default=DEFAULT_HAND,
                   help="built-in hand name, hand file or URDF (with its NAME.hand.json sidecar)")


def add_robot_options(p: argparse.ArgumentParser) -> None:
    """--robot, --robot-base, --flange and --mount: the arm the hand is mounted on (bayesgrasp.arm)."""
    g = p.add_argument_group("arm", "the arm the hand is mounted on: grasps it cannot reach are refused (grasp) "
                                    "or never chosen while a reachable one exists (plan)")
    g.add_argument("--robot", default=None, metavar="ARM.urdf",
                   help="the arm's URDF (any serial arm), or a built-in arm's name (kuka_lbr4, the thesis's KUKA "
                        "LBR4+); default: none, the hand is free-floating")
    g.add_argument("--robot-base", default=",".join(f"{v:g}" for v in DEFAULT_BASE), metavar="X,Y,Z,YAW",
                   help="the arm's root in the table frame (m, m, m, rad)")
    g.add_argument("--flange", default=None, metavar="LINK",
                   help="the link the hand is mounted on (default: the chain's last link)")
    g.add_argument("--mount", default=None, metavar="X,Y,Z,R,P,Y",
                   help="the palm in the flange's frame (m, rad; roll, pitch, yaw as in a URDF) (default: the "
                        "hand's base on the flange, its approach along the flange's z)")


def robot_arm(args: argparse.Namespace, hand):
    """The --robot arm with --robot-base, --flange and --mount (``hand``: the loaded hand, for the
    default mount), or None without --robot; CliError naming the option."""
    if getattr(args, "robot", None) is None:
        for opt in ("flange", "mount"):
            if getattr(args, opt, None) is not None:
                raise CliError(f"--{opt}: only with --robot")
        return None
    from ..arm import Arm, default_mount, mount_pose, resolve_arm

    base = floats(args.robot_base, 4, "--robot-base")
    mount = default_mount(hand) if args.mount is None else mount_pose(floats(args.mount, 6, "--mount"))
    try:
        resolve_arm(args.robot)
    except ValueError as e:
        raise CliError(f"--robot: {str(e).split(': ', 1)[-1]}") from None
    try:
        return Arm.load(args.robot, flange=args.flange, mount=mount, base=base)
    except ValueError as e:
        msg = str(e)
        option = "--flange" if msg.startswith("flange") else "--robot"
        raise CliError(f"{option}: {msg.split(': ', 1)[-1]}") from None


def add_object_options(p: argparse.ArgumentParser, units: bool = True, mass: bool = True) -> None:
    """--units (unless the command's camera options give it) and --mass (for commands that lift)
    for --object's mesh."""
    if units:
        p.add_argument("--units", default=None, choices=["m", "cm", "mm"],
                       help="length unit of an --object mesh file (default m)")
    if not mass:
        return
    p.add_argument("--mass", type=float, default=None, metavar="KG",
                   help="the object's weight (a scale's reading, kg): sets its density; default: its volume "
                        "at 1000 kg/m^3 (a built-in's own density)")


def object_arg(args: argparse.Namespace, option: str = "--object"):
    """--object loaded once, in --units and weighing --mass (an ObjectModel); a problem with the
    mesh is a CliError naming ``--object FILE``."""
    name = getattr(args, option.lstrip("-").replace("-", "_"))
    units, mass = getattr(args, "units", None), getattr(args, "mass", None)
    if mass is not None and not (math.isfinite(mass) and mass > 0):
        raise CliError(f"--mass: must be a weight > 0 kg, got {mass}")
    from ..objects import load_object

    try:
        return load_object(name, units=units, mass=mass)
    except (ValueError, FileNotFoundError) as e:
        raise CliError(f"{option} {name}: {e}") from None


def add_seed_option(p: argparse.ArgumentParser, help: str = "seed of every random draw (same seed, same result)") -> None:
    """--seed, as every command takes it (RunContext.seed)."""
    p.add_argument("--seed", type=bounded_int(0, SEED_MAX), default=0, help=help)


def add_context_options(p: argparse.ArgumentParser, lift: bool = False, seed: bool = True) -> None:
    """The options every run context is built from: --hand, --cache, --success (and --seed, --no-lift)."""
    add_hand_option(p)
    p.add_argument("--success", default="lift", choices=["lift", "epsilon"],
                   help="what a successful grasp is: held in the lift test (default) or epsilon above the "
                        "models' eps_stable (the thesis's simulation criterion)")
    p.add_argument("--cache", default=None, help="model cache directory (default: $BAYESGRASP_CACHE/models, "
                                                 "$BAYESGRASP_CACHE defaulting to ~/.cache/bayesgrasp)")
    if seed:
        add_seed_option(p)
    p.add_argument("--set", action="append", default=[], metavar="GROUP.FIELD=VALUE",
                   help="override a setting: models.FIELD (bayesgrasp.models.ModelSettings, e.g. models.n_samples=500), "
                        "planner.FIELD (bayesgrasp.planners.PlannerSettings, e.g. planner.n_particles=1000) "
                        "or episode.measurement_noise (rad); repeatable")
    if lift:
        p.add_argument("--no-lift", action="store_true", help="skip the physical lift tests (faster)")


def add_families_option(p: argparse.ArgumentParser) -> None:
    """--families: the grasp families the planners choose from."""
    p.add_argument("--families", default="top", metavar="top|side|top,side",
                   help="grasp families to plan over: top (palm down, the thesis's), side (a horizontal approach; "
                        "height, roll and spread chosen per object), or both (default: top)")


def add_category_options(p: argparse.ArgumentParser, png_help: str) -> None:
    """What `category` and `fuse` share: leave-one-out, demonstrated grasps from a file, JSON, PNG."""
    p.add_argument("--exclude", nargs="*", default=None, metavar="NAME",
                   help="training models to leave out (default: the scene object itself, if it is one)")
    p.add_argument("--task-grasps", default=None, metavar="FILE",
                   help="demonstrated grasps to use instead of generating them (JSON {\"grasps\": [{model, task, pose "
                        "(4x4, model frame), spread, epsilon, lifted}]}; the generator's cache files have this format, "
                        "so hand-made grasps can be added to a copy of one)")
    add_format_options(p)
    add_view_option(p)
    p.add_argument("--png", default=None, metavar="FILE", help=png_help)


def task_grasps_arg(args: argparse.Namespace):
    """The --task-grasps file's grasps, or None (generate them)."""
    if not getattr(args, "task_grasps", None):
        return None
    from ..models.task_grasps import load_task_grasp_file

    return load_task_grasp_file(args.task_grasps)


#: The command-line option of each RunContext field whose check can fail.
CONTEXT_OPTIONS = {"lift": "--no-lift", "success": "--success", "families": "--families",
                   "measurement_noise": "--set episode.measurement_noise", "planner": "--set planner"}


#: --set groups -> the run-context setting each reaches.
GROUP_SETTING = {"models": "models", "planner": "planner", "episode": "measurement_noise"}


@dataclass(frozen=True)
class GivenSetting:
    """A run-context setting the command line gives, and the option that gives it (e.g.
    ``planner``, ``--set planner.n_particles``)."""

    setting: str
    option: str


def given_settings(args: argparse.Namespace) -> Tuple[GivenSetting, ...]:
    """The run-context settings the command line gives, each once with the first option that
    gives it: an option set to another value than the context's default, and any --set or --sweep
    of a setting's group (given is given, even at the default value)."""
    from ..loop.context import RunContext

    values = (("success", getattr(args, "success", RunContext.success)), ("lift", not getattr(args, "no_lift", False)),
              ("families", families_arg(getattr(args, "families", ",".join(RunContext.families)))))
    given = [GivenSetting(s, CONTEXT_OPTIONS[s]) for s, v in values if v != getattr(RunContext, s)]
    for option, assignments in (("--set", getattr(args, "set", [])), ("--sweep", getattr(args, "sweep", []))):
        for a in assignments:
            group = a.partition("=")[0].partition(".")[0]
            if group in GROUP_SETTING and all(g.setting != GROUP_SETTING[group] for g in given):
                given.append(GivenSetting(GROUP_SETTING[group], f"{option} {a.partition('=')[0]}"))
    return tuple(given)


def refuse_unread(args: argparse.Namespace, reads, what: str) -> None:
    """A run setting that ``what`` does not read (not in ``reads``) is refused, not silently dropped."""
    unread = [g for g in given_settings(args) if g.setting not in reads]
    if unread:
        raise CliError(f"{', '.join(g.option for g in unread)}: {what} does not read "
                       f"{', '.join(g.setting for g in unread)} (of the run settings it reads: {', '.join(reads) or 'none'})")


def context(args: argparse.Namespace, progress: bool = True, reads: Optional[Sequence[str]] = None):
    """The :class:`~bayesgrasp.loop.context.RunContext` of a command, built once from its
    options; ``reads``: the run settings the command reads (None: all), the others are refused."""
    from ..loop.context import RunContext, stderr_progress

    if reads is not None:
        refuse_unread(args, reads, f"`{args.command}`" if getattr(args, "command", None) else "this command")
    if getattr(args, "cache", None):
        out_dir(args.cache, "--cache")  # before minutes of model building
    success, lift = getattr(args, "success", "lift"), not getattr(args, "no_lift", False)
    try:  # RunContext checks the settings (the success/lift rule among them); errors name the option
        return RunContext(hand=getattr(args, "hand", DEFAULT_HAND), cache_dir=getattr(args, "cache", None),
                          success=success, lift=lift, seed=getattr(args, "seed", 0),
                          progress=stderr_progress if progress else None,
                          model_settings=model_settings(getattr(args, "set", []), success),
                          families=families_arg(getattr(args, "families", "top")),
                          planner=planner_settings(getattr(args, "set", [])),
                          measurement_noise=measurement_noise(getattr(args, "set", [])))
    except ValueError as e:
        which, _, why = str(e).partition(": ")
        raise CliError(f"{CONTEXT_OPTIONS.get(which, '--' + which)}: {why}") from None


def families_arg(text):
    """--families as a tuple of family names (a CliError naming the option otherwise)."""
    from ..models import parse_families

    try:
        return parse_families(text)
    except ValueError as e:
        raise CliError(f"--{e}") from None


#: Fields --set may not reach: an option of their own sets them (one channel per setting).
SET_BY_OPTION = {"models.success": "--success", "models.family": "--families"}


#: The groups --set reaches, each a settings class: models (ModelSettings), planner
#: (PlannerSettings), episode (EpisodeOverrides).
SET_GROUPS = ("models", "planner", "episode")


def _set_class(group: str):
    """The settings class of a --set group (None for another name)."""
    from ..loop.context import EpisodeOverrides
    from ..models import ModelSettings
    from ..planners import PlannerSettings

    return {"models": ModelSettings, "planner": PlannerSettings, "episode": EpisodeOverrides}.get(group)


@dataclass(frozen=True)
class SetOverrides:
    """The --set overrides read, per group: {field: value} (each value its field's type)."""

    models: dict = field(default_factory=dict)
    planner: dict = field(default_factory=dict)
    episode: dict = field(default_factory=dict)


def _read_value(default, text: str, name: str):
    """``text`` read as the type of the field's ``default`` (bool, int, float, a tuple of
    floats "a,b,c", None for an optional number, or a string)."""
    if text.lower() == "none" and (default is None or name == "spread"):
        return None
    if isinstance(default, bool):
        return {"true": True, "false": False}[text.lower()]
    if isinstance(default, int):
        return int(text)
    if isinstance(default, float) or default is None:
        return float(text)
    if isinstance(default, (tuple, list)):
        return tuple(float(v) for v in text.split(","))
    return text


def parse_set(assignments) -> SetOverrides:
    """``GROUP.FIELD=VALUE`` overrides (--set), each value read as its field's type; a CliError
    names a wrong group, field or value."""
    import dataclasses

    out = SetOverrides()
    for a in assignments:
        key, sep, text = a.partition("=")
        group, _, name = key.partition(".")
        cls = _set_class(group)
        fields = {f.name for f in dataclasses.fields(cls)} if cls else set()
        if not sep or name not in fields:
            known = "; ".join(f"{g}: {', '.join(sorted(f.name for f in dataclasses.fields(_set_class(g))))}"
                              for g in SET_GROUPS)
            raise CliError(f"--set: expected models.FIELD=VALUE, planner.FIELD=VALUE or episode.FIELD=VALUE with "
                           f"FIELD one of ({known}); got {a!r}")
        if key in SET_BY_OPTION:
            raise CliError(f"--set: {key} is set by {SET_BY_OPTION[key]}; give it there")
        default = getattr(cls(), name)
        try:
            getattr(out, group)[name] = _read_value(default, text, name)
        except (ValueError, KeyError):
            raise CliError(f"--set: {key}: cannot read {text!r} as {type(default).__name__}") from None
    return out


def model_settings(assignments, success: str):
    """ModelSettings from the ``models.FIELD=VALUE`` overrides (None when there are none)."""
    from ..models import ModelSettings

    values = parse_set(assignments).models
    if not values:
        return None
    try:
        return ModelSettings(**{"success": success, **values})
    except ValueError as e:
        raise CliError(f"--set: {e}") from None


def planner_settings(assignments):
    """PlannerSettings from the ``planner.FIELD=VALUE`` overrides (None when there are none)."""
    from ..planners import PlannerSettings

    values = parse_set(assignments).planner
    if not values:
        return None
    try:
        return PlannerSettings(**values)
    except ValueError as e:
        raise CliError(f"--set: planner.{e}") from None


def measurement_noise(assignments) -> float:
    """episode.measurement_noise from the overrides (0 when not given)."""
    return float(parse_set(assignments).episode.get("measurement_noise", 0.0))


FORMATS = ("text", "json", "ros")


def add_format_options(p: argparse.ArgumentParser) -> None:
    """--format text|json|ros and --json (the same as --format json)."""
    p.add_argument("--format", choices=FORMATS, default=None,
                   help="text (default), json (one JSON object, the grasp in the schema of "
                        "bayesgrasp/data/schema/grasp.schema.json) or ros (JSON shaped like moveit_msgs/Grasp)")
    p.add_argument("--json", action="store_true", help="print one JSON object (the same as --format json)")


def add_view_option(p: argparse.ArgumentParser) -> None:
    """--view [PORT]: after the output, the result in 3D in the browser (as `bayesgrasp view`)."""
    p.add_argument("--view", nargs="?", type=bounded_int(1, 65535), const=8080, default=None, metavar="PORT",
                   help="then show the result in 3D in the browser (viser) on PORT (default 8080; the next free one "
                        "if busy) until Ctrl-C, as `bayesgrasp view FILE.json` does")
    p.add_argument("--view-seconds", type=float, default=None, metavar="S",
                   help="with --view: stop the viewer after S seconds (default: at Ctrl-C)")


def output_format(args: argparse.Namespace) -> str:
    """The chosen output format; --json with another --format is an error."""
    fmt = getattr(args, "format", None)
    if getattr(args, "json", False):
        if fmt not in (None, "json"):
            raise CliError(f"--json: not with --format {fmt}")
        return "json"
    return fmt or "text"


def hand_name(text: str) -> str:
    """An argparse type for --hand: a built-in hand's name or a hand file that exists (argparse then
    names --hand in the error, before any work)."""
    from ..hand import builtin_hands, resolve_hand

    try:
        resolve_hand(text)
        return text
    except ValueError:
        raise argparse.ArgumentTypeError(f"unknown hand {text!r} (built-in: {', '.join(builtin_hands())}; or the "
                                         "path of a hand file or a URDF)") from None


hand_name.__name__ = "hand"


class Renamed(argparse.Action):
    """Stores the value like ``store``; given by one of its ``old`` spellings (kept for one
    release), it also prints one deprecation line on stderr naming the new spelling."""

    def __init__(self, option_strings, dest, old=(), **kw):
        self.old = tuple(old)
        super().__init__(option_strings, dest, **kw)

    def __call__(self, parser, namespace, values, option_string=None):
        if option_string in self.old:
            import sys

            new = next(o for o in self.option_strings if o not in self.old)
            print(f"{parser.prog}: warning: {option_string} is deprecated and will be removed in the next release; "
                  f"use {new}", file=sys.stderr)
        setattr(namespace, self.dest, values)
