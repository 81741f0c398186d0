"""`bayesgrasp view` draws the arm of a grasp record (the schema's `arm`, from `--robot`): each of
its moving collision shapes at the grasp, posed by the arm's forward kinematics, faint at the
pre-grasp behind the "pregrasp" toggle; an unreachable grasp draws no arm and says why; a record
without `arm` draws none. Oracles: the planar two-link arm's links in closed form, the KUKA's
T_joint(q) M_shape from Arm.joint_frames, and the palm of `grasp --robot` at the grasp pose."""
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("viser")

from scipy.spatial.transform import Rotation  # noqa: E402

from bayesgrasp.arm import Arm  # noqa: E402
from bayesgrasp.viewer import scene_from_result  # noqa: E402
from testkit import cli_json, free_port, served_nodes  # noqa: E402

PLANAR = Path(__file__).resolve().parents[1] / "data" / "arms" / "planar_2link.urdf"


@pytest.fixture()
def grasp_doc(capsys):
    return cli_json(capsys, "grasp", "--object", "mug/3", "--top", "0,0,0.3", "--json")


def with_arm(doc, arm: dict) -> dict:
    return {**doc, "grasp": {**doc["grasp"], "arm": arm}}


def record(urdf, base, q, q_pre=None, mount=np.eye(4), names=None, flange=None) -> dict:
    """The schema's `arm` for joints q (and q_pre) of an arm, as `arm_record` writes it."""
    arm = Arm.load(urdf, flange=flange, mount=mount, base=base)
    rec = {"urdf": str(urdf), "base": arm.base.tolist(), "flange_link": arm.flange, "mount": arm.mount.tolist(),
           "joint_names": names or arm.joint_names, "reachable": True, "reason": "",
           "joint_positions": list(q)}
    if q_pre is not None:
        rec["pregrasp_joint_positions"] = list(q_pre)
    return rec


def pose(node) -> np.ndarray:
    """A viser node's 4x4 pose in the world (its parents are identity anchors)."""
    T = np.eye(4)
    w, x, y, z = node.wxyz
    T[:3, :3] = Rotation.from_quat([x, y, z, w]).as_matrix()
    T[:3, 3] = node.position
    return T


def arm_nodes(nodes, k=0, which="arm") -> dict:
    pre = f"/steps/{k}/{which}/"
    return {n[len(pre):]: h for n, h in nodes.items() if n.startswith(pre)}


def test_the_planar_arms_links_lie_where_its_angles_put_them(grasp_doc):
    """Shoulder at (0, 0, 0.1) turning q1, a 0.5 m upper link, the elbow turning q2, a 0.3 m
    forearm: each link's cylinder is centred half-way along it, its axis along the link."""
    q1, q2 = 0.7, -1.1
    doc = with_arm(grasp_doc, record(PLANAR, np.eye(4), [q1, q2], q_pre=[0.2, 0.4]))
    nodes, view = served_nodes(scene_from_result(doc))
    links = arm_nodes(nodes)
    assert {"upper_0-0", "fore_0-0", "base", "palm"} <= set(links)
    u, f = np.array([np.cos(q1), np.sin(q1), 0.0]), np.array([np.cos(q1 + q2), np.sin(q1 + q2), 0.0])
    shoulder = np.array([0.0, 0.0, 0.1])
    elbow = shoulder + 0.5 * u
    for name, centre, axis, length in (("upper_0-0", shoulder + 0.25 * u, u, 0.5), ("fore_0-0", elbow + 0.15 * f, f, 0.3)):
        T = pose(links[name])
        np.testing.assert_allclose(T[:3, 3], centre, atol=1e-9)
        np.testing.assert_allclose(T[:3, 2], axis, atol=1e-6)      # the URDF's pitch is 1.5707963, not pi/2
        V = np.asarray(links[name].vertices)                      # the cylinder in its own frame
        np.testing.assert_allclose(np.ptp(V, axis=0), [0.02, 0.02, length], atol=1e-3)
    np.testing.assert_allclose(pose(links["palm"])[:3, 3], elbow + 0.3 * f, atol=1e-9)   # the tip link
    pre = arm_nodes(nodes, which="arm_pregrasp")
    np.testing.assert_allclose(pose(pre["upper_0-0"])[:3, 3], shoulder + 0.25 * np.array([np.cos(0.2), np.sin(0.2), 0]),
                               atol=1e-9)
    assert "arm: planar_2link, reachable" in view.label.content


def test_the_kuka_links_are_posed_by_its_forward_kinematics_and_toggle(grasp_doc):
    base = (-0.6, 0.1, 0.0, 0.4)
    arm = Arm.load("kuka_lbr4", base=base)
    q = 0.5 * (arm.lower + arm.upper) + 0.3 * np.sin(np.arange(arm.dof) + 1.0)
    q_pre = q + 0.1
    mount = np.eye(4)
    mount[2, 3] = 0.06
    doc = with_arm(grasp_doc, record("kuka_lbr4", base, q, q_pre, mount=mount))
    from bayesgrasp.viewer.serve import serve, stop

    server, view = serve(scene_from_result(doc), port=free_port())
    try:
        check_kuka(dict(server.scene._handle_from_node_name), view, base, mount, q, q_pre)
    finally:
        stop(server)


def check_kuka(nodes, view, base, mount, q, q_pre) -> None:
    links, pre = arm_nodes(nodes), arm_nodes(nodes, which="arm_pregrasp")
    arm = Arm.load("kuka_lbr4", base=base, mount=mount)
    shapes = arm.link_shapes()
    for qq, drawn in ((q, links), (q_pre, pre)):
        T = arm.joint_frames(qq)[0]
        seen = {}
        for name, _, k, M in shapes:
            i = seen[name] = seen.get(name, -1) + 1
            np.testing.assert_allclose(pose(drawn[f"{name}-{i}"]), T[k] @ M, atol=1e-9)
        assert len(drawn) >= len(shapes)
    np.testing.assert_allclose(pose(links["palm"]), arm.palm_poses(q)[0], atol=1e-9)
    np.testing.assert_allclose(pose(links["base"]), arm.base, atol=1e-9)
    # the arm at the grasp is its own layer; the pre-grasp's arm goes with the pre-grasp toggle (off at first)
    grasp_link, pre_link = links[f"{shapes[0][0]}-0"], pre[f"{shapes[0][0]}-0"]
    assert grasp_link.visible and not pre_link.visible
    view.toggles["arm"].value = False
    view.toggles["pregrasp"].value = True
    view.show(0)
    assert not grasp_link.visible and pre_link.visible


def test_an_unreachable_grasp_draws_no_arm_and_says_why(grasp_doc):
    rec = {"urdf": "kuka_lbr4", "base": np.eye(4).tolist(), "flange_link": "lbr4_link7", "mount": np.eye(4).tolist(),
           "joint_names": [f"lbr4_a{i}" for i in range(1, 8)], "reachable": False, "reason": "arm hits table"}
    nodes, view = served_nodes(scene_from_result(with_arm(grasp_doc, rec)))
    assert not [n for n in nodes if "/arm" in n]
    assert "unreachable (arm hits table)" in view.label.content
    nodes, view = served_nodes(scene_from_result(grasp_doc))            # no `arm`: no arm, no note
    assert not [n for n in nodes if "/arm" in n] and "arm" not in view.label.content
    assert any(n.startswith("/steps/0/hand/") for n in nodes)


def test_a_record_whose_joints_are_not_the_urdfs_draws_no_arm_and_says_so(grasp_doc):
    rec = record(PLANAR, np.eye(4), [0.1, 0.2], names=["elbow", "shoulder"])
    nodes, view = served_nodes(scene_from_result(with_arm(grasp_doc, rec)))
    assert not [n for n in nodes if "/arm" in n] and "not the URDF's chain" in view.label.content


def test_grasp_with_the_robot_shows_the_arm_holding_the_hand(capsys):
    """`grasp --robot` end to end: the drawn palm frame is the grasp's pose (the IK's 1 mm)."""
    doc = cli_json(capsys, "grasp", "--object", "mug", "--top", "0,0,0", "--robot", "kuka_lbr4",
                   "--robot-base", "-0.6,0,0,0", "--json")
    assert doc["grasp"]["arm"]["reachable"]
    nodes, view = served_nodes(scene_from_result(doc))
    links = arm_nodes(nodes)
    P = pose(links["palm"])
    np.testing.assert_allclose(P[:3, 3], np.asarray(doc["grasp"]["pose"])[:3, 3], atol=1e-3)
    assert len(links) >= 9 and arm_nodes(nodes, which="arm_pregrasp")


def test_the_matplotlib_fallback_draws_the_arm_as_a_stick_figure(grasp_doc, tmp_path):
    import matplotlib.image as mpimg

    from bayesgrasp.viewer.arm import stick_points
    from bayesgrasp.viewer.static import render_step

    q1, q2 = 0.7, -1.1
    arm = Arm.load(PLANAR)
    S = stick_points(arm, [q1, q2])       # base, shoulder, elbow, flange, palm
    elbow = np.array([0.5 * np.cos(q1), 0.5 * np.sin(q1), 0.1])
    tip = elbow + 0.3 * np.array([np.cos(q1 + q2), np.sin(q1 + q2), 0.0])
    np.testing.assert_allclose(S, [[0, 0, 0], [0, 0, 0.1], elbow, tip, tip], atol=1e-9)
    with_ = render_step(scene_from_result(with_arm(grasp_doc, record(PLANAR, np.eye(4), [q1, q2]))), 0,
                        tmp_path / "arm.png")
    without = render_step(scene_from_result(grasp_doc), 0, tmp_path / "no_arm.png")
    a, b = np.asarray(mpimg.imread(with_))[..., :3], np.asarray(mpimg.imread(without))[..., :3]
    dark = lambda img: int(np.all(img < 0.25, axis=-1).sum())        # the stick is drawn near-black, 3 px wide
    assert a.shape == b.shape and dark(a) > dark(b) + 300


def test_a_link_given_as_a_mesh_file_is_drawn_as_that_mesh(grasp_doc, tmp_path):
    """One revolute joint at z = 0.1 turning q about z, its link a 0.04 x 0.06 x 0.3 box written
    as an STL, scaled 2 along z and placed 0.15 m up the joint's z: drawn as that box's 8 corners,
    0.6 m long, its centre at z = 0.25, turned by q."""
    import trimesh

    trimesh.creation.box(extents=(0.04, 0.06, 0.3)).export(tmp_path / "link.stl")
    urdf = tmp_path / "arm.urdf"
    urdf.write_text('<?xml version="1.0"?><robot name="mesh_arm"><link name="base"/>'
                    '<joint name="j1" type="revolute"><origin xyz="0 0 0.1"/><axis xyz="0 0 1"/>'
                    '<limit lower="-3" upper="3" effort="1" velocity="1"/><parent link="base"/><child link="l1"/></joint>'
                    '<link name="l1"><collision><origin xyz="0 0 0.15"/><geometry>'
                    '<mesh filename="link.stl" scale="1 1 2"/></geometry></collision></link></robot>')
    q = 0.3
    nodes, _ = served_nodes(scene_from_result(with_arm(grasp_doc, record(urdf, np.eye(4), [q]))))
    link = arm_nodes(nodes)["l1_0-0"]
    V = np.asarray(link.vertices)
    assert len(V) == 8
    np.testing.assert_allclose(np.ptp(V, axis=0), [0.04, 0.06, 0.6], atol=1e-6)
    T = pose(link)
    np.testing.assert_allclose(T[:3, 3], [0, 0, 0.25], atol=1e-9)
    np.testing.assert_allclose(T[:3, :3], Rotation.from_euler("z", q).as_matrix(), atol=1e-9)
