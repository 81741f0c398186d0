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
