"""URDF hands (issue 31): the shipped BH8 and Robotiq 3F URDFs give the same grasps as their hand
files, and a URDF or sidecar the conversion cannot take is refused in one line naming it."""
import json
import re
import shutil

import numpy as np
import pytest

from bayesgrasp.hand import HANDS_DIR, Hand, builtin_hands
from bayesgrasp.hand_urdf import HandFileError, hand_json_from_urdf
from bayesgrasp.objects import load_object
from bayesgrasp.sim import GraspSimulator
from testkit import cli_json, urdf_fk


def _grasp_set(obj, n_top, n_side, seed):
    """A fixed set of top grasps over the object's footprint and side approaches at its middle."""
    rng = np.random.default_rng(seed)
    lo, hi = obj.bounds
    xyyaw = np.c_[rng.uniform(lo[0], hi[0], n_top), rng.uniform(lo[1], hi[1], n_top), rng.uniform(-np.pi, np.pi, n_top)]
    az = rng.uniform(-np.pi, np.pi, n_side)
    dirs = np.c_[np.cos(az), np.sin(az), np.zeros(n_side)]
    targets = np.c_[rng.uniform(lo[0], hi[0], n_side) * 0.3, rng.uniform(lo[1], hi[1], n_side) * 0.3,
                    rng.uniform(lo[2] + 0.02, hi[2] - 0.01, n_side)]
    return xyyaw, dirs, targets, rng.uniform(-np.pi, np.pi, n_side)


def _contact_rows(batch):
    c = batch.contacts
    return np.c_[c.grasp, c.link, c.point, c.on_table]


@pytest.mark.parametrize("name", ["barrett_bh8", "robotiq_3f"])
def test_urdf_hand_grasps_like_its_hand_file(name):
    """Joint angles within 1e-6 rad and the same contacts (grasp, link, table flag; point within 1e-5 m) on 300
    top grasps and 100 side approaches (no table, so any roll is free) of the mug (issue 31's
    equivalence)."""
    json_hand, urdf_hand = Hand.load(name), Hand.load(f"{name}.urdf")
    assert urdf_hand.links == json_hand.links
    assert list(urdf_hand.measured_joints) == list(json_hand.measured_joints)
    np.testing.assert_allclose(urdf_hand.joint_limits, json_hand.joint_limits, atol=1e-12)
    np.testing.assert_allclose(urdf_hand.joint_torques, json_hand.joint_torques, atol=0)
    mug = load_object("mug")
    xyyaw, dirs, targets, rolls = _grasp_set(mug, 300, 100, seed=3)
    spread = 0.5 * sum(json_hand.spread_limits) + 0.1
    out = []
    for hand in (json_hand, urdf_hand):
        top = GraspSimulator(hand, mug.vertices, mug.faces)
        side = GraspSimulator(hand, mug.vertices, mug.faces, table=False)
        out.append((top.top_grasp_batch(xyyaw, spread=spread, standoff=0.005),
                    side.approach_batch(dirs, targets, rolls, spread=spread, standoff=0.005)))
    for a, b in zip(out[0], out[1]):
        assert np.abs(np.asarray(a.joint_angles) - np.asarray(b.joint_angles)).max() < 1e-6
        np.testing.assert_allclose(np.asarray(a.hand_pose), np.asarray(b.hand_pose), atol=1e-9)
        ra, rb = _contact_rows(a), _contact_rows(b)
        assert ra.shape == rb.shape and len(ra) > 150   # the set touches the mug
        np.testing.assert_array_equal(ra[:, [0, 1, 5]], rb[:, [0, 1, 5]])
        # a witness point on a face parallel to a phalanx is ill-conditioned (FCL's tie-break moves
        # along the face with 1e-16 changes of pose): 10 um, where the joint angles agree to 1e-6 rad
        assert np.abs(ra[:, 2:5] - rb[:, 2:5]).max() < 1e-5


def test_urdf_hands_are_builtin_and_their_links_move_alike():
    assert {"barrett_bh8.urdf", "robotiq_3f.urdf"} <= set(builtin_hands())
    a, b = Hand.load("robotiq_3f"), Hand.load("robotiq_3f.urdf")   # its URDF's fingers stand up at joint 0
    rng = np.random.default_rng(1)
    for _ in range(20):
        s, t = rng.uniform(*a.spread_limits), rng.uniform(0, 2, a.num_fingers)
        qa, qb = a.coupled_joints(s, t), b.coupled_joints(s, t)
        np.testing.assert_allclose(qa, qb, atol=1e-12)
        np.testing.assert_allclose(a.link_poses(qa), b.link_poses(qb), atol=1e-12)


# ---------------------------------------------------------------- refused files ----

def _copy_bh8(tmp_path, urdf_edit=None, side_edit=None, name="hand"):
    urdf = (HANDS_DIR / "barrett_bh8.urdf").read_text()
    side = json.loads((HANDS_DIR / "barrett_bh8.hand.json").read_text())
    side["urdf"] = f"{name}.urdf"
    if urdf_edit:
        urdf = urdf_edit(urdf)
    if side_edit:
        side_edit(side)
    (tmp_path / f"{name}.urdf").write_text(urdf)
    (tmp_path / f"{name}.hand.json").write_text(json.dumps(side))
    return tmp_path / f"{name}.urdf"


def test_copied_urdf_hand_loads(tmp_path):
    assert Hand.load(_copy_bh8(tmp_path)).num_joints == 7


@pytest.mark.parametrize("side_edit, urdf_edit, message", [
    (lambda s: s.pop("palm"), None, r"hand\.hand\.json: top level: 'palm' is a required property"),
    (lambda s: s.update(stiffness=3), None, r"Additional properties are not allowed \('stiffness'"),
    (lambda s: s["fingers"][0]["phalanges"][0].pop("torque_nm"), None, r"fingers\.0\.phalanges\.0: needs exactly one of torque_nm, force_n"),
    (lambda s: s["fingers"][1]["phalanges"][1].update(joint="bh_j99"), None,
     r"fingers\[1\]\.phalanges\[1\]\.joint names joint 'bh_j99', which the URDF does not have"),
    (lambda s: s["spread"].update(joint="nope"), None, r"spread\.joint names joint 'nope'"),
    (lambda s: s["measured_joints"].append("bh_j11"), None, r"measured_joints\[6\]: joint 'bh_j11' is not a finger's"),
    (lambda s: s["palm"].update(link="wrist"), None, r"palm\.link names link 'wrist'"),
    (lambda s: s["fingers"].pop(2), None, r"joint 'bh_j32' moves link 'bh_finger3_proximal', but the sidecar names it nowhere"),
    (None, lambda u: u.replace('<cylinder radius="0.0125" length="0.07"/>', '<mesh filename="meshes/proximal.stl"/>', 1),
     r"link 'bh_finger1_proximal': mesh file 'meshes/proximal\.stl' not found"),
    (None, lambda u: u.replace("</robot>", '<joint name="loop" type="fixed"><parent link="bh_finger3_distal"/>'
                                           '<child link="bh_finger1_knuckle"/></joint></robot>'),
     r"kinematic loop: link 'bh_finger1_knuckle' is the child of two joints"),
    (None, lambda u: u.replace('<axis xyz="0 -1 0"/>', '<axis xyz="0 0 1"/>', 1),
     r"joint 'bh_j12' turns about the approach axis \(a spread or abduction joint"),
    (None, lambda u: u.replace('<mimic joint="bh_j12" multiplier="0.3333333333333333" offset="0.7330382858376184"/>', ""),
     r"joint 'bh_j13' is neither the finger's first joint nor a mimic of 'bh_j12'"),
    (None, lambda u: u.replace("<robot", "<robt", 1), r"hand\.urdf: not a readable URDF"),
    (None, lambda u: u.replace('<mimic joint="bh_j12" multiplier="0.3333333333333333"', '<mimic joint="bh_j12" multiplier="-1"'),
     r"hand\.hand\.json: fingers\[0\]\.phalanges\[1\]: joint 'bh_j13' turns against 'bh_j12' \(mimic multiplier -1\)"),
])
def test_bad_urdf_hand_refused_in_one_line(tmp_path, side_edit, urdf_edit, message):
    path = _copy_bh8(tmp_path, urdf_edit, side_edit)
    with pytest.raises(HandFileError, match=message) as e:
        Hand.load(path)
    assert "\n" not in str(e.value)


def test_missing_sidecar_and_mismatched_urdf_named(tmp_path):
    path = _copy_bh8(tmp_path)
    (tmp_path / "hand.hand.json").rename(tmp_path / "other.hand.json")
    with pytest.raises(HandFileError, match=r"its sidecar hand\.hand\.json is missing"):
        Hand.load(path)
    shutil.copy(path, tmp_path / "second.urdf")
    (tmp_path / "other.hand.json").rename(tmp_path / "second.hand.json")
    with pytest.raises(HandFileError, match=r"urdf: names hand\.urdf, but it was loaded with .*second\.urdf"):
        Hand.load(tmp_path / "second.urdf")
    with pytest.raises(ValueError, match="sidecar"):
        Hand.load(tmp_path / "second.hand.json")


def test_conversion_is_deterministic_text():
    """The converted text is the cache key's hand text: the same files give the same text."""
    p = HANDS_DIR / "barrett_bh8.urdf"
    assert hand_json_from_urdf(p) == hand_json_from_urdf(p) == Hand.load(p).text


# ---------------------------------------------------------------- mesh and convex shapes ----

def _bh8_with(tmp_path, pattern, replacement, name="mesh_bh8"):
    return _copy_bh8(tmp_path, lambda u: re.sub(pattern, replacement, u, count=1, flags=re.S), name=name)


def test_palm_as_a_box_mesh_grasps_exactly_like_the_box(tmp_path):
    """The palm box given as an STL mesh becomes a convex shape of the same 8 corners: the same
    geometry, so the same grasps (joint angles within 1e-6 rad), on grasps that touch the palm."""
    import trimesh

    (tmp_path / "meshes").mkdir()
    trimesh.creation.box(extents=[0.09, 0.09, 0.06]).export(tmp_path / "meshes" / "palm.stl")
    path = _bh8_with(tmp_path, r'<box size="0\.09 0\.09 0\.06"/>', '<mesh filename="package://bh8/meshes/palm.stl"/>')
    hand, ref = Hand.load(path), Hand.load("barrett_bh8")
    palm = hand.link_shapes()[0][0]
    assert palm.type == "convex" and palm.vertices.shape == (8, 3) and palm.faces.shape == (12, 3)
    post = trimesh.creation.box(extents=[0.02, 0.02, 0.06])   # fits between the fingers: the palm lands on it
    post.apply_translation([0, 0, 0.03])
    rng = np.random.default_rng(5)
    xyyaw = np.c_[rng.uniform(-0.02, 0.02, 200), rng.uniform(-0.02, 0.02, 200), rng.uniform(-np.pi, np.pi, 200)]
    a = GraspSimulator(ref, post.vertices, post.faces, table=False).top_grasp_batch(xyyaw, spread=1.0)
    b = GraspSimulator(hand, post.vertices, post.faces, table=False).top_grasp_batch(xyyaw, spread=1.0)
    assert np.abs(np.asarray(a.joint_angles) - np.asarray(b.joint_angles)).max() < 1e-6
    np.testing.assert_allclose(np.asarray(a.hand_pose), np.asarray(b.hand_pose), atol=1e-9)
    np.testing.assert_array_equal(np.asarray(a.contacts.link), np.asarray(b.contacts.link))
    assert np.sum(np.asarray(b.contacts.link) == 0) > 150   # the palm touched: the convex shape was queried


def test_tessellated_capsule_mesh_finger_grasps_and_lifts_like_the_capsule(tmp_path):
    """Distal links as a 24 x 12 tessellated capsule mesh (its hull; at most 0.09 mm inside the
    capsule): the grasps follow the capsule hand's and the lift test agrees on most of them."""
    import trimesh

    from bayesgrasp import physics

    cap = trimesh.creation.capsule(height=0.045, radius=0.01, count=[24, 12])   # along z, centred
    cap.apply_transform(trimesh.transformations.rotation_matrix(np.pi / 2, [0, 1, 0]))
    cap.apply_translation([0.0225, 0, 0])
    cap.export(tmp_path / "distal.obj")
    path = _copy_bh8(tmp_path, name="mesh_bh8")
    text = (tmp_path / "mesh_bh8.urdf").read_text()   # every distal link's three capsule pieces: one mesh
    text = re.sub(r'<collision name="distal_shaft">.*?<collision name="distal_cap1">.*?</collision>',
                  '<collision name="distal"><geometry><mesh filename="distal.obj"/></geometry></collision>', text, flags=re.S)
    (tmp_path / "mesh_bh8.urdf").write_text(text)
    assert text.count("distal.obj") == 3
    hand, ref = Hand.load(path), Hand.load("barrett_bh8")
    assert [s.type for s in hand.link_shapes()[3]] == ["convex"]
    mug = load_object("mug")
    xyyaw, *_ = _grasp_set(mug, 150, 0, seed=3)
    a = GraspSimulator(ref, mug.vertices, mug.faces).top_grasp_batch(xyyaw, spread=np.pi / 2)
    b = GraspSimulator(hand, mug.vertices, mug.faces).top_grasp_batch(xyyaw, spread=np.pi / 2)
    d = np.abs(np.asarray(a.joint_angles) - np.asarray(b.joint_angles)).max(axis=1)
    # a contact up to 0.09 mm further in, on a lever of 5 to 12 cm: about 1e-3 to 2e-3 rad
    assert np.median(d) < 4e-3 and np.mean(d < 0.02) > 0.9
    cube = load_object("cube")
    rng = np.random.default_rng(3)
    xy = np.c_[rng.uniform(-0.01, 0.01, 24), rng.uniform(-0.01, 0.01, 24), rng.uniform(-np.pi, np.pi, 24)]
    ga = GraspSimulator(ref, cube.vertices, cube.faces).top_grasp_batch(xy, spread=0.0)
    gb = GraspSimulator(hand, cube.vertices, cube.faces).top_grasp_batch(xy, spread=0.0)
    la = physics.LiftTester(ref, cube.vertices, cube.faces).run_batch(ga.hand_pose, ga.joint_angles)
    lb = physics.LiftTester(hand, cube.vertices, cube.faces).run_batch(gb.hand_pose, gb.joint_angles)
    assert np.sum(lb.lifted) >= 10                       # the mesh fingers hold the cube
    assert np.mean(np.asarray(la.lifted) == np.asarray(lb.lifted)) >= 0.75


def test_rotated_box_and_lone_cylinder_become_convex(tmp_path):
    path = _copy_bh8(tmp_path, lambda u: re.sub(r'<collision name="proximal_cap0">.*?</collision>', '', u.replace(
        '<origin xyz="0.025 0 -0.012"/>', '<origin xyz="0.025 0 -0.012" rpy="0.3 0 0"/>', 1), count=1, flags=re.S))
    hand = Hand.load(path)
    knuckle = hand.link_shapes()[1]
    assert [s.type for s in knuckle] == ["convex"] and knuckle[0].vertices.shape == (8, 3)
    prox = hand.link_shapes()[2]
    assert sorted(s.type for s in prox) == ["capsule", "convex"]   # the lone end sphere and the cylinder's prism
    prism = next(s for s in prox if s.type == "convex")
    assert prism.vertices.shape == (64, 3)
    np.testing.assert_allclose(np.linalg.norm(prism.vertices[:, 1:], axis=1), 0.0125, atol=1e-12)


@pytest.mark.parametrize("edit, message", [
    (lambda s: s["faces"].pop(), r"do not close the shape"),
    (lambda s: s["faces"][0].reverse(), r"do not close the shape"),
    (lambda s: s.update(faces=[f[::-1] for f in s["faces"]]), r"not convex or wound inwards"),
    (lambda s: s["vertices"][0].__setitem__(0, 0.0), r"not convex or wound inwards"),
    (lambda s: s["faces"][0].__setitem__(0, 99), r"faces\[0\] must be 3 vertex indices in \[0, 8\)"),
    (lambda s: s.pop("faces"), r"missing key 'faces'"),
])
def test_bad_convex_shape_refused(edit, message):
    spec = json.loads((HANDS_DIR / "barrett_bh8.json").read_text())
    corners = [[x, y, z] for x in (-0.045, 0.045) for y in (-0.045, 0.045) for z in (-0.06, 0.0)]
    from bayesgrasp.hand_urdf.urdf import _convex

    shape = _convex(np.array(corners))
    spec["palm"]["shapes"] = [shape]
    assert Hand.from_json(json.dumps(spec)).link_shapes()[0][0].type == "convex"
    edit(shape)
    with pytest.raises(ValueError, match=r"palm\.shapes\[0\]: .*" + message):
        Hand.from_json(json.dumps(spec))


@pytest.mark.parametrize("tilt, ok", [(3.67e-6, True), (5e-5, True), (1e-3, False)])
def test_an_axis_rounded_in_the_urdf_is_taken_within_1e_4_rad(tmp_path, tilt, ok):
    """A URDF that writes its numbers rounded (1.5708 for pi/2 tilts an axis by 3.7e-6 rad) loads,
    and grasps as the exact one does; an axis 1e-3 rad out of the palm plane is what the URDF says:
    the finger's plane rolled by 1e-3 rad about its outward direction (a thumb's case)."""
    axis = f'<axis xyz="0 -1 {np.tan(tilt):.12g}"/>'
    path = _copy_bh8(tmp_path, lambda u: u.replace('<axis xyz="0 -1 0"/>', axis, 2))   # bh_j12 and bh_j13
    if not ok:
        finger = json.loads(Hand.load(path).text)["fingers"][0]
        assert abs(finger["roll_deg"]) == pytest.approx(np.degrees(tilt), rel=1e-6)
        return
    (tmp_path / "exact").mkdir()
    tilted, exact = Hand.load(path), Hand.load(_copy_bh8(tmp_path / "exact"))
    q = np.array([0.5, 1.2, 1.0, 1.1, 0.9, 1.3, 1.0])
    np.testing.assert_allclose(tilted.fingertips(q), exact.fingertips(q), atol=1e-5)


def test_a_simulator_s_namespaced_extension_is_skipped(tmp_path):
    """<drake:...> elements (declared or not, as URDFs from simulators carry them) do not stop the
    hand from loading; broken XML still does."""
    ext = '<drake:collision_filter_group name="g"><drake:member link="bh_base_link"/></drake:collision_filter_group>'
    undeclared = _copy_bh8(tmp_path, lambda u: u.replace("</robot>", ext + "</robot>"))
    assert Hand.load(undeclared).num_joints == 7
    (tmp_path / "b").mkdir()
    declared = _copy_bh8(tmp_path / "b", lambda u: u.replace("<robot ", '<robot xmlns:drake="http://drake.mit.edu" ', 1)
                         .replace("</robot>", ext + "</robot>"))
    assert Hand.load(declared).text == Hand.load(undeclared).text
    (tmp_path / "c").mkdir()
    broken = _copy_bh8(tmp_path / "c", lambda u: u.replace("</robot>", "<drake:open></robot>"))
    with pytest.raises(HandFileError, match=r"hand\.urdf: not a readable URDF \(XML: "):
        Hand.load(broken)


def test_a_hand_inside_an_arm_urdf_is_read_from_its_root_link(tmp_path, capsys):
    """The BH8 mounted on a two-joint arm in one URDF: refused while the arm's joints are unnamed;
    with the sidecar's root naming the hand's base link everything above it is ignored and the hand
    is the BH8 (the same fingertips at the same joints), and it grasps through the CLI: the cube
    and the mug from the top, the cylinder from the side, each lifted, joints named as the URDF's."""
    arm = ('<link name="world"/><link name="arm_1"/><link name="arm_2"/>'
           '<joint name="arm_j1" type="revolute"><parent link="world"/><child link="arm_1"/><origin xyz="0 0 0.3"/>'
           '<axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="10" velocity="1"/></joint>'
           '<joint name="arm_j2" type="revolute"><parent link="arm_1"/><child link="arm_2"/><origin xyz="0 0 0.4"/>'
           '<axis xyz="0 1 0"/><limit lower="-2" upper="2" effort="10" velocity="1"/></joint>'
           '<joint name="arm_to_hand" type="fixed"><parent link="arm_2"/><child link="bh_base_link"/>'
           '<origin xyz="0.1 0 0.05" rpy="0.3 -0.2 1.0"/></joint></robot>')
    mounted = _copy_bh8(tmp_path, lambda u: u.replace("</robot>", arm))
    with pytest.raises(HandFileError, match=r"joint 'arm_j\d' moves link '\w+', but the sidecar names it nowhere"):
        Hand.load(mounted)
    (tmp_path / "r").mkdir()
    rooted = _copy_bh8(tmp_path / "r", lambda u: u.replace("</robot>", arm), lambda s: s.update(root="bh_base_link"))
    (tmp_path / "e").mkdir()
    hand, exact = Hand.load(rooted), Hand.load(_copy_bh8(tmp_path / "e"))
    q = np.array([0.4, 1.0, 1.1, 0.8, 1.0, 1.2, 0.9])
    np.testing.assert_allclose(hand.fingertips(q), exact.fingertips(q), atol=1e-12)
    for args in (["--object", "cube", "--top", "0,0,0"], ["--object", "mug", "--top", "0,0,0.5"],
                 ["--object", "cylinder", "--approach", "-1,0,0"]):
        doc = cli_json(capsys, "grasp", *args, "--hand", str(rooted), "--json")
        assert doc["lifted"] is True, args
        assert "arm_j1" not in doc["grasp"]["urdf"]["joint_names"] and "bh_j12" in doc["grasp"]["urdf"]["joint_names"]
    (tmp_path / "x").mkdir()
    with pytest.raises(HandFileError, match=r"root names link 'bh_wrist', which the URDF does not have"):
        Hand.load(_copy_bh8(tmp_path / "x", lambda u: u.replace("</robot>", arm), lambda s: s.update(root="bh_wrist")))


@pytest.mark.parametrize("name", ["barrett_bh8.urdf", "robotiq_3f.urdf", "parallel_jaw.urdf", "robotiq_2f85.urdf",
                                  "allegro_like.urdf"])
def test_the_joint_values_out_drive_the_urdf_to_the_simulator_s_fingertips(name):
    """Our joint vector in the URDF's own terms (Hand.urdf_joints): every moving URDF joint,
    mimic joints included, put into the URDF's own kinematic chain, brings each finger's tip (the
    sidecar's point on its last link; a jaw's on its sliding line) to where our model puts it,
    within 1 mm, at the open hand and at grasps the simulator closed."""
    from bayesgrasp.world import World

    hand = Hand.load(name)
    urdf, side = HANDS_DIR / name, json.loads((HANDS_DIR / name.replace(".urdf", ".hand.json")).read_text())
    world = World.single("cube", hand=hand)
    closed = [world.grasp(x, 0.0, yaw).joint_angles for x, yaw in ((0.0, 0.0), (0.01, 0.6))]
    for q in [hand.open_joints()] + closed:
        names, values = hand.urdf_joints(q)
        assert len(names) == len(set(names)) and len(names) >= hand.num_joints - 1
        links = urdf_fk(str(urdf), dict(zip(names, values)))
        palm = side["palm"]
        from scipy.spatial.transform import Rotation

        H = np.eye(4)
        H[:3, :3] = Rotation.from_euler("xyz", palm["rpy"]).as_matrix()
        H[:3, 3] = palm["xyz"]
        H = links[palm["link"]] @ H                              # the hand frame in the URDF's root
        robot = __import__("yourdfpy").URDF.load(str(urdf), build_scene_graph=False, load_meshes=False).robot
        joints = {j.name: j for j in robot.joints}
        tips = []
        for f in side["fingers"]:
            j = joints[f["phalanges"][-1]["joint"]]
            tip = np.asarray(f["fingertip"], float)
            if j.type == "prismatic":       # our jaw's tip lies on its sliding line (the pad offset is its shapes')
                axis = np.asarray(j.axis, float) / np.linalg.norm(j.axis)
                tip = tip - (tip @ axis) * axis
            tips.append((np.linalg.inv(H) @ links[j.child] @ np.append(tip, 1.0))[:3])
        np.testing.assert_allclose(np.array(tips), hand.fingertips(q), atol=1e-3)
    file_hand = Hand.load("barrett_bh8")
    assert file_hand.urdf_joints(file_hand.open_joints()) is None          # a hand file has no URDF


def test_outputs_give_a_urdf_hand_s_joints_in_the_urdf_s_terms(capsys):
    """grasp --json and --format ros with a URDF hand: the record's urdf block and the ROS
    postures name the URDF's joints with the URDF's values (a jaw's position, not its travel)."""
    from bayesgrasp.cli import main
    from bayesgrasp.io.grasp_schema import validate

    assert main(["grasp", "--object", "cube", "--top", "0,0,0", "--hand", "parallel_jaw.urdf", "--no-lift", "--json"]) == 0
    g = json.loads(capsys.readouterr().out)["grasp"]
    validate(g)
    travel = dict(zip(g["joint_names"], g["joint_positions"]))
    assert g["urdf"]["joint_names"] == ["pj_finger_joint1", "pj_finger_joint2"]
    np.testing.assert_allclose(g["urdf"]["joint_positions"], [0.04 - travel["left/jaw"], 0.04 - travel["right/jaw"]])
    np.testing.assert_allclose(g["urdf"]["pregrasp_joint_positions"], [0.04, 0.04])       # open: the URDF's upper limit
    assert main(["grasp", "--object", "cube", "--top", "0,0,0", "--hand", "parallel_jaw.urdf", "--no-lift",
                 "--format", "ros"]) == 0
    ros = json.loads(capsys.readouterr().out)
    assert ros["grasp_posture"]["joint_names"] == g["urdf"]["joint_names"]
    assert ros["joint_state"]["position"] == g["urdf"]["joint_positions"]
    assert main(["grasp", "--object", "cube", "--top", "0,0,0", "--no-lift", "--json"]) == 0
    assert "urdf" not in json.loads(capsys.readouterr().out)["grasp"]                    # a hand file's record has none


def test_a_multi_piece_collision_mesh_keeps_its_pieces(tmp_path):
    """A palm mesh of two separate blocks becomes two convex shapes, each a block's 8 corners, not
    one hull over both (which would fill the 4 cm gap between them)."""
    import trimesh

    (tmp_path / "meshes").mkdir()
    a, b = trimesh.creation.box(extents=[0.09, 0.025, 0.06]), trimesh.creation.box(extents=[0.09, 0.025, 0.06])
    a.apply_translation([0, -0.0325, 0])
    b.apply_translation([0, 0.0325, 0])
    trimesh.util.concatenate([a, b]).export(tmp_path / "meshes" / "palm.stl")
    path = _bh8_with(tmp_path, r'<box size="0\.09 0\.09 0\.06"/>', '<mesh filename="package://bh8/meshes/palm.stl"/>')
    palm = [s for s in Hand.load(path).link_shapes()[0]]
    assert [s.type for s in palm] == ["convex", "convex"]
    assert sorted(round(float(s.vertices[:, 1].mean()), 4) for s in palm) == [-0.0325, 0.0325]
    assert all(s.vertices.shape == (8, 3) for s in palm)


def test_a_mimic_of_an_equivalent_joint_is_the_same_coupling(tmp_path):
    """Finger 2's distal written as a mimic of finger 1's proximal, which finger 2's proximal mimics
    one to one: the URDF makes it the same coupling, and the hand converts to the same text; a mimic
    of another finger's independent joint is still refused."""
    def via_finger1(u):
        u = u.replace('<mimic joint="bh_j22" multiplier="0.3333333333333333"',
                      '<mimic joint="bh_j12" multiplier="0.3333333333333333"')
        return u.replace('<axis xyz="0 -1 0"/><limit lower="0" upper="2.443460952792061" effort="1.467" velocity="1"/></joint>\n'
                         '  <link name="bh_finger2_proximal">',
                         '<axis xyz="0 -1 0"/><limit lower="0" upper="2.443460952792061" effort="1.467" velocity="1"/>'
                         '<mimic joint="bh_j12" multiplier="1" offset="0"/></joint>\n  <link name="bh_finger2_proximal">')
    urdf = (HANDS_DIR / "barrett_bh8.urdf").read_text()
    assert via_finger1(urdf).count('<mimic joint="bh_j12"') == 3        # the edit took: j13, j22 and j23
    (tmp_path / "exact").mkdir()
    assert Hand.load(_copy_bh8(tmp_path, via_finger1)).text == Hand.load(_copy_bh8(tmp_path / "exact")).text
    (tmp_path / "other").mkdir()
    other = _copy_bh8(tmp_path / "other", lambda u: u.replace('<mimic joint="bh_j22" multiplier', '<mimic joint="bh_j32" multiplier'))
    with pytest.raises(HandFileError, match=r"joint 'bh_j23' is neither the finger's first joint nor a mimic of 'bh_j22'"):
        Hand.load(other)


@pytest.mark.parametrize("name", ["barrett_bh8.urdf", "robotiq_3f.urdf", "parallel_jaw.urdf", "robotiq_2f85.urdf",
                                  "allegro_like.urdf"])
def test_a_reading_in_the_urdf_s_terms_comes_back_as_our_joints(name):
    """Hand.joints_from_urdf inverts urdf_joints (open and closed hands); URDF joints that read one
    joint of ours and disagree, a wrong count, or a hand file are refused with what was expected."""
    from bayesgrasp.world import World

    hand = Hand.load(name)
    world = World.single("cube", hand=hand)
    for q in [hand.open_joints(), world.grasp(0.01, 0.0, 0.6).joint_angles]:
        names, values = hand.urdf_joints(q)
        np.testing.assert_allclose(hand.joints_from_urdf(values), q, atol=1e-12)
    with pytest.raises(ValueError, match=f"for the URDF's {len(names)} moving joints"):
        hand.joints_from_urdf(values[:-1])
    reads = [m for m in hand.urdf_joint_map if m["scale"] != 0]      # a held joint (scale 0) reads nothing
    shared = [i for i in range(hand.num_joints) if sum(m["index"] == i for m in reads) > 1]
    if shared:   # two URDF joints read one of ours (a spread, a mimic): a reading where they differ
        k = next(k for k, m in enumerate(hand.urdf_joint_map) if m["index"] == shared[0] and m["scale"] != 0)
        bad = values.copy()
        bad[k] += 0.2 * hand.urdf_joint_map[k]["scale"]
        with pytest.raises(ValueError, match="disagree by more than"):
            hand.joints_from_urdf(bad)
    with pytest.raises(ValueError, match="not a URDF hand"):
        Hand.load("barrett_bh8").joints_from_urdf(values)
