"""A dexterous hand from a URDF (issue 55): allegro_like.urdf, one motor per joint (no mimic), the
fingers' abduction joints held straight and the thumb's opposition joint held at 0.44 rad, so
the thumb's flexion axes leave the palm plane (closing 'independent', held_joints). The
kinematics are checked against the URDF's own chain (test_hand_urdf.py's parametrized tests
take it too); here: what the conversion makes of it, grasps that lift, the lift test pressing
with every joint's own motor, and the refusals."""
import json
import math

import numpy as np
import pytest

from bayesgrasp.hand import HANDS_DIR, Hand
from bayesgrasp.hand_urdf import HandFileError
from testkit import cli_json

HAND = "allegro_like.urdf"
SIDE = "allegro_like.hand.json"


@pytest.fixture(scope="module")
def hand():
    return Hand.load(HAND)


def test_the_thumb_opposes_out_of_the_palm_plane(hand):
    """Four fingers of three flexion joints each (13 joints with the spread), every one measured;
    the thumb's flexion axis is the URDF's (0, -1, 0) turned by its held opposition joint (0.44 rad
    about its outward axis -x): (0, cos 0.44, -sin 0.44) up to sign, i.e. 25.2 deg out of the palm
    plane, the fingers' in it."""
    assert hand.core.closing == "independent"
    assert hand.num_fingers == 4 and hand.num_joints == 13 and len(hand.measured_joints) == 12
    poses = hand.link_poses(hand.open_joints())
    for f, links in enumerate(hand.phalanx_links):
        axis = poses[links[0]][:3, 1]
        tilt = math.degrees(math.asin(abs(axis[2])))
        assert tilt == pytest.approx(25.21 if f == 3 else 0.0, abs=0.01), (f, axis)
    a = poses[hand.phalanx_links[3][0]][:3, 1]
    assert abs(a @ np.array([0.0, math.cos(0.44), -math.sin(0.44)])) == pytest.approx(1.0, abs=1e-9)
    np.testing.assert_allclose(hand.joint_torques[1:], 0.7)
    names, values = hand.urdf_joints(hand.open_joints())
    held = dict(zip(names, values))
    assert held["ah_thumb_j0"] == pytest.approx(0.44) and held["ah_index_j0"] == 0.0   # held joints reported


def test_it_lifts_the_cube_and_the_mug_through_the_cli(capsys):
    for obj, top in (("cube", "0,0,1.5708"), ("mug", "0,0,0")):
        doc = cli_json(capsys, "grasp", "--object", obj, "--top", top, "--hand", HAND, "--json")
        assert doc["lifted"] is True, obj
        touching = {c["link_name"].split("/")[0] for c in doc["contacts"] if not c.get("on_table")}
        assert "thumb" in touching and len(touching) >= 2, touching    # the thumb opposes a finger


def test_every_joint_presses_with_its_own_motor(hand):
    """The same closed cube grasp: held at the hand's 0.7 N m per joint, dropped when every joint's
    motor is cut to 0.005 N m (the lift test's override)."""
    from bayesgrasp import physics
    from bayesgrasp.world import World

    w = World.single("cube", hand=hand)
    g = w.grasp(0.0, 0.0, math.pi / 2)
    def lift(torque):   # 0: the hand's own torques
        return physics.LiftTester(hand.core, w.vertices, w.faces, mu=w.mu, density=w.object.density,
                                  finger_torque=torque).run(g.hand_pose, g.joint_angles)
    strong, weak = lift(0.0), lift(0.005)
    assert strong.lifted and not weak.lifted


def _copy(tmp_path, side_edit=None, urdf_edit=None):
    tmp_path.mkdir()
    text = (HANDS_DIR / HAND).read_text()
    (tmp_path / HAND).write_text(urdf_edit(text) if urdf_edit else text)
    side = json.loads((HANDS_DIR / SIDE).read_text())
    (tmp_path / SIDE).write_text(json.dumps(side_edit(side) if side_edit else side))
    return tmp_path / HAND


def test_refusals_name_the_joint_and_what_was_expected(tmp_path):
    def unheld(s):
        s["held_joints"].pop("ah_index_j0")
        return s
    with pytest.raises(HandFileError, match=r"ah_index_j0.*moves the finger's base but the sidecar's spread is null"):
        Hand.load(_copy(tmp_path / "a", unheld))
    with pytest.raises(HandFileError, match=r"held_joints: joint 'ah_thumb_j0' held at 2, outside its limits \[0, 1\.4\]"):
        Hand.load(_copy(tmp_path / "b", lambda s: s | {"held_joints": s["held_joints"] | {"ah_thumb_j0": 2.0}}))
    mimic = '<limit lower="-0.17" upper="1.7" effort="0.7" velocity="3"/>\n  </joint>'
    with pytest.raises(HandFileError, match=r"fingers\[0\]\.phalanges\[1\]: joint 'ah_index_j2' mimics 'ah_index_j1'; "
                                            r"with closing 'independent' every phalanx has its own motor"):
        Hand.load(_copy(tmp_path / "c", urdf_edit=lambda u: u.replace(
            mimic, mimic.replace("\n  </joint>", '<mimic joint="ah_index_j1"/>\n  </joint>'), 1)))

    def ratio_in_breakaway(s):
        s["closing"] = "breakaway"
        s["fingers"][0]["phalanges"][0]["ratio"] = 2.0
        return s
    with pytest.raises(HandFileError, match=r"fingers\[0\]\.phalanges\[0\]: a ratio is given only with closing 'independent'"):
        Hand.load(_copy(tmp_path / "d", ratio_in_breakaway))
    doc = json.loads(Hand.load(HAND).text)
    doc["fingers"][3]["roll_deg"] = 95.0
    with pytest.raises(ValueError, match=r"fingers\[3\]: roll_deg must lie in \(-90, 90\)"):
        Hand.from_json(json.dumps(doc))
    doc["fingers"][3]["roll_deg"] = 25.0
    doc["fingers"][3]["phalanges"][1]["ratio"] = 0.0
    with pytest.raises(ValueError, match=r"ratio must be > 0 with closing 'independent'"):
        Hand.from_json(json.dumps(doc))
