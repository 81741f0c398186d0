"""``bayesgrasp touch``: JSON output, the landscape PNG, and user errors."""
import json

import numpy as np
import pytest

from bayesgrasp.cli import main
from bayesgrasp.io.grasp_schema import validate


def _json(capsys, *args):
    code = main(["touch", *args, "--json"])
    out, err = capsys.readouterr()
    assert code == 0, err
    return json.loads(out)


def test_touch_json_on_the_cube(capsys):
    d = _json(capsys, "--object", "cube", "--true-pose", "0.01,-0.01,0.3", "--estimate", "-0.01,0.005,0.45",
              "--budget", "400")
    assert d["status"] == "estimated" and d["evaluations"] == 400
    assert d["top_grasp"]["x"] == -0.01 and d["readings"]["contact_links"]
    validate(d["grasp"])                                        # the one grasp schema
    assert d["grasp"]["pose"] == d["readings"]["hand_pose"] and d["grasp"]["joint_positions"] == d["readings"]["joint_angles"]
    assert d["fitness"] <= d["initial_fitness"]
    assert d["errors_after"]["orientation_error"] is not None   # the cube: modulo 90 degrees
    assert d["trace"]["evaluations"][-1] == 400
    assert np.all(np.diff(d["trace"]["best_fitness"]) <= 0)


def test_touch_size_png_and_revolution(capsys, tmp_path):
    png = tmp_path / "landscape.png"
    d = _json(capsys, "--object", "cylinder", "--true-pose", "0,0,0.3", "--true-scale", "1.1", "--estimate",
              "0.01,0.01,0", "--size", "--budget", "200", "--optimizer", "firefly", "--png", str(png))
    assert png.exists() and png.stat().st_size > 0
    assert d["case"] == "pose_and_scale" and d["errors_after"]["orientation_error"] is None
    assert d["errors_after"]["size_error"] < d["errors_before"]["size_error"]


def test_touch_without_contact_and_negative_numbers(capsys):
    code = main(["touch", "--object", "cube", "--true-pose", "-0.3,-0.3,0", "--estimate", "0.3,0.3,0"])
    out, _ = capsys.readouterr()
    assert code == 0 and "nothing learnt" in out


@pytest.mark.parametrize("args, message", [
    (["--budget", "5"], "budget"),
    (["--size", "--orientation-only"], "choose one"),
    (["--true-scale", "-1"], "true-scale"),
])
def test_touch_user_errors(capsys, args, message):
    code = main(["touch", "--object", "cube", "--true-pose", "0,0,0", "--estimate", "0,0,0", *args])
    assert code == 2 and message in capsys.readouterr().err
