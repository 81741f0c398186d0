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
    assert d["optimizer"] == "pso" and d["contact_term"] == "flags"   # not given: the core's defaults, named
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


def test_touch_defaults_have_one_home_the_core():
    """TouchSettings' defaults, estimate_options() with nothing given and the touch help's budget
    are the core's EstimateOptions."""
    from bayesgrasp.cli import build_parser
    from bayesgrasp.planners import touch as T

    core, s = T.EstimateOptions(), T.TouchSettings()
    assert (T.OPTIMIZERS[s.optimizer], T.UNKNOWNS[s.unknowns], T.CONTACT_TERMS[s.contact_term]) == \
        (core.optimizer, core.unknowns, core.fitness.contact_term)
    assert (s.budget, s.seed, s.threads, s.stop_fitness) == (core.budget, core.seed, core.threads, core.stop_fitness)
    assert tuple(s.box) == (core.box.xy, core.box.yaw, core.box.scale_low, core.box.scale_high)
    given_none = T.estimate_options()
    for name in ("optimizer", "unknowns", "budget", "seed", "threads", "stop_fitness", "population"):
        assert getattr(given_none, name) == getattr(core, name), name
    assert given_none.fitness.contact_term == core.fitness.contact_term and given_none.box.xy == core.box.xy
    assert f"default {core.budget:,}" in " ".join(build_parser()._subparsers._group_actions[0].choices["touch"]
                                                   .format_help().split())
