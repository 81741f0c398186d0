import json
import subprocess
import sys

import numpy as np
import pytest

from bayesgrasp.cli import main
from bayesgrasp.world import World


def run_cli(*args):
    p = subprocess.run([sys.executable, "-m", "bayesgrasp.cli", *args], capture_output=True, text=True)
    return p.returncode, p.stdout, p.stderr


def test_grasp_json_on_cube_has_the_documented_keys_and_contacts_on_the_surface():
    code, out, err = run_cli("grasp", "--object", "cube", "--top", "0,0,0", "--json")
    assert code == 0, err
    d = json.loads(out)
    for key in ("joint_angles", "contacts", "epsilon", "volume", "lifted", "collision_at_start"):
        assert key in d
    assert len(d["joint_angles"]) == 7 and d["collision_at_start"] is False
    obj = [c for c in d["contacts"] if not c["on_table"]]
    assert obj, "the fingers should touch the cube"
    half = World.single("cube").object.extent / 2
    for c in obj:   # every object contact lies on one of the cube's faces (object at the origin)
        p = np.array(c["point"])
        assert np.all(np.abs(p[:2]) <= half[:2] + 3e-4) and -3e-4 <= p[2] <= 2 * half[2] + 3e-4
        on_face = np.isclose(np.abs(p[:2]), half[:2], atol=3e-4).any() or np.isclose(p[2], 2 * half[2], atol=3e-4)
        assert on_face
    assert isinstance(d["lifted"], bool)


def test_grasp_relative_to_the_object_pose_is_invariant():
    a = World.single("cylinder", pose=(0.0, 0.0, 0.0)).grasp(0.01, 0.0, 0.2)
    b = World.single("cylinder", pose=(0.1, -0.05, 0.7)).grasp(0.01, 0.0, 0.2)
    np.testing.assert_allclose(a["joint_angles"], b["joint_angles"], atol=1e-3)
    assert len(a["contacts"]) == len(b["contacts"])
    # (epsilon is not compared: a link lying across the cylinder's rim touches it along a
    # segment, and which point of it is reported as the one contact depends on round-off)


@pytest.mark.parametrize("args, needle", [
    (["grasp", "--object", "no_such_thing", "--top", "0,0,0"], "neither a built-in"),
    (["grasp", "--object", "cube", "--top", "0,0"], "--top"),
    (["grasp", "--object", "cube", "--top", "0,0,nan"], "finite"),
    (["grasp", "--object", "cube", "--top", "0,0,0", "--object-pose", "5,0,0"], "table"),
    (["demo", "--out", "/proc/forbidden/dir"], "--out"),
])
def test_bad_input_gives_a_message_and_exit_status_2(args, needle, capsys):
    assert main(args) == 2
    err = capsys.readouterr().err
    assert needle in err and "Traceback" not in err
