"""The World: grasps in the object frame against hand-derived joint angles, the object-to-world
mapping on known poses, the quality inputs, and the typed results."""
import numpy as np
import pytest
from scipy.optimize import brentq

from bayesgrasp import quality
from bayesgrasp.hand import Hand
from bayesgrasp.sim import GraspSimulator
from bayesgrasp.world import ContactRecord, World, WorldGrasp, WorldGraspBatch

DEG = np.pi / 180
R_CYL, H_CYL = 0.035, 0.12  # the built-in cylinder


def distal_inner_u(u0, th):
    """Innermost u of the BH8 distal capsule's segment in its finger plane (see test_sim.py)."""
    ju = u0 + 0.07 * np.cos(th)
    phi = th + th / 3 + 42 * DEG
    return min(ju, ju + 0.045 * np.cos(phi))


def test_top_grasp_keeps_the_finger_sweep_above_the_table():
    world = World.single("mug")
    V, F = world.vertices, world.faces
    # The mug (9.5 cm) is lower than the Barrett's fingers reach below the palm (about 10.6 cm):
    # stopping at the first contact (clearance < 0) lets the fingers strike the table.
    first_contact = GraspSimulator(world.hand, V, F, table_clearance=-1.0).top_grasp(0.0, 0.0, 0.3, spread=0.0)
    assert first_contact.contacts.on_table.any()
    clear = GraspSimulator(world.hand, V, F, table_clearance=0.005).top_grasp(0.0, 0.0, 0.3, spread=0.0)
    assert not clear.contacts.on_table.any()
    assert int((~clear.contacts.on_table).sum()) >= 3          # all three fingers on the mug
    # the palm is raised so that the deepest point of the closing sweep is 5 mm above the table
    assert clear.hand_pose[2, 3] > first_contact.hand_pose[2, 3]


@pytest.mark.parametrize("pose, yaw", [((0.0, 0.0, 0.0), 0.0), ((0.05, 0.02, 0.4), 0.3), ((-0.1, 0.07, 2.5), -1.2)])
def test_centred_grasp_of_the_cylinder_matches_trigonometry_at_any_object_pose(pose, yaw):
    # Spread 90 deg: fingers 1 and 2 close in the vertical plane of the hand's x axis, finger 3
    # in that of its -y axis. The palm lands on the top face (the cylinder is taller than the
    # fingers reach, so the table clearance does not raise it); each distal capsule (radius
    # 10 mm) meets the side wall when the innermost point of its segment reaches R + 10 mm.
    world = World.single("cylinder", pose=pose, spread=90 * DEG)
    ox, oy, oyaw = pose
    g = world.grasp(0.0, 0.0, yaw)
    assert isinstance(g, WorldGrasp) and not g.collision_at_start
    # Object frame -> world: the hand is centred over the object's axis, turned by both yaws.
    expected = Hand.top_grasp_pose(ox, oy, yaw + oyaw, 0.0)
    np.testing.assert_allclose(g.hand_pose[:3, :3], expected[:3, :3], atol=1e-12)
    np.testing.assert_allclose(g.hand_pose[:2, 3], [ox, oy], atol=1e-12)
    assert H_CYL <= g.hand_pose[2, 3] <= H_CYL + 2e-4
    for f, u0 in enumerate([0.075, 0.075, 0.05]):
        th = brentq(lambda t: distal_inner_u(u0, t) - (R_CYL + 0.010), 30 * DEG, 120 * DEG)
        j = 1 + 2 * f
        assert g.joint_angles[j] / DEG == pytest.approx(th / DEG, abs=0.5)
        assert g.joint_angles[j + 1] / DEG == pytest.approx((th / 3 + 42 * DEG) / DEG, abs=0.5)
    # The distal contacts lie on the side wall, at the world angles of the fingers' planes:
    # finger 1 along the hand's x (world angle yaw + oyaw), finger 2 opposite, finger 3 along
    # the hand's -y (world +y after the palm-down flip: 90 deg further).
    a = yaw + oyaw
    want = {"finger1/distal": a, "finger2/distal": a + np.pi, "finger3/distal": a + np.pi / 2}
    distal = {c.link_name: c for c in g.contacts if c.link_name in want}
    assert set(distal) == set(want)
    for name, angle in want.items():
        p = np.asarray(distal[name].point)
        assert np.hypot(p[0] - ox, p[1] - oy) == pytest.approx(R_CYL, abs=3e-4)
        assert np.cos(np.arctan2(p[1] - oy, p[0] - ox) - angle) > np.cos(1 * DEG)
        n = np.asarray(distal[name].normal)  # the side wall's outward normal: radial, horizontal
        np.testing.assert_allclose(n, [np.cos(angle), np.sin(angle), 0.0], atol=0.03)
    palm = [c for c in g.contacts if c.link_name == "palm"]
    assert len(palm) == 1 and palm[0].point[2] == pytest.approx(H_CYL, abs=1e-9)
    np.testing.assert_allclose(palm[0].normal, [0, 0, 1], atol=1e-9)
    # Quality inputs: the cylinder's centre of mass (axis, half height) and its largest radius.
    np.testing.assert_allclose(world.com, [ox, oy, H_CYL / 2], atol=1e-9)
    assert world.torque_scale == pytest.approx(np.hypot(R_CYL, H_CYL / 2), rel=1e-9)
    pts = np.array([c.point for c in g.contacts if not c.on_table])
    nrm = np.array([c.normal for c in g.contacts if not c.on_table])
    eps, vol = quality.epsilon_volume(pts, nrm, [ox, oy, H_CYL / 2], np.hypot(R_CYL, H_CYL / 2), mu=world.mu)
    assert g.epsilon > 0.1 and g.epsilon == pytest.approx(eps, rel=1e-9) and g.volume == pytest.approx(vol, rel=1e-9)


def test_grasp_batch_is_the_simulation_at_the_mapped_poses():
    # The object at (x, y, yaw) = (0.05, 0.02, 0.4): the batch's hand poses are the top-grasp
    # poses at the object-frame grasps mapped by that planar pose.
    world = World.single("cylinder", pose=(0.05, 0.02, 0.4))
    grasps = np.array([[0.0, 0.0, 0.0], [0.01, -0.005, 0.7], [0.0, 0.01, 1.9]])
    b = world.grasp_batch(grasps, spread=0.0, threads=2)
    assert isinstance(b, WorldGraspBatch) and len(b) == 3
    c, s = np.cos(0.4), np.sin(0.4)
    for i, (gx, gy, gyaw) in enumerate(grasps):
        x, y = 0.05 + c * gx - s * gy, 0.02 + s * gx + c * gy
        expected = Hand.top_grasp_pose(x, y, gyaw + 0.4, b.hand_pose[i][2, 3])
        np.testing.assert_allclose(b.hand_pose[i], expected, atol=1e-12)
    assert b.joint_angles.shape == (3, 7) and b.link_contact.shape == (3, 9) and b.table_contact.shape == (3, 9)
    assert b.contacts.offsets.tolist()[0] == 0 and b.contacts.offsets[-1] == len(b.contacts.point)
    assert b.epsilon.shape == b.volume.shape == (3,) and b.epsilon[0] > 0.1  # the centred grasp holds
    assert b.lifted is None and b.lift_displacement is None
    assert (b.distance_queries > 0).all()


def test_grasp_result_as_dict():
    world = World.single("cube", pose=(0.02, -0.01, 0.5))
    g = world.grasp(0.0, 0.0, 0.2)
    d = g.to_dict()
    assert list(d) == ["joint_angles", "contacts", "epsilon", "volume", "collision_at_start", "hand_pose",
                       "lifted", "lift_displacement", "stopped_by_table", "hand_pose_object", "joint_names"]
    assert d["lifted"] is None and d["lift_displacement"] is None and d["stopped_by_table"] is False
    assert d["joint_names"] == world.hand.joint_names
    assert all(isinstance(c, ContactRecord) for c in g.contacts)
    assert [list(c) for c in d["contacts"]] == [["point", "normal", "link", "link_name", "penetration", "on_table",
                                                 "triangle", "part"]] * len(g.contacts)
    assert d["contacts"][0]["link_name"] == world.hand.links[d["contacts"][0]["link"]]
    assert isinstance(d["contacts"][0]["point"], list) and isinstance(d["epsilon"], float)


def test_world_rejects_bad_parameters():
    with pytest.raises(ValueError, match="mu"):
        World.single("cube", mu=-1.0)
    with pytest.raises(ValueError, match="grasps"):
        World.single("cube").grasp_batch(np.zeros((2, 2)))


def test_plot_grasp_draws_the_hand_and_contacts(tmp_path):
    from bayesgrasp import viz
    world = World.single("cube")
    g = world.grasp(0.0, 0.0, 0.0)
    meshes = viz.hand_meshes(world.hand, g.joint_angles, g.hand_pose)
    assert len(meshes) == sum(len(s) for s in world.hand.link_shapes())  # one mesh per shape
    out = viz.plot_grasp(world, g, tmp_path / "grasp.png", title="cube")
    assert out.exists() and out.stat().st_size > 1000
