"""The World: grasps in the object frame against hand-derived joint angles, the object-to-world
mapping on known poses, the quality inputs, and the typed results."""
import numpy as np
import pytest
from scipy.optimize import brentq

from bayesgrasp import quality
from bayesgrasp.hand import Hand
from bayesgrasp.objects import ObjectModel
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


# ---- approaches and hand poses -----------------------------------------------------------------

def _segment_distance(c, a, b):
    ab = b - a
    t = np.clip(np.dot(c - a, ab) / ab.dot(ab), 0.0, 1.0)
    return np.linalg.norm(a + t * ab - c)


def side_grasp_angle(r):
    """Proximal angle at which a BH8 finger closing in a plane perpendicular to a standing
    cylinder of radius r (its side touching the palm face) first touches it. In the finger's
    plane, u outward from the palm centre and w along the approach direction, the cylinder's
    section is the circle of centre (0, r), radius r; the proximal capsule (radius 12.5 mm) runs
    from the joint J0 = (50 mm, 0) (knuckle 50 mm, finger base on the palm's centre line at
    spread 0) at angle th, 70 mm; the distal one (radius 10 mm) from its end at th + th / 3 +
    42 deg, 45 mm."""
    c, j0 = np.array([0.0, r]), np.array([0.05, 0.0])

    def clearance(th):
        j1 = j0 + 0.07 * np.array([np.cos(th), np.sin(th)])
        phi = th + th / 3 + 42 * DEG
        tip = j1 + 0.045 * np.array([np.cos(phi), np.sin(phi)])
        return min(_segment_distance(c, j0, j1) - (r + 0.0125), _segment_distance(c, j1, tip) - (r + 0.010))

    return brentq(clearance, 30 * DEG, 120 * DEG)


@pytest.mark.parametrize("pose", [(0.0, 0.0, 0.0), (0.1, -0.05, 0.7)])
def test_side_grasp_of_a_standing_cylinder_matches_trigonometry(pose):
    # Horizontal approach along the object's +x towards its axis, roll 0, spread 0: the hand's x
    # axis points up (the palm-down hand tilted about -y by 90 deg), the three fingers point
    # along the object's -y (fingers 1, 2, 25 mm above and below the palm centre) and +y
    # (finger 3) and close in horizontal planes, each wrapping the same circular section.
    world = World.single("cylinder", pose=pose, spread=0.0)
    ox, oy, oyaw = pose
    g = world.approach([1.0, 0.0, 0.0], [0.0, 0.0, 0.06], roll=0.0)
    assert not g.collision_at_start and not g.stopped_by_table
    c, s = np.cos(oyaw), np.sin(oyaw)
    d = np.array([c, s, 0.0])
    np.testing.assert_allclose(g.hand_pose[:3, :3], [[0, s, c], [0, -c, s], [1, 0, 0]], atol=1e-12)
    np.testing.assert_allclose(g.hand_pose_object[:3, :3], [[0, 0, 1], [0, -1, 0], [1, 0, 0]], atol=1e-12)
    # the palm face stops within the tolerance of the side wall, on the line through the target
    palm_gap = np.dot(np.array([ox, oy, 0.06]) - g.hand_pose[:3, 3], d) - R_CYL
    assert 0.0 < palm_gap < 2e-4
    np.testing.assert_allclose(g.hand_pose_object[:3, 3], [-R_CYL - palm_gap, 0.0, 0.06], atol=1e-12)
    th = side_grasp_angle(R_CYL)
    for f in range(3):
        assert g.joint_angles[1 + 2 * f] / DEG == pytest.approx(th / DEG, abs=0.5)
        assert g.joint_angles[2 + 2 * f] / DEG == pytest.approx((th / 3 + 42 * DEG) / DEG, abs=0.5)
    names = {c.link_name for c in g.contacts}
    assert {"palm", "finger1/distal", "finger2/distal", "finger3/distal"} <= names
    for k in g.contacts:
        assert not k.on_table
        p = np.asarray(k.point)
        assert np.hypot(p[0] - ox, p[1] - oy) == pytest.approx(R_CYL, abs=3e-4)
        if k.link_name == "palm":   # the side wall facing the hand: normal -d
            np.testing.assert_allclose(k.normal, -d, atol=0.03)
        if k.link_name.endswith("distal"):  # horizontal planes 25 mm apart around the palm centre
            assert p[2] == pytest.approx({"finger1/distal": 0.085, "finger2/distal": 0.035,
                                          "finger3/distal": 0.06}[k.link_name], abs=1e-9)
    # (epsilon is not compared: the palm and the knuckles lie along a line of the side wall, and
    # which point of it is reported as a link's one contact depends on round-off)


def test_top_grasp_is_the_approach_along_minus_z_in_the_world():
    world = World.single("mug", pose=(0.05, 0.02, 0.4))
    for x, y, yaw in [(0.0, 0.0, 0.3), (0.01, -0.02, -1.2), (0.03, 0.0, 2.0)]:
        t = world.grasp(x, y, yaw)
        a = world.approach([0, 0, -1], [x, y, 0.05], roll=yaw)
        np.testing.assert_array_equal(t.joint_angles, a.joint_angles)
        np.testing.assert_array_equal(t.hand_pose, a.hand_pose)
        assert [c.to_dict() for c in t.contacts] == [c.to_dict() for c in a.contacts]


def test_approaches_in_the_object_frame_are_the_world_approaches_mapped_by_the_object_pose():
    ox, oy, oyaw = 0.08, -0.03, 0.9
    world = World.single("mug", pose=(ox, oy, oyaw))
    rng = np.random.default_rng(4)
    u = rng.normal(size=(8, 3))
    u[:, 2] = np.abs(u[:, 2]) + 1.0
    D = -u / np.linalg.norm(u, axis=1, keepdims=True)
    P = np.c_[rng.uniform(-0.01, 0.01, (8, 2)), rng.uniform(0.03, 0.07, 8)]
    rolls = rng.uniform(-np.pi, np.pi, 8)
    b = world.approach_batch(D, P, rolls, threads=2)
    T = np.eye(4)
    T[:2, :2] = [[np.cos(oyaw), -np.sin(oyaw)], [np.sin(oyaw), np.cos(oyaw)]]
    T[:2, 3] = ox, oy
    w = world.approach_batch(D @ T[:3, :3].T, P @ T[:3, :3].T + T[:3, 3], rolls + oyaw, frame="world", threads=1)
    np.testing.assert_allclose(w.joint_angles, b.joint_angles, atol=1e-9)
    np.testing.assert_allclose(w.hand_pose, b.hand_pose, atol=1e-9)
    np.testing.assert_allclose(b.hand_pose_object, np.linalg.inv(T) @ b.hand_pose, atol=1e-12)
    np.testing.assert_array_equal(w.stopped_by_table, b.stopped_by_table)
    assert (~b.stopped_by_table).sum() >= 4 and b.joint_names == tuple(world.hand.joint_names)
    # one by one: the same grasps
    for i in range(8):
        g = world.approach(D[i], P[i], roll=rolls[i])
        np.testing.assert_array_equal(g.joint_angles, b.joint_angles[i])
        assert g.epsilon == pytest.approx(b.epsilon[i], abs=1e-12)
    # the closing from the poses reached gives the same joints (the approach only places the hand)
    p = world.grasp_poses(b.hand_pose_object, threads=1)
    np.testing.assert_allclose(p.joint_angles, b.joint_angles, atol=1e-6)
    q = world.grasp_poses(b.hand_pose, frame="world", threads=1)
    np.testing.assert_allclose(q.joint_angles, p.joint_angles, atol=1e-9)
    one = world.grasp_pose(b.hand_pose_object[0])
    np.testing.assert_allclose(one.joint_angles, p.joint_angles[0], atol=1e-12)
    assert not p.stopped_by_table.any()


def test_contacts_name_their_triangle_and_part():
    # The mug's labels: body, rim (its top), handle (beyond the body, at +x). The body is a
    # cylinder whose axis is at (x0 + r, 0) for its outer radius r (half the y extent).
    world = World.single("mug")
    obj = world.object
    V, F = obj.vertices, obj.faces
    r = (V[:, 1].max() - V[:, 1].min()) / 2
    axis = np.array([V[:, 0].min() + r, 0.0])
    # from the handle's side onto the handle (then the fingers wrap the body), from above
    # onto the handle, from above onto the middle
    b = world.approach_batch([[-1, 0, 0], [0, 0, -1], [0, 0, -1]], [[0, 0, 0.05], [0.04, 0, 0.05], [0, 0, 0.05]],
                             0.0, threads=1)
    c = b.contacts
    seen = set()
    for k in range(len(c.point)):
        if c.on_table[k]:
            assert c.triangle[k] == -1 and b.contact_part[k] is None
            continue
        # the contact point lies on its triangle (barycentric coordinates in [0, 1])
        a, e1, e2 = V[F[c.triangle[k], 0]], V[F[c.triangle[k], 1]] - V[F[c.triangle[k], 0]], V[F[c.triangle[k], 2]] - V[F[c.triangle[k], 0]]
        (s, t), *_ = np.linalg.lstsq(np.c_[e1, e2], c.point[k] - a, rcond=None)
        assert np.linalg.norm(a + s * e1 + t * e2 - c.point[k]) < 1e-9 and s >= -1e-9 and t >= -1e-9 and s + t <= 1 + 1e-9
        part = b.contact_part[k]
        radial = np.linalg.norm(c.point[k][:2] - axis)
        if radial > r + 1e-3:
            assert part == "handle"
        elif c.point[k][2] < 0.085 and radial > r - 1e-3:
            assert part == "body"
        seen.add(part)
    assert {"handle", "body"} <= seen
    g = world.approach([-1, 0, 0], [0, 0, 0.05])
    assert [k.part for k in g.contacts] == list(b.contact_part[: b.contacts.offsets[1]])
    cube = World.single("cube").object
    unlabelled = ObjectModel("box", cube.vertices, cube.faces)
    g = World.single(unlabelled).grasp(0, 0, 0)
    assert g.contacts and all(k.part is None for k in g.contacts)


def test_bad_approaches_and_poses_are_value_errors_naming_the_argument():
    world = World.single("cube")
    ok_d, ok_t = [0, 0, -1], [0, 0, 0.05]
    for kwargs, needle in [
        (dict(direction=[0, 0, 0], target=ok_t), "direction"),
        (dict(direction=[np.nan, 0, -1], target=ok_t), "direction"),
        (dict(direction=[0, 0, -1, 0], target=ok_t), "direction"),
        (dict(direction=ok_d, target=[0, 0, -0.01]), "target"),
        (dict(direction=ok_d, target=[2.0, 0, 0.05]), "target"),
        (dict(direction=ok_d, target=[0, np.inf, 0.05]), "target"),
        (dict(direction=ok_d, target=ok_t, roll=np.nan), "roll"),
        (dict(direction=ok_d, target=ok_t, frame="table"), "frame"),
    ]:
        with pytest.raises(ValueError, match=f"^{needle}"):
            world.approach(**kwargs)
    with pytest.raises(ValueError, match=r"^directions\[1\]"):
        world.approach_batch([ok_d, [0, 0, 0]], [ok_t, ok_t])
    with pytest.raises(ValueError, match=r"^targets\[1\].*off the table"):
        world.approach_batch([ok_d, ok_d], [ok_t, [0, -1.5, 0.05]])
    with pytest.raises(ValueError, match="^rolls"):
        world.approach_batch([ok_d, ok_d], [ok_t, ok_t], rolls=[0.0, 1.0, 2.0])
    sheared = np.eye(4)
    sheared[0, 1] = 0.3
    with pytest.raises(ValueError, match="^hand_pose: .*rotation"):
        world.grasp_pose(sheared)
    with pytest.raises(ValueError, match=r"^hand_poses\[1\]: .*rotation"):
        world.grasp_poses([np.eye(4), np.diag([2.0, 1.0, 1.0, 1.0])])
    bottom = np.eye(4)
    bottom[3, 0] = 1.0
    with pytest.raises(ValueError, match="^hand_pose: .*bottom row"):
        world.grasp_pose(bottom)
    with pytest.raises(ValueError, match="^hand_pose: expected shape"):
        world.grasp_pose(np.eye(3))


def test_a_hand_starting_in_the_object_or_the_table_is_reported():
    world = World.single("cube")
    inside = world.grasp_pose(Hand.top_grasp_pose(0.0, 0.0, 0.0, 0.03))     # palm inside the cube
    below = world.grasp_pose(Hand.top_grasp_pose(0.3, 0.0, 0.0, -0.01))     # under the table
    side = world.approach([1, 0, 0], [0, 0, 0.01], roll=0.0)                # hand reaching below z = 0
    for g in (inside, below, side):
        assert g.collision_at_start and g.contacts == [] and g.epsilon == 0.0
        np.testing.assert_array_equal(g.joint_angles, world.hand.open_joints(world.spread))
