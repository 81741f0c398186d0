"""The README's side-grasp examples (CLI and Python) do what their text says: the hand starts
clear of the table and the object, and the cylinder / mug comes up in the lift test. Both are
read from README.md, so the test breaks when the README changes them."""
import json
import re
import shlex
from pathlib import Path

import numpy as np

from bayesgrasp.cli import main
from bayesgrasp.world import World

README = (Path(__file__).resolve().parents[2] / "README.md").read_text()


def test_cli_side_grasp_lifts(capsys, tmp_path, monkeypatch):
    line = next(l for l in README.splitlines() if "--approach 1,0,0" in l and "bayesgrasp grasp" in l)
    argv = shlex.split(line.split("#")[0])[1:]
    monkeypatch.chdir(tmp_path)
    assert main(argv + ["--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["lifted"] is True and d["collision_at_start"] is False and not d["stopped_by_table"]
    assert (tmp_path / "out" / "side.png").stat().st_size > 1000


def test_python_side_grasp_lifts():
    m = re.search(r"^(world = World\.single\(.*\))$.*?^(side = world\.approach\(.*\))", README, re.M | re.S)
    scope = {"World": World, "np": np}
    exec(m.group(1), scope)
    exec(m.group(2).split("#")[0], scope)
    side = scope["side"]
    assert side.lifted is True and not side.collision_at_start and len(side.contacts) >= 2
