"""A four-bar linkage gripper from a URDF (issue 55): the 2F-85-like robotiq_2f85.urdf, whose pad
joint mimics its driver with multiplier -1 (the pad stays parallel) and whose inner knuckle is a
passive bar. Oracles from the linkage's geometry: the outer bar (56.6 mm, 0.9 rad above the palm
plane when open) turns by the driver's angle t about its pivot 30.6 mm off the centre, and the pad,
hanging from its end, keeps its angle; its inner face is 23.3 mm inboard of the pad joint."""
import json
import math
import shutil

import numpy as np
import pytest

from bayesgrasp.hand import HANDS_DIR, Hand
from bayesgrasp.hand_urdf import HandFileError
from testkit import cli_json, urdf_fk

GRIPPER = "robotiq_2f85.urdf"
PIVOT, BAR, OPEN = 0.0306, 0.0566, 0.9     # m, m, rad (the URDF's figures)
FACE, TIP = 0.0233, 0.04                  # the pad face inboard of the pad joint, the tip above it (m)


@pytest.fixture(scope="module")
def gripper():
    return Hand.load(GRIPPER)


def test_the_pads_stay_parallel_and_follow_the_four_bar(gripper):
    """Over the driver's whole range, each fingertip is where the four-bar puts it: x = pivot +
    bar cos(0.9 + t) - face, z = bar sin(0.9 + t) + tip, and the pad's angle never changes."""
    assert gripper.core.closing == "linkage"
    assert gripper.num_joints == 5 and list(gripper.measured_joints) == [1, 3]
    ref = None
    for t in np.linspace(0.0, 0.8, 9):
        q = gripper.coupled_joints(0.0, t)
        tips = gripper.fingertips(q)
        x = PIVOT + BAR * math.cos(OPEN + t) - FACE
        z = BAR * math.sin(OPEN + t) + TIP
        np.testing.assert_allclose(tips, [[x, 0.0, z], [-x, 0.0, z]], atol=1e-6)   # the URDF gives 6 digits
        pads = [gripper.link_poses(q)[gripper.phalanx_links[f][1]][:3, :3] for f in (0, 1)]
        ref = pads if ref is None else ref
        for R, R0 in zip(pads, ref):
            np.testing.assert_allclose(R, R0, atol=1e-9)   # parallel: the pad's orientation is fixed
    # open, the pads are 85 mm apart; closed, they meet
    assert abs(2 * (PIVOT + BAR * math.cos(OPEN) - FACE) - 0.085) < 2e-4
    assert abs(PIVOT + BAR * math.cos(OPEN + 0.8) - FACE) < 2e-4


@pytest.mark.parametrize("width", [0.03, 0.05, 0.07])
def test_the_pads_close_parallel_on_a_box(gripper, width):
    """A box of width w under the open gripper: each finger stops as a whole when its pad reaches
    the face (the driver's t where pivot + bar cos(0.9 + t) - face = w / 2), the pad still at its
    open angle, and both pads touch the box."""
    from bayesgrasp.sim import GraspSimulator
    import trimesh

    post = trimesh.creation.box(extents=[width, 0.04, 0.2])
    post.apply_translation([0, 0, 0.1])
    sim = GraspSimulator(gripper, post.vertices, post.faces, table=False)
    # palm 6 cm above the box top: the open pads (3.9-8.4 cm below the palm) overlap its sides
    H = gripper.top_grasp_pose(0.0, 0.0, 0.0, 0.2 + 0.06)
    g = sim.close(H, 0.0)
    q = np.asarray(g.joint_angles)
    t = math.acos((0.5 * width + FACE - PIVOT) / BAR) - OPEN
    slack = sim.options.contact_tolerance / (BAR * math.sin(OPEN + t))   # the tolerance in driver angle
    open_q = gripper.open_joints()
    for f in (0, 1):
        k = 1 + 2 * f
        assert t - slack - 1e-6 <= q[k] - open_q[k] <= t + 1e-6, (f, q, t)
        assert q[k] + q[k + 1] == pytest.approx(open_q[k] + open_q[k + 1], abs=1e-9)   # pad parallel
    links = set(np.asarray(g.contacts.link)[~np.asarray(g.contacts.on_table, bool)].tolist())
    assert {gripper.phalanx_links[0][1], gripper.phalanx_links[1][1]} <= links


def test_grasps_lift_through_the_cli_and_report_the_urdf_s_joints(capsys):
    """grasp with the gripper on the cube (top), the mug (top, across its 8 cm body: the 85 mm stroke
    just spans it) and the cylinder from the side: each
    lifted; the URDF block names all six moving joints, the passive inner knuckles reading the
    driver's value and the pads minus it."""
    for args in (["--object", "cube", "--top", "0,0,0"], ["--object", "mug", "--top", "0,0,1.5708"],   # across the body
                 ["--object", "cylinder", "--approach", "-1,0,0", "--roll", "1.5708"]):
        doc = cli_json(capsys, "grasp", *args, "--hand", GRIPPER, "--json")
        assert doc["lifted"] is True, args
        u = dict(zip(doc["grasp"]["urdf"]["joint_names"], doc["grasp"]["urdf"]["joint_positions"]))
        assert set(u) == {"r2f_finger_joint", "r2f_left_inner_finger_joint", "r2f_left_inner_knuckle_joint",
                          "r2f_right_outer_knuckle_joint", "r2f_right_inner_finger_joint",
                          "r2f_right_inner_knuckle_joint"}
        for side, driver in (("left", "r2f_finger_joint"), ("right", "r2f_right_outer_knuckle_joint")):
            assert 0.0 <= u[driver] <= 0.8 and (u[driver] > 0.1 or "mug" in args)   # the mug: touching when open
            assert u[f"r2f_{side}_inner_knuckle_joint"] == pytest.approx(u[driver], abs=1e-9)
            assert u[f"r2f_{side}_inner_finger_joint"] == pytest.approx(-u[driver], abs=1e-9)


def test_the_urdf_values_out_close_the_four_bar(gripper):
    """The URDF values we report for a closed grasp, put into the URDF's own chain (independent of
    our conversion): the passive inner knuckle's far end (one bar length along it) lands on the
    pad where the parallelogram attaches it (14 mm inboard of the pad joint), and the pads point
    as they do open."""
    from bayesgrasp.world import World

    q = World.single("cube", hand=gripper).grasp(0.0, 0.0, 0.0).joint_angles
    urdf = str(HANDS_DIR / GRIPPER)
    frames = []
    for qq in (gripper.open_joints(), q):
        names, values = gripper.urdf_joints(qq)
        L = urdf_fk(urdf, dict(zip(names, values)))
        frames.append(L)
        bar_end = L["r2f_left_inner_knuckle"] @ np.array([BAR * math.cos(OPEN), 0, BAR * math.sin(OPEN), 1])
        on_pad = L["r2f_left_inner_finger"] @ np.array([-0.014, 0, 0, 1])
        np.testing.assert_allclose(bar_end, on_pad, atol=1e-6)
    assert q[1] > gripper.open_joints()[1] + 0.05                       # it did close
    for side in ("left", "right"):
        np.testing.assert_allclose(frames[1][f"r2f_{side}_inner_finger"][:3, :3],
                                   frames[0][f"r2f_{side}_inner_finger"][:3, :3], atol=1e-9)


def _copy(tmp_path, edit=lambda side: side):
    shutil.copy(HANDS_DIR / GRIPPER, tmp_path / GRIPPER)
    side = json.loads((HANDS_DIR / "robotiq_2f85.hand.json").read_text())
    (tmp_path / "robotiq_2f85.hand.json").write_text(json.dumps(edit(side)))
    return tmp_path / GRIPPER


def test_refusals_name_what_the_linkage_needs(tmp_path):
    """A negative mimic under closing 'breakaway', a passive joint that no driver moves, and a
    moving bar the sidecar leaves out are refused, each naming the joint and what was expected;
    a hand file with a negative ratio and no linkage is refused by the core."""
    def breakaway(s):
        return s | {"closing": "breakaway"}
    for d in "abc":
        (tmp_path / d).mkdir()
    with pytest.raises(HandFileError, match=r"r2f_left_inner_finger_joint.*multiplier -1.*\"closing\": \"linkage\""):
        Hand.load(_copy(tmp_path / "a", breakaway))
    pad_too = ["r2f_left_inner_knuckle_joint", "r2f_right_inner_knuckle_joint", "r2f_left_inner_finger_joint"]
    with pytest.raises(HandFileError, match=r"passive_joints\[2\]: joint 'r2f_left_inner_finger_joint' closes "
                                            r"left/pad"):
        Hand.load(_copy(tmp_path / "b", lambda s: s | {"passive_joints": pad_too}))
    with pytest.raises(HandFileError, match=r"joint 'r2f_left_inner_knuckle_joint' moves link 'r2f_left_inner_knuckle'"):
        Hand.load(_copy(tmp_path / "c", lambda s: {k: v for k, v in s.items() if k != "passive_joints"}))
    (tmp_path / "d").mkdir()

    def knuckle(s):
        s["fingers"][0]["phalanges"][0]["name"] = "knuckle"
        return s
    with pytest.raises(HandFileError, match=r"fingers\[0\]\.phalanges\[0\]: name 'knuckle' is the finger's knuckle link"):
        Hand.load(_copy(tmp_path / "d", knuckle))
    doc = json.loads(Hand.load(GRIPPER).text)
    twice = json.loads(json.dumps(doc))
    twice["fingers"][0]["phalanges"][1]["name"] = "outer"
    with pytest.raises(ValueError, match=r"fingers\[0\]\.phalanges\[1\]: its link name 'left/outer' is taken"):
        Hand.from_json(json.dumps(twice))
    doc.pop("closing")
    with pytest.raises(ValueError, match=r"fingers\[0\]\.phalanges\[1\]: ratio must be >= 0 with closing 'breakaway'"):
        Hand.from_json(json.dumps(doc))
    doc["closing"] = "sideways"
    with pytest.raises(ValueError, match=r"closing: must be 'breakaway', 'linkage' or 'independent'"):
        Hand.from_json(json.dumps(doc))
