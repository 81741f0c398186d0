"""The README's examples, read as `make readme` reads them (tests/readme): every command parses
with the CLI's own parser, no two experiment lines write one directory with different settings,
every file they name is shipped, the runner's checks catch what they claim to, and the first
examples (seconds each) run as written on a clean copy. `make readme` runs them all (hours on a
cold model cache)."""
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "tests" / "readme"))

import readme_examples as rx  # noqa: E402
import run_readme  # noqa: E402
from bayesgrasp.cli import build_parser  # noqa: E402
from bayesgrasp.cli.args import join_negative_values  # noqa: E402

EXAMPLES = rx.parse()
COMMANDS = [(e, rx.bayesgrasp_argv(e)) for e in EXAMPLES if rx.bayesgrasp_argv(e) is not None]


def test_the_readme_has_its_examples_in_order():
    kinds = [e.kind for e in EXAMPLES]
    assert kinds.count("python") >= 3 and kinds.count("sh") >= 50
    assert [e.line for e in EXAMPLES] == sorted(e.line for e in EXAMPLES)
    # the two set-up commands first: make demo runs (as its job), make test does not
    assert [e.text for e in EXAMPLES[:2]] == ["make demo", "make test"]
    assert rx.not_run(EXAMPLES[0]) is None and rx.not_run(EXAMPLES[1])
    skipped = [e for e in EXAMPLES if rx.not_run(e)]
    assert all(e.argv[:1] == ["make"] or rx.bayesgrasp_argv(e)[:1] == ["view"] for e in skipped)
    assert len(skipped) <= 3


@pytest.mark.parametrize("e,argv", COMMANDS, ids=[f"README:{e.line}" for e, _ in COMMANDS])
def test_every_command_parses(e, argv):
    parser = build_parser()
    try:
        args = parser.parse_args(join_negative_values(list(argv)))
    except SystemExit:
        pytest.fail(f"{e.label()}: refused by the CLI's parser")
    assert args.command == argv[0]


def _experiment_settings(argv):
    """(out, the options that change results): what may share a directory."""
    skip = {"--workers", "--engine", "--runs", "--out"}
    opts, k = [], 2
    while k < len(argv):
        a = argv[k]
        if a.startswith("--") and k + 1 < len(argv) and not argv[k + 1].startswith("--"):
            if a not in skip:
                opts.append((a, argv[k + 1]))
            k += 2
        else:
            opts.append((a, None))
            k += 1
    out = rx.experiment_out(argv)
    config = dict(opts).get("--config")
    if config:
        cfg = tomllib.loads((ROOT / config).read_text())
        out = cfg.get("out", out)
    return out, (argv[1], tuple(sorted(opts)))


def test_experiment_lines_write_their_own_directories():
    seen = {}
    for e, argv in COMMANDS:
        if argv[:1] != ["experiment"] or argv[1] == "list" or "HEAD:6379" in e.text:
            continue
        out, settings = _experiment_settings(argv)
        if out in seen:
            assert seen[out] == settings, f"{e.label()} resumes into {out} with other settings than " \
                                          f"README:{seen[out]}"
        seen[out] = settings
    assert len(seen) >= 10


def test_every_file_an_example_reads_is_shipped():
    named = [a for _, argv in COMMANDS for a in argv if a.startswith(("examples/", "tests/data/"))]
    named += [a for e in EXAMPLES if e.kind == "sh" for a in e.argv if a.startswith("examples/")]
    assert "examples/pub2.toml" in named
    for f in named:
        assert (ROOT / f).is_file(), f


def test_the_runner_checks_what_the_text_claims(tmp_path):
    side = next(e for e in EXAMPLES if "side grasp, lifted" in e.comment)
    assert "lifted" in side.claims and "file:out/side.png" in side.claims
    done = subprocess.CompletedProcess([], 0, stdout="  lift test: dropped (moved 9 cm)\n", stderr="")
    problems = run_readme.check(side, tmp_path, done, 1.0)
    assert any("lifted" in p for p in problems) and any("out/side.png" in p for p in problems)
    cluster = next(e for e in EXAMPLES if rx.expects_refusal(e))
    hung = subprocess.CompletedProcess([], 0, stdout="", stderr="")
    assert run_readme.check(cluster, tmp_path, hung, 300.0)
    refused = subprocess.CompletedProcess([], 2, stdout="", stderr="error: --address: no Ray head at HEAD:6379\n")
    assert run_readme.check(cluster, tmp_path, refused, 3.0) == []
    episode = next(e for e in EXAMPLES if e.printed is not None)
    other = subprocess.CompletedProcess([], 0, stdout="something else\n", stderr="")
    assert run_readme.check(episode, tmp_path, other, 1.0)
    exp = next(e for e in EXAMPLES if any(c.startswith("experiment:") for c in e.claims))
    assert run_readme.check(exp, tmp_path, subprocess.CompletedProcess([], 0, "", ""), 1.0)
    assert "--runs 2" in run_readme.command(exp, 2) and run_readme.command(
        next(e for e in EXAMPLES if "--runs 30" in e.text), 2).count("--runs") == 1


def test_the_first_examples_run_as_written(tmp_path):
    """The Examples section's first block (objects, grasps, a registration: seconds each) through
    the runner, on a clean copy."""
    report = tmp_path / "report.json"
    p = subprocess.run([sys.executable, str(ROOT / "tests" / "readme" / "run_readme.py"), "--only", "Examples",
                        "--from", str(EXAMPLES[2].line), "--until", str(EXAMPLES[6].line), "--report", str(report),
                        "--keep", str(tmp_path / "clone")], capture_output=True, text=True, timeout=900)
    assert p.returncode == 0, p.stderr[-3000:]
    assert "5 of 5 examples ran as their text says" in p.stderr
    assert (tmp_path / "clone" / "out" / "side.png").is_file() and (tmp_path / "clone" / "out" / "reg.png").is_file()
