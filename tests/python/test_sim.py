"""Contact simulation through Python: hand-derived closing angles, batches, bad input."""
import numpy as np
import pytest
from scipy.optimize import brentq

from bayesgrasp.hand import Hand
from bayesgrasp.objects.primitives import grid_box
from bayesgrasp.sim import GraspBatch, GraspResult, GraspSimulator, SimOptions, make_options

DEG = np.pi / 180


def cylinder(r, z0, z1, n, cx=0.0, cy=0.0):
    """Closed vertical cylinder with a vertex at angle 0 (n divisible by 4: also at 90 deg)."""
    a = 2 * np.pi * np.arange(n) / n
    ring = np.c_[cx + r * np.cos(a), cy + r * np.sin(a)]
    V = np.vstack([np.c_[ring, np.full(n, z0)], np.c_[ring, np.full(n, z1)], [[cx, cy, z0], [cx, cy, z1]]])
    F = []
    for i in range(n):
        j = (i + 1) % n
        F += [[i, j, n + j], [i, n + j, n + i], [2 * n, j, i], [2 * n + 1, n + i, n + j]]
    return V, np.array(F)


def box(lo, hi):
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    V = np.array([[hi[0] if i & 1 else lo[0], hi[1] if i & 2 else lo[1], hi[2] if i & 4 else lo[2]] for i in range(8)])
    F = np.array([[0, 2, 3], [0, 3, 1], [4, 5, 7], [4, 7, 6], [0, 1, 5], [0, 5, 4], [2, 6, 7], [2, 7, 3],
                  [0, 4, 6], [0, 6, 2], [1, 3, 7], [1, 7, 5]])
    return V, F


def distal_inner_u(u0, th):
    """Innermost u of the BH8 distal capsule's segment in its finger plane (u: outward)."""
    ju = u0 + 0.07 * np.cos(th)
    phi = th + th / 3 + 42 * DEG
    return min(ju, ju + 0.045 * np.cos(phi))


@pytest.fixture(scope="module")
def barrett():
    return Hand.load("barrett_bh8")


def test_top_grasp_on_cylinder_matches_trigonometry(barrett):
    # r = 35 mm, palm lands on the top; each distal capsule (radius 10 mm) meets the side when
    # the innermost point of its segment reaches u = r + 10 mm (vertex at 0 / 90 deg).
    r = 0.035
    sim = GraspSimulator(barrett, *cylinder(r, 0.0, 0.2, 256))
    g = sim.top_grasp(0.0, 0.0, 0.0, spread=90 * DEG)
    assert isinstance(g, GraspResult) and not g.collision_at_start
    assert g.hand_pose[2, 3] == pytest.approx(0.2, abs=2e-4)
    for f, u0 in enumerate([0.075, 0.075, 0.05]):
        th = brentq(lambda t: distal_inner_u(u0, t) - (r + 0.010), 30 * DEG, 120 * DEG)
        j = 1 + 2 * f
        assert g.joint_angles[j] / DEG == pytest.approx(th / DEG, abs=0.5)
        assert g.joint_angles[j + 1] / DEG == pytest.approx((th / 3 + 42 * DEG) / DEG, abs=0.5)
    # object contacts: palm, two knuckles, three distal links; normals unit, points on the side
    pts, nrm = g.object_contacts()
    assert len(pts) == 6
    np.testing.assert_allclose(np.linalg.norm(nrm, axis=1), 1.0)
    side = pts[:, 2] < 0.19
    np.testing.assert_allclose(np.hypot(pts[side, 0], pts[side, 1]), r, atol=3e-4)


def test_table_stops_fingers(barrett):
    # palm down 80 mm above the table, object far away: the distal tip sphere reaches the table
    # when 70 sin th + 45 sin(4 th / 3 + 42 deg) + 10 mm = 80 mm
    sim = GraspSimulator(barrett, *box([1, 1, 0], [1.05, 1.05, 0.05]))
    g = sim.close(Hand.top_grasp_pose(0, 0, 0, 0.08), 90 * DEG)
    th = brentq(lambda t: 0.07 * np.sin(t) + 0.045 * np.sin(t + t / 3 + 42 * DEG) + 0.01 - 0.08, 0.0, 60 * DEG)
    np.testing.assert_allclose(g.joint_angles[[1, 3, 5]] / DEG, th / DEG, atol=0.5)
    assert g.contacts.on_table.all() and len(g.contacts.link) == 3 and len(g.contacts) == 3
    np.testing.assert_allclose(g.contacts.point[:, 2], 0.0, atol=1e-12)
    np.testing.assert_allclose(g.contacts.normal, np.tile([0.0, 0.0, 1.0], (3, 1)))
    assert g.table_contact[[3, 6, 8]].all()  # the three distal links


def test_collision_at_start_reported(barrett):
    sim = GraspSimulator(barrett, *box([-0.03, -0.03, 0], [0.03, 0.03, 0.06]))
    g = sim.close(Hand.top_grasp_pose(0, 0, 0, 0.05), 0.0)
    assert g.collision_at_start and g.num_contacts == 0
    np.testing.assert_allclose(g.joint_angles, barrett.open_joints(0.0))


def test_batch_equals_serial_and_is_deterministic(barrett):
    sim = GraspSimulator(barrett, *cylinder(0.035, 0.0, 0.12, 48, 0.01, -0.005))
    rng = np.random.default_rng(3)
    xyyaw = np.c_[rng.uniform(-0.04, 0.04, (12, 2)), rng.uniform(-np.pi, np.pi, 12)]
    b1 = sim.top_grasp_batch(xyyaw, spread=0.7, threads=1)
    b2 = sim.top_grasp_batch(xyyaw, spread=0.7, threads=2)
    assert isinstance(b1, GraspBatch) and len(b1) == 12
    np.testing.assert_array_equal(b1.joint_angles, b2.joint_angles)
    np.testing.assert_array_equal(b1.contacts.point, b2.contacts.point)
    assert b1.joint_angles.shape == (12, 7) and b1.link_contact.shape == (12, 9)
    assert b1.hand_pose.shape == (12, 4, 4) and b1.link_contact.dtype == bool
    off = b1.contacts.offsets
    for i in range(12):
        g = sim.top_grasp(*xyyaw[i], spread=0.7)
        np.testing.assert_array_equal(g.joint_angles, b1.joint_angles[i])
        np.testing.assert_array_equal(g.contacts.point, b1.grasp_contacts(i).point)
        np.testing.assert_array_equal(g.contacts.link, b1.contacts.link[off[i]:off[i + 1]])
        np.testing.assert_array_equal(g.hand_pose, b1.hand_pose[i])
        np.testing.assert_array_equal(g.link_contact, b1.link_contact[i])
        assert g.collision_at_start == b1.collision_at_start[i]
        assert (b1.contacts.grasp[off[i]:off[i + 1]] == i).all()
    # close_batch from the reached poses gives the same grasps
    c = sim.close_batch(b1.hand_pose, 0.7, threads=2)
    np.testing.assert_allclose(c.joint_angles, b1.joint_angles, atol=1e-6)
    # results are read-only views
    with pytest.raises(ValueError):
        b1.joint_angles[0, 0] = 1.0


def test_robotiq_closes_on_a_box():
    hand = Hand.load("robotiq_3f")
    # 140 x 50 x 200 mm box (tall enough that the fingertips do not reach the table): fingers
    # B and C (x = +-45.5 mm, on one side) close onto one long face, finger A onto the other
    V, F = box([-0.07, -0.025, 0.0], [0.07, 0.025, 0.2])
    sim = GraspSimulator(hand, V, F)
    g = sim.top_grasp(0.0, 0.0, 0.0, spread=0.0)
    assert not g.collision_at_start
    fingers_touching = {hand.core.link_fingers[l] for l, t in zip(g.contacts.link, g.contacts.on_table)
                        if not t and l > 0}
    assert fingers_touching == {0, 1, 2}
    pts, nrm = g.object_contacts()
    side = pts[:, 2] < 0.199  # finger contacts on the long faces (the palm rests on the top)
    np.testing.assert_allclose(np.abs(nrm[side, 1]), 1.0, atol=1e-9)
    for link in range(1, hand.num_links):
        assert sim.link_object_distance(g.hand_pose, g.joint_angles, link) >= 0.0


def test_bad_input_raises_value_error(barrett):
    V, F = box([-0.03, -0.03, 0], [0.03, 0.03, 0.06])
    sim = GraspSimulator(barrett, V, F)
    bad = np.eye(4)
    bad[0, 3] = np.nan
    with pytest.raises(ValueError, match="hand_pose"):
        sim.close(bad, 0.0)
    with pytest.raises(ValueError, match="hand_pose"):
        sim.close(np.eye(3), 0.0)
    with pytest.raises(ValueError, match="spread"):
        sim.close(np.eye(4), 4.0)
    with pytest.raises(ValueError, match="spread"):
        sim.top_grasp(0, 0, 0, spread=np.nan)
    with pytest.raises(ValueError, match="standoff"):
        sim.top_grasp(0, 0, 0, spread=0.0, standoff=-0.01)
    with pytest.raises(ValueError, match="x"):
        sim.top_grasp(np.inf, 0, 0, spread=0.0)
    with pytest.raises(ValueError, match="xyyaw"):
        sim.top_grasp_batch(np.zeros((4, 2)), spread=0.0)
    with pytest.raises(ValueError, match="hand_poses"):
        sim.close_batch(np.zeros((2, 4, 4)), 0.0)
    with pytest.raises(ValueError, match="spreads"):
        sim.close_batch(np.stack([np.eye(4)] * 2), np.zeros(3))
    with pytest.raises(ValueError, match="threads"):
        sim.close_batch(np.stack([np.eye(4)] * 2), 0.0, threads=-1)
    with pytest.raises(ValueError, match="object"):
        GraspSimulator(barrett, V, F + 100)
    with pytest.raises(ValueError, match="object"):
        GraspSimulator(barrett, V, np.zeros((0, 3), dtype=int))
    with pytest.raises(ValueError, match="hand"):
        GraspSimulator(42, V, F)
    with pytest.raises(ValueError, match="contact_tolerance"):
        GraspSimulator(barrett, V, F, contact_tolerance=-1e-3)
    with pytest.raises(ValueError, match="box_skip"):
        GraspSimulator(barrett, V, F, box_skip=1e-4)
    with pytest.raises(ValueError, match="rel_err"):
        GraspSimulator(barrett, V, F, rel_err=1.0)
    with pytest.raises(ValueError, match="max_iterations"):
        GraspSimulator(barrett, V, F, max_iterations=0)
    with pytest.raises(ValueError, match="table_clearance"):
        GraspSimulator(barrett, V, F, table_clearance=np.nan)
    with pytest.raises(ValueError, match="not_an_option"):
        GraspSimulator(barrett, V, F, not_an_option=1)
    with pytest.raises(ValueError, match="q"):
        sim.link_object_distance(np.eye(4), np.zeros(3), 1)
    with pytest.raises(ValueError, match="link"):
        sim.link_object_distance(np.eye(4), barrett.open_joints(0.0), 99)
    # empty batch is fine
    b = sim.top_grasp_batch(np.zeros((0, 3)), spread=0.0)
    assert b.joint_angles.shape == (0, 7) and b.contacts.point.shape == (0, 3) and b.contacts.offsets.tolist() == [0]


def test_approach_bindings_check_shapes_and_name_the_argument(barrett):
    V, F = box([-0.03, -0.03, 0], [0.03, 0.03, 0.06])
    sim = GraspSimulator(barrett, V, F)
    D, P = np.array([[0, 0, -1.0], [1.0, 0, -1.0]]), np.array([[0, 0, 0.03], [0, 0, 0.03]])
    for call, needle in [
        (lambda: sim.approach([0, 0], [0, 0, 0.03]), "direction"),
        (lambda: sim.approach([0, 0, -1], np.zeros((1, 3))), "target"),
        (lambda: sim.approach([0, 0, 0], [0, 0, 0.03]), "direction"),
        (lambda: sim.approach_batch(D[:, :2], P), "directions"),
        (lambda: sim.approach_batch(D, P[:1]), "targets"),
        (lambda: sim.approach_batch(D, P, rolls=np.zeros(3)), "rolls"),
        (lambda: sim.approach_batch(D, P, threads=-1), "threads"),
    ]:
        with pytest.raises(ValueError, match=f"^{needle}"):
            call()
    # rolls: a number is every approach's roll
    b1 = sim.approach_batch(D, P, rolls=0.4, spread=0.3)
    b2 = sim.approach_batch(D, P, rolls=[0.4, 0.4], spread=0.3, threads=2)
    np.testing.assert_array_equal(b1.joint_angles, b2.joint_angles)
    g = sim.approach(D[1], P[1], roll=0.4, spread=0.3)
    assert isinstance(g, GraspResult) and isinstance(b1, GraspBatch)
    np.testing.assert_array_equal(g.joint_angles, b1.joint_angles[1])
    assert g.stopped_by_table == b1.stopped_by_table[1] and b1.stopped_by_table.shape == (2,)
    # contacts carry their triangle (-1 on the table)
    t = sim.top_grasp(0.0, 0.0, 0.0, spread=0.0)
    c = t.contacts
    assert c.triangle.dtype == np.int32 and len(c.triangle) == len(c.point)
    assert np.all((c.triangle == -1) == c.on_table) and np.all(c.triangle < len(F))


def test_every_option_reaches_the_simulator(barrett):
    V, F = box([-0.03, -0.03, 0], [0.03, 0.03, 0.06])
    o = make_options(table=False, contact_tolerance=5e-4, rel_err=0.01, bv=SimOptions.BoundingVolume.RSS,
                     links=SimOptions.LinkGeometry.Primitives, max_iterations=321, table_clearance=-1.0,
                     prune_queries=False, tie_tolerance=1e-10)
    assert o.box_skip == pytest.approx(2.5 * 5e-4)  # raised above the tolerance
    got = GraspSimulator(barrett, V, F, options=o).options
    for k in ["table", "contact_tolerance", "rel_err", "box_skip", "bv", "links", "max_iterations", "table_clearance",
              "prune_queries", "tie_tolerance"]:
        assert getattr(got, k) == getattr(o, k), k
    # without a table, a hand closing in the air touches nothing
    g = GraspSimulator(barrett, V, F, options=o).close(Hand.top_grasp_pose(0.5, 0.5, 0, 0.02), 0.0)
    assert g.num_contacts == 0 and not g.table_contact.any()


def test_tied_triangles_under_a_flat_finger_give_the_grasp_of_the_exact_traversal(barrett):
    # A finely tessellated box: fingers closing on its faces are parallel to many triangles at
    # once. The tie tolerance (1e-12 m) prunes them; the grasps must be those of FCL's own
    # traversal (tie_tolerance = 0) to round-off, with fewer nodes visited (bench/sim_mesh_size.py).
    V, F = grid_box((0, 0, 0.05), (0.03, 0.02, 0.05), 24)
    rng = np.random.default_rng(5)
    g = np.column_stack([rng.uniform(-0.02, 0.02, 24), rng.uniform(-0.02, 0.02, 24), rng.uniform(0, np.pi, 24)])
    tied = GraspSimulator(barrett, V, F).top_grasp_batch(g, spread=0.0, threads=1)
    exact = GraspSimulator(barrett, V, F, tie_tolerance=0.0).top_grasp_batch(g, spread=0.0, threads=1)
    assert GraspSimulator(barrett, V, F).options.tie_tolerance == 1e-12
    assert np.asarray(tied.contacts.point).shape[0] > 24   # the fingers do reach the faces
    np.testing.assert_allclose(tied.joint_angles, exact.joint_angles, rtol=0, atol=1e-9)
    for bad in (-1e-12, float("nan"), 1e-4):
        with pytest.raises(ValueError, match="tie_tolerance"):
            GraspSimulator(barrett, V, F, tie_tolerance=bad)
