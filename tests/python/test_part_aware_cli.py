"""The part-aware plan and task term through the CLI (issue 29), with test_viewer_results' small
models and two training mugs."""
import pytest
from testkit import cli_json, without_set   # the fixture cat_options: conftest.py


def test_the_cli_plans_part_aware_and_fuses_with_the_part_aware_term(capsys, cat_options):
    """`category --method part-aware` and `fuse --task-term part-aware` end to end (small models,
    two training mugs): the check's figures are in the output, and the executed grasp's verdict."""
    doc = cli_json(capsys, "category", "--category", "mug", "--task", "top", "--scene-object", "mug/3",
                   "--object-pose", "0.01,0.02,0.7", "--method", "part-aware", *without_set(cat_options), "--json")
    pc = doc["part_check"]
    assert doc["method"] == "part-aware" and 0.0 <= pc["p_success"] <= pc["p_rule"] <= 1.0 + 1e-12
    assert pc["candidates"] == 64 and set(pc["contact_parts_on_models"]) <= {"mug/1", "mug/2"}
    assert doc["success"] == (doc["lifted"] and doc["task_ok"])
    fuse = cli_json(capsys, "fuse", "--category", "mug", "--task", "top", "--scene-object", "mug/3",
                    "--object-pose", "0.01,0.02,0.7", "--rounds", 1, "--task-term", "part-aware", *cat_options, "--json")
    assert fuse["task_term"] == "part-aware" and all(0.0 <= r["part"] <= 1.0 for r in fuse["rounds"][1:])


def test_the_text_output_says_what_the_part_check_found(capsys, cat_options):
    from bayesgrasp.cli import main

    assert main(["category", "--category", "mug", "--task", "top", "--scene-object", "mug/3", "--object-pose",
                 "0.01,0.02,0.7", "--method", "part-aware", *without_set(cat_options)]) == 0
    line = next(x for x in capsys.readouterr().out.splitlines() if "part check:" in x)
    assert "of 64 candidates obeyed the rule on some model" in line


def test_the_cli_plans_warped_and_fuses_on_the_warped_models_avoiding_failures(capsys, cat_options):
    """`category --method warped` reports each warp's weight and residual and the lift test's
    decision; `fuse --task-term warped --avoid-failed` runs its rounds with the part check on the
    warped shapes."""
    from bayesgrasp.cli import main

    doc = cli_json(capsys, "category", "--category", "mug", "--task", "top", "--scene-object", "mug/3",
                   "--object-pose", "0.01,0.02,0.7", "--method", "warped", *without_set(cat_options), "--json")
    pc = doc["part_check"]
    assert doc["method"] == "warped" and set(pc["warps"]) <= {"mug/1", "mug/2"} and pc["warps"]
    assert sum(w["weight"] for w in pc["warps"].values()) == pytest.approx(1.0)
    assert all(0.0 < w["residual"] < 0.02 for w in pc["warps"].values())
    assert 0 <= pc["lift_checked"] <= 4 and 0.0 <= pc["p_lifted"] <= pc["p_success"] + 1e-12
    fuse = cli_json(capsys, "fuse", "--category", "mug", "--task", "top", "--scene-object", "mug/3",
                    "--object-pose", "0.01,0.02,0.7", "--rounds", 1, "--task-term", "warped", "--avoid-failed",
                    *cat_options, "--json")
    assert fuse["task_term"] == "warped" and fuse["avoid_failed"] is True
    assert all(0.0 <= r["part"] <= 1.0 for r in fuse["rounds"][1:])
    assert main(["category", "--category", "mug", "--task", "top", "--scene-object", "mug/3", "--object-pose",
                 "0.01,0.02,0.7", "--method", "warped", *without_set(cat_options)]) == 0
    assert "warped onto the view: mug/" in capsys.readouterr().out
