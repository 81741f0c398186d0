"""The README's episode transcript runs as written: its commands, in order, in a fresh directory.
`episode new` gets small models in a temporary cache (the README's default models take minutes to
build on a cold cache); the readings and verdicts are the README's, so the story's shape (a miss,
then a lift: success after 2 grasps) does not depend on the models."""
import re
import shlex
from pathlib import Path

from bayesgrasp.cli import main

README = Path(__file__).resolve().parents[2] / "README.md"
SMALL = ["--set", "models.n_samples=300", "--set", "models.n_inducing=50", "--set", "models.max_iter=30",
         "--set", "models.n_lift_samples=150", "--set", "models.n_calibration=100", "--set", "models.n_pilot=40",
         "--set", "models.n_pilot_lifts=10"]


def transcript():
    """(command argv, printed lines) of each `$ .venv/bin/bayesgrasp episode ...` in the README."""
    text = README.read_text()
    start = text.index("$ .venv/bin/bayesgrasp episode new")
    block = text[start:text.index("```", start)]
    steps = []
    for chunk in re.split(r"^\$ ", block, flags=re.M):
        if chunk.strip():
            cmd, *out = chunk.rstrip("\n").split("\n")
            argv = shlex.split(cmd)
            assert argv[0] == ".venv/bin/bayesgrasp"
            steps.append((argv[1:], out))
    return steps


def test_readme_episode_transcript_runs(tmp_path, monkeypatch, capsys):
    steps = transcript()
    assert [a[:2] for a, _ in steps] == [["episode", "new"]] + [["episode", "observe"]] * (len(steps) - 2) + \
        [["episode", "show"]]
    monkeypatch.chdir(tmp_path)
    for argv, printed in steps:
        extra = SMALL + ["--cache", str(tmp_path / "cache")] if argv[1] == "new" else []
        assert main(argv + extra) == 0, capsys.readouterr().err
        out = capsys.readouterr().out.splitlines()
        assert len(out) == len(printed)
        assert out[0].split(":")[0] == printed[0].split(":")[0]    # "attempt N (kind)" / "episode ep1" lines
    assert out[0] == printed[0]                                    # "episode ep1: cylinder, stability, success"
    assert [l.split(":")[0] for l in out[1:-1]] == [l.split(":")[0] for l in printed[1:-1]]
