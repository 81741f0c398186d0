"""Hand models from data files: structure and kinematics against the published BH8 lengths."""
import json

import numpy as np
import pytest

from bayesgrasp.hand import HANDS_DIR, Hand, builtin_hands

DEG = np.pi / 180


def test_builtin_hands_listed_and_loaded():
    assert {"barrett_bh8", "robotiq_3f"} <= set(builtin_hands())
    h = Hand.load()
    assert h.num_joints == 7 and h.num_links == 9 and h.num_fingers == 3
    assert h.joint_names[0] == "spread"
    assert h.links[0] == "palm"
    np.testing.assert_allclose(h.spread_limits, (0.0, np.pi))
    # by path too
    assert Hand.load(HANDS_DIR / "barrett_bh8.json").num_joints == 7


def test_barrett_fingertips_from_published_lengths():
    h = Hand.load("barrett_bh8")
    q = h.open_joints(spread=0.0)
    np.testing.assert_allclose(q[[1, 2]], [0.0, 42 * DEG])
    tips = h.fingertips(q)
    # finger 3: joint 50 mm along -y, proximal 70 mm flat, distal 55 mm at 42 deg towards +z
    np.testing.assert_allclose(tips[2], [0.0, -(0.05 + 0.07 + 0.055 * np.cos(42 * DEG)), 0.055 * np.sin(42 * DEG)],
                               atol=1e-12)
    # spread 90, proximal 90: fingers 1 and 2 point along the approach axis, distal at 30 + 42
    q = h.coupled_joints(np.pi / 2, np.pi / 2)
    np.testing.assert_allclose(q[2], 72 * DEG)
    tips = h.fingertips(q)
    a = (90 + 72) * DEG
    np.testing.assert_allclose(tips[0], [0.075 + 0.055 * np.cos(a), 0.0, 0.07 + 0.055 * np.sin(a)], atol=1e-12)
    np.testing.assert_allclose(tips[1][0], -tips[0][0], atol=1e-12)


def test_link_geometry_in_world_frame():
    h = Hand.load()
    T = Hand.top_grasp_pose(0.1, 0.2, 0.0, 0.3)  # palm down, palm face at z = 0.3
    q = h.open_joints(0.0)
    parts = h.link_geometry(q, T)
    names = {p.name for p in parts}
    assert "finger3/distal" in names and "palm" in names
    palm = next(p for p in parts if p.name == "palm")
    # palm box centre 30 mm behind the palm face: above it in the world
    assert palm.type == "box" and palm.p0 is None
    np.testing.assert_allclose(palm.center, [0.1, 0.2, 0.33], atol=1e-12)
    np.testing.assert_allclose(palm.rotation, T[:3, :3], atol=1e-15)
    prox3 = next(p for p in parts if p.name == "finger3/proximal")
    # finger 3 (hand -y) lies along world +y after the flip about x; the capsule spans 70 mm
    np.testing.assert_allclose(prox3.p0, [0.1, 0.2 + 0.05, 0.3], atol=1e-12)
    np.testing.assert_allclose(prox3.p1, [0.1, 0.2 + 0.12, 0.3], atol=1e-12)
    assert prox3.type == "capsule" and prox3.radius == pytest.approx(0.0125)
    shapes = h.link_shapes()
    assert len(shapes) == 9 and shapes[0][0].type == "box"
    poses = h.link_poses(q, T)
    assert poses.shape == (9, 4, 4)
    np.testing.assert_allclose(poses[0], T)


def test_robotiq_file_loads():
    h = Hand.load("robotiq_3f")
    assert h.num_fingers == 3 and h.num_joints == 10 and h.num_links == 10
    assert "approximate" in h.name.lower()
    lo, hi = h.spread_limits
    assert lo < 0 < hi


def test_bad_hand_input():
    with pytest.raises(ValueError, match="name_or_path"):
        Hand.load("no_such_hand")
    with pytest.raises(ValueError, match="not valid JSON"):
        Hand.from_json("{not json")
    bad = json.loads((HANDS_DIR / "barrett_bh8.json").read_text())
    del bad["fingers"][0]["phalanges"][0]["length"]
    with pytest.raises(ValueError, match="length"):
        Hand.from_json(json.dumps(bad))
    h = Hand.load()
    with pytest.raises(ValueError, match="q"):
        h.link_poses(np.zeros(3))
    with pytest.raises(ValueError, match="q"):
        h.link_poses(np.full(7, np.nan))
    with pytest.raises(ValueError, match="hand_pose"):
        h.link_poses(h.open_joints(), np.eye(3))
    with pytest.raises(ValueError, match="spread"):
        h.coupled_joints(4.0)


def test_approach_pose_convention():
    # along -z: the top grasp's pose itself; roll = yaw
    np.testing.assert_array_equal(Hand.approach_pose([0, 0, -1], 0.7, [0.1, -0.2, 0.3]),
                                  Hand.top_grasp_pose(0.1, -0.2, 0.7, 0.3))
    # along +x at roll 0: hand z = +x, hand x = +z (the palm-down hand tilted about -y), y = -y
    T = Hand.approach_pose([3.0, 0, 0], 0.0, [0, 0, 0.05])
    np.testing.assert_allclose(T[:3, :3], [[0, 0, 1], [0, -1, 0], [1, 0, 0]], atol=1e-15)
    # roll: a right-handed turn about -direction (Rodrigues)
    d = np.array([0.3, -0.5, -0.8]) / np.linalg.norm([0.3, -0.5, -0.8])
    a, r = -d, 1.1
    K = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    turn = np.eye(3) + np.sin(r) * K + (1 - np.cos(r)) * K @ K
    np.testing.assert_allclose(Hand.approach_pose(d, r, [0, 0, 0])[:3, :3],
                               turn @ Hand.approach_pose(d, 0.0, [0, 0, 0])[:3, :3], atol=1e-12)
    for bad, needle in [([0, 0, 0], "direction"), ([np.nan, 0, 1], "direction"), ([0, 0], "direction")]:
        with pytest.raises(ValueError, match=needle):
            Hand.approach_pose(bad, 0.0, [0, 0, 0])
    with pytest.raises(ValueError, match="palm"):
        Hand.approach_pose([0, 0, -1], 0.0, [0, np.inf, 0])


def _edited(edit):
    spec = json.loads((HANDS_DIR / "barrett_bh8.json").read_text())
    edit(spec)
    return json.dumps(spec)


@pytest.mark.parametrize("edit, needle", [
    (lambda s: s["fingers"][1]["phalanges"][0].update(torque=2.0),
     r"fingers\[1\]\.phalanges\[0\]: unknown key 'torque'"),
    (lambda s: s["fingers"][0]["phalanges"][1].pop("offset_deg"), r"fingers\[0\]\.phalanges\[1\]: missing key 'offset_deg'"),
    (lambda s: s["fingers"][0]["phalanges"][1].pop("torque_nm"), r"missing key 'torque_nm'"),
    (lambda s: s["fingers"][0]["phalanges"][0].pop("ratio"), r"missing key 'ratio'"),
    (lambda s: s["fingers"][2].pop("knuckle"), r"fingers\[2\]: missing key 'knuckle'"),
    (lambda s: s["fingers"][2].pop("spread_sign"), r"missing key 'spread_sign'"),
    (lambda s: s["fingers"][0].pop("name"), r"fingers\[0\]: missing key 'name'"),
    (lambda s: s["spread"].pop("default_deg"), r"spread: missing key 'default_deg'"),
    (lambda s: s.pop("actuation"), r"top level: missing key 'actuation'"),
    (lambda s: s.update(colour="red"), r"top level: unknown key 'colour'"),
    (lambda s: s["palm"]["shapes"][0].update(radius=0.01), r"palm\.shapes\[0\]: unknown key 'radius'"),
    (lambda s: s["fingers"][0]["knuckle"].pop("shapes"), r"knuckle: missing key 'shapes'"),
])
def test_hand_files_are_strict_one_line_naming_the_key(edit, needle):
    # issue 31: an unknown or missing key is refused in one line naming where; nothing defaults
    with pytest.raises(ValueError, match=needle) as e:
        Hand.from_json(_edited(edit))
    assert "\n" not in str(e.value)


def test_documentation_keys_may_be_left_out():
    h = Hand.from_json(_edited(lambda s: (s.pop("description"), s.pop("frame"))))
    ref = Hand.load()
    np.testing.assert_array_equal(h.link_poses(ref.open_joints()), ref.link_poses(ref.open_joints()))


def test_every_built_in_hand_names_each_link_once():
    """Link names label contacts, joints and the viewer's meshes: no two links of a hand share one."""
    for name in builtin_hands():
        links = Hand.load(name).links
        assert len(set(links)) == len(links), (name, links)
