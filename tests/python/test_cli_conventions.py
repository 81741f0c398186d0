"""What a shell user expects of the CLI: --version, help for every command and option with its
default, an unknown hand named as --hand."""
import argparse

import pytest

import bayesgrasp
from bayesgrasp.cli import build_parser, main


def test_version_is_the_package_version(capsys):
    with pytest.raises(SystemExit) as e:
        main(["--version"])
    assert e.value.code == 0
    assert capsys.readouterr().out.strip() == f"bayesgrasp {bayesgrasp.__version__}"


def parsers(parser, name="bayesgrasp"):
    """(name, parser, help line) of every sub-command, nested ones included."""
    for a in parser._actions:
        if isinstance(a, argparse._SubParsersAction):
            helps = {c.dest: c.help for c in a._choices_actions}
            for n, sp in a.choices.items():
                yield f"{name} {n}", sp, helps.get(n)
                yield from parsers(sp, f"{name} {n}")


ALL = list(parsers(build_parser()))


def test_every_command_is_walked():
    names = {n for n, _, _ in ALL}
    assert {"bayesgrasp demo", "bayesgrasp plan", "bayesgrasp episode observe", "bayesgrasp touch",
            "bayesgrasp objects", "bayesgrasp experiment", "bayesgrasp register"} <= names


@pytest.mark.parametrize("name, parser, line", ALL, ids=[n for n, _, _ in ALL])
def test_every_command_and_option_has_help(name, parser, line):
    assert line and parser.description, name
    missing = [a.option_strings or a.dest for a in parser._actions
               if not isinstance(a, argparse._SubParsersAction) and not a.help]
    assert not missing, f"{name}: options without help: {missing}"


def test_defaults_are_shown(capsys):
    with pytest.raises(SystemExit):
        main(["plan", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert "grasps at most (default: 4)" in text and "(default: explore)" in text and "(default: barrett_bh8)" in text


@pytest.mark.parametrize("argv", [["grasp", "--object", "mug", "--top", "0,0,0"],
                                  ["plan", "--object", "mug", "--true-pose", "0,0,0"],
                                  ["touch", "--object", "cube", "--true-pose", "0,0,0"]])
def test_an_unknown_hand_names_the_option(capsys, argv):
    with pytest.raises(SystemExit) as e:
        main(argv + ["--hand", "nosuch"])
    err = capsys.readouterr().err
    assert e.value.code == 2 and "argument --hand: unknown hand 'nosuch'" in err and "barrett_bh8" in err
    assert "name_or_path" not in err


@pytest.mark.parametrize("old, new, argv", [
    ("--pose", "--object-pose", ["register", "--scene-object", "cube", "--models", "cube"]),
    ("--pose", "--object-pose", ["category", "--category", "mug", "--task", "top"]),
    ("--pose", "--object-pose", ["fuse", "--scene-object", "mug/3"]),
])
def test_old_spellings_still_work_and_warn(capsys, old, new, argv):
    """The old spelling is parsed into the same setting as the new one, with one deprecation line."""
    parser = build_parser()
    a = parser.parse_args(argv + [old, "0.01,0.02,0.3"])
    err = capsys.readouterr().err
    assert f"{old} is deprecated" in err and f"use {new}" in err
    b = parser.parse_args(argv + [new, "0.01,0.02,0.3"])
    assert vars(a) == vars(b) and a.object_pose == "0.01,0.02,0.3"


def test_old_spelling_warns_once_naming_the_new_one(capsys):
    build_parser().parse_args(["fuse", "--scene-object", "mug/3", "--pose", "0,0,0"])
    err = capsys.readouterr().err.strip().splitlines()
    assert err == ["bayesgrasp fuse: warning: --pose is deprecated and will be removed in the next release; "
                   "use --object-pose"]
    build_parser().parse_args(["fuse", "--scene-object", "mug/3", "--object-pose", "0,0,0"])
    assert capsys.readouterr().err == ""


def test_grasp_hand_pose_old_spelling(capsys, tmp_path):
    import json

    f = tmp_path / "T.json"
    f.write_text(json.dumps([[1, 0, 0, 0], [0, -1, 0, 0], [0, 0, -1, 0.3], [0, 0, 0, 1]]))
    assert main(["grasp", "--object", "cube", "--pose", str(f), "--json"]) == 0
    out, err = capsys.readouterr()
    assert "--pose is deprecated" in err and "use --hand-pose" in err
    assert main(["grasp", "--object", "cube", "--hand-pose", str(f), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["joint_angles"] == json.loads(out)["joint_angles"]


@pytest.mark.parametrize("command, declared, help_of", [
    ("plan", "bayesgrasp.planners.registry:PLANNERS", "bayesgrasp.planners.registry:METHOD_HELP"),
    ("demo", "bayesgrasp.planners.registry:PLANNERS", "bayesgrasp.planners.registry:METHOD_HELP"),
    ("category", "bayesgrasp.planners.category:METHODS", "bayesgrasp.planners.category:METHOD_HELP")])
def test_method_choices_and_their_help_come_from_the_planners_declaration(command, declared, help_of):
    """Each planner family declares its methods and their help once; --method offers exactly those
    and its help is each method's declared line (a method added to the family reaches the parser)."""
    import importlib

    def attr(spec):
        module, name = spec.split(":")
        return getattr(importlib.import_module(module), name)

    methods, helps = list(attr(declared)), attr(help_of)
    assert list(helps) == methods                        # every method has its line, none more
    parser = next(p for n, p, _ in ALL if n == f"bayesgrasp {command}")
    option = next(a for a in parser._actions if "--method" in a.option_strings)
    assert list(option.choices) == methods
    for m in methods:
        assert f"{m}: {helps[m]}" in option.help


def test_episode_methods_and_their_help_come_from_the_planners_declarations():
    """`episode new --method` offers the registry's episode pose methods, the category planners'
    thesis methods and fusion, each with the line its family declares; the outside loop accepts
    exactly the registry's pose methods."""
    from bayesgrasp.loop import outside_loop
    from bayesgrasp.planners import category, fusion, registry

    assert set(registry.EPISODE_METHODS) <= set(registry.PLANNERS)
    assert outside_loop.METHODS == registry.EPISODE_METHODS
    declared = {**{m: registry.METHOD_HELP[m] for m in registry.EPISODE_METHODS},
                **{m: category.METHOD_HELP[m] for m in category.THESIS_METHODS}, **fusion.METHOD_HELP}
    parser = next(p for n, p, _ in ALL if n == "bayesgrasp episode new")
    option = next(a for a in parser._actions if "--method" in a.option_strings)
    assert list(option.choices) == list(declared)
    for m, line in declared.items():
        assert f"{m}: {line}" in option.help
    assert "part-aware" not in option.choices    # a category method the episode refuses is not offered
