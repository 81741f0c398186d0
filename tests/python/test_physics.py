"""Lift test from Python: a held box is lifted, an untouched one stays; batches; bad input."""
import numpy as np
import pytest

from bayesgrasp import physics


def _box(lo, hi):
    V = np.array([[hi[0] if i & 1 else lo[0], hi[1] if i & 2 else lo[1], hi[2] if i & 4 else lo[2]]
                  for i in range(8)], float)
    F = np.array([[0, 2, 1], [1, 2, 3], [4, 5, 6], [5, 7, 6], [0, 1, 4], [1, 5, 4],
                  [2, 6, 3], [3, 6, 7], [0, 4, 2], [2, 4, 6], [1, 3, 5], [3, 7, 5]])
    return V, F


# An 8 x 5 x 12 cm box on the table; the palm-down Barrett hand 1 cm above it (hand z =
# world -z, palm face at z = 0.13). Joint angles at which the three fingertips touch the box
# (within 0.1 mm; found by bisection in tests/cpp/test_physics.cpp): proximal 1.285743178
# rad, distal coupled = proximal / 3 + 42 deg.
V, F = _box((-0.04, -0.025, 0.0), (0.04, 0.025, 0.12))
POSE = np.diag([1.0, -1.0, -1.0, 1.0])
POSE[2, 3] = 0.13
PROX = 1.285743178
GOOD = np.array([0.0] + [PROX, PROX / 3 + np.radians(42)] * 3)
OPEN = np.array([0.0] + [0.0, np.radians(42)] * 3)


def test_held_box_is_lifted_and_open_hand_leaves_it():
    r = physics.lift_test(None, POSE, GOOD, V, F, density=400.0)
    assert isinstance(r, physics.LiftResult)
    assert r.finite and r.lifted
    assert r.displacement < 0.01
    assert abs(r.height_gain - 0.1) <= r.displacement + r.squeeze_displacement + 1e-9
    r = physics.lift_test(None, POSE, OPEN, V, F, density=400.0)   # None: the default hand
    assert not r.lifted
    assert abs(r.height_gain) < 2e-3  # still on the table


def test_tester_batch_equals_single_runs():
    t = physics.LiftTester(None, V, F, density=400.0)
    assert t.mass == pytest.approx(400.0 * 0.08 * 0.05 * 0.12)
    assert t.shape == "hull"
    out = t.run_batch(np.stack([POSE, POSE]), np.stack([GOOD, OPEN]), threads=2)
    assert isinstance(out, physics.LiftBatch) and len(out) == 2
    for i, q in enumerate([GOOD, OPEN]):
        r = t.run(POSE, q)
        assert out.lifted[i] == r.lifted
        assert out.displacement[i] == r.displacement
        assert out.rotation[i] == r.rotation and out.steps[i] == r.steps
        assert out[i].height_gain == r.height_gain
    assert out.lifted.tolist() == [True, False]
    assert out.shape == ["hull", "hull"]
    with pytest.raises(ValueError):
        out.lifted[0] = False  # read-only view of the results


def test_the_solver_stop_level_reaches_bullet():
    # a level every step's first iteration meets ends each step after one iteration: the same
    # run as solver_iterations=1, and not the default's 100
    one = physics.lift_test(None, POSE, GOOD, V, F, density=400.0, solver_iterations=1)
    huge = physics.lift_test(None, POSE, GOOD, V, F, density=400.0, solver_residual=1e30)
    full = physics.lift_test(None, POSE, GOOD, V, F, density=400.0)
    assert huge.displacement == one.displacement and huge.height_gain == one.height_gain
    assert full.displacement != one.displacement
    # a tiny level leaves the untouched box exactly where running every iteration leaves it
    tiny = physics.lift_test(None, POSE, OPEN, V, F, density=400.0, solver_residual=1e-10)
    rest = physics.lift_test(None, POSE, OPEN, V, F, density=400.0)
    assert tiny.lifted == rest.lifted and tiny.height_gain == pytest.approx(rest.height_gain, abs=1e-6)
    for bad in (-1.0, float("nan")):
        with pytest.raises(ValueError, match="solver_residual"):
            physics.lift_test(None, POSE, OPEN, V, F, solver_residual=bad)


def test_warm_start_and_friction_caching_reach_bullet():
    # warm start 0 starts every contact's impulse from nothing: a different run from the default's
    # 0.85 (the held box moves differently); the open hand touches nothing, so no setting changes it
    base = physics.lift_test(None, POSE, GOOD, V, F, density=400.0)
    cold = physics.lift_test(None, POSE, GOOD, V, F, density=400.0, warmstart_factor=0.0)
    cached = physics.lift_test(None, POSE, GOOD, V, F, density=400.0, friction_direction_caching=True)
    assert cold.displacement != base.displacement and cached.displacement != base.displacement
    rest = physics.lift_test(None, POSE, OPEN, V, F, density=400.0)
    for kw in ({"warmstart_factor": 0.0}, {"friction_direction_caching": True}):
        r = physics.lift_test(None, POSE, OPEN, V, F, density=400.0, **kw)
        assert r.lifted == rest.lifted and r.height_gain == pytest.approx(rest.height_gain, abs=1e-6)
    for bad in (-0.1, 1.5, float("nan")):
        with pytest.raises(ValueError, match="warmstart_factor"):
            physics.lift_test(None, POSE, OPEN, V, F, warmstart_factor=bad)


def test_options_and_shapes():
    assert physics.make_options(shape="decomposition").shape == "decomposition"
    o = physics.make_options(mu=0.3, shape="tetrahedra", table=False)
    assert (o.mu, o.shape, o.table) == (0.3, "tetrahedra", False)
    with pytest.raises(ValueError, match="not_an_option"):
        physics.make_options(not_an_option=1)
    with pytest.raises(ValueError, match="shape"):
        physics.make_options(shape="sphere")


@pytest.mark.parametrize("args, match", [
    (dict(hand_pose=np.eye(3)), "hand_pose"),
    (dict(hand_pose=np.full((4, 4), np.nan)), "hand_pose"),
    (dict(joints=np.zeros(3)), "joints"),
    (dict(joints=np.full(7, np.nan)), "joints"),
    (dict(hand="/nonexistent/hand.json"), "hand"),
    (dict(faces=F + 100), "object"),
    (dict(vertices=V[:, :2]), "object vertices"),
    (dict(density=-1.0), "density"),
])
def test_bad_input_raises_value_error(args, match):
    kw = dict(hand=None, hand_pose=POSE, joints=OPEN, vertices=V, faces=F)
    kw.update(args)
    with pytest.raises(ValueError, match=match):
        physics.lift_test(**kw)


def test_bad_hand_type_and_batch_shapes():
    with pytest.raises(TypeError, match="hand"):
        physics.lift_test(42, POSE, OPEN, V, F)
    t = physics.LiftTester(None, V, F)
    with pytest.raises(ValueError, match="hand_poses"):
        t.run_batch(np.eye(4), OPEN[None])
    with pytest.raises(ValueError, match="joints"):
        t.run_batch(np.stack([POSE, POSE]), OPEN[None])


# ---- concave objects: the convex decomposition ------------------------------------------------

def _in_any_piece(pieces, pt):
    from scipy.spatial import Delaunay
    return any(Delaunay(p).find_simplex(np.asarray(pt)) >= 0 for p in pieces)


@pytest.fixture(scope="module")
def mug():
    """The built-in mug in its object frame (centred on its xy bounding box: body centre at
    x = -0.0175, radius 4 cm; handle on +x out to x = 0.0575) and its CoACD pieces (computed
    once, then read from the cache)."""
    from bayesgrasp.objects import Scene
    s = Scene()
    o = s.canonical_object(s.add_object("mug", 0.0, 0.0, 0.0))
    return o, physics.convex_decomposition(o.vertices, o.faces)


def test_mug_decomposition_is_convex_covers_the_mug_and_keeps_its_concavities(mug):
    import trimesh
    o, pieces = mug
    assert 5 <= len(pieces) <= 60
    hulls = [trimesh.Trimesh(p).convex_hull for p in pieces]
    assert all(h.volume > 0 for h in hulls)
    # Convex: every piece's points are on its hull (none inside, no dent).
    for p, h in zip(pieces, hulls):
        faces_n = h.face_normals
        off = np.einsum("ij,ij->i", faces_n, h.triangles[:, 0])
        gap = np.min(off[None, :] - p @ faces_n.T, axis=1)  # distance inside the hull, per point
        assert np.all(gap < 1e-7)
    m = trimesh.Trimesh(o.vertices, o.faces)
    union = trimesh.boolean.union(hulls, engine="manifold")
    inside = trimesh.boolean.intersection([union, m], engine="manifold").volume
    assert inside / m.volume > 0.97  # the pieces cover the mug's volume
    assert (union.volume - inside) / m.volume < 0.3  # and add little outside it (hull bulges)
    # The opening and the handle's hole stay open.
    assert not _in_any_piece(pieces, (-0.0175, 0.0, 0.06))
    assert not _in_any_piece(pieces, (-0.0175, 0.0, 0.03))
    assert not _in_any_piece(pieces, (0.035, 0.0, 0.0475))
    assert _in_any_piece(pieces, (-0.0175 + 0.038, 0.0, 0.05))  # in the wall


def test_decomposition_cache(tmp_path):
    # An L-shaped block (two boxes sharing a face): concave, decomposed in well under a second.
    L = np.array([[0, 0, 0], [0.06, 0, 0], [0.06, 0.02, 0], [0.02, 0.02, 0], [0.02, 0.06, 0], [0, 0.06, 0]], float)
    Vs = np.vstack([L, L + [0, 0, 0.02]])
    n = 6
    F = [[0, 2, 1], [0, 3, 2], [0, 5, 3], [3, 5, 4]]
    F += [[n + a, n + c, n + b] for a, b, c in F]
    for i in range(n):
        j = (i + 1) % n
        F += [[i, j, n + j], [i, n + j, n + i]]
    F = np.array(F)
    p1 = physics.convex_decomposition(Vs, F, cache_dir=tmp_path)
    files = list(tmp_path.glob("*.npz"))
    assert len(files) == 1
    with np.load(files[0], allow_pickle=False) as z:  # plain arrays, no pickle
        assert int(z["count"]) == len(p1)
    p2 = physics.convex_decomposition(Vs, F, cache_dir=tmp_path)
    assert len(p2) == len(p1) and all(np.array_equal(a, b) for a, b in zip(p1, p2))
    physics.convex_decomposition(Vs * 1.1, F, cache_dir=tmp_path)  # another mesh, another entry
    assert len(list(tmp_path.glob("*.npz"))) == 2
    assert physics.is_concave(Vs, F)


def test_decomposed_mug_gives_the_tetrahedra_verdicts_when_the_hand_reaches_into_it():
    # Two top grasps of the bench grid (bench/bench_physics_concave.py) over the mug's opening,
    # where a finger starts inside the mug's hull (Auto needs a concave shape): 1.1 cm from
    # the body's axis away from the handle, yaw 90 deg - both shapes lift it; 2.6 cm from it,
    # y -1.3 cm, yaw 45 deg - both drop it.
    from bayesgrasp.world import World
    w = World.single("mug")
    lo, hi = w.object.vertices.min(0), w.object.vertices.max(0)
    xs, ys = np.linspace(lo[0], hi[0], 9), np.linspace(lo[1], hi[1], 7)
    CONCAVE_GRASPS = [[xs[2], ys[3], np.pi / 2], [xs[1], ys[2], np.pi / 4]]
    CONCAVE_LIFTED = [True, False]
    dec = w.lift_tester()
    assert dec.shape == "decomposition" and dec.concave and dec.num_pieces > 0
    tets = physics.LiftTester(None, w.vertices, w.faces, shape="tetrahedra", mu=w.mu, density=w.object.density)
    b = w.grasp_batch(CONCAVE_GRASPS, threads=1)
    assert not np.any(b.collision_at_start)
    rd = dec.run_batch(b.hand_pose, b.joint_angles)
    rt = tets.run_batch(b.hand_pose, b.joint_angles)
    assert rd.shape == ["decomposition"] * len(CONCAVE_GRASPS)  # the hand reaches into the hull
    assert rd.lifted.tolist() == rt.lifted.tolist() == CONCAVE_LIFTED
    assert abs(rd.displacement[0] - rt.displacement[0]) < 5e-3
    # Skipping the narrowphase for pairs proven apart (the default) changes nothing.
    obj, T = w.object, w.scene.object_pose(w.object_index)
    pieces = [p @ T[:3, :3].T + T[:3, 3] for p in physics.convex_decomposition(obj.vertices, obj.faces)]
    off = physics.LiftTester(None, w.vertices, w.faces, convex_pieces=pieces, mu=w.mu, density=w.object.density,
                             skip_separated_pairs=False)
    ro = off.run_batch(b.hand_pose, b.joint_angles)
    assert rd.skipped_queries.sum() > 0 and ro.skipped_queries.sum() == 0
    assert ro.displacement.tolist() == rd.displacement.tolist()
    assert ro.rotation.tolist() == rd.rotation.tolist()


def test_decomposition_bad_input():
    with pytest.raises(ValueError, match="convex_pieces"):
        physics.LiftTester(None, V, F, convex_pieces="pieces")
    with pytest.raises(ValueError, match=r"convex_pieces\[0\]"):
        physics.LiftTester(None, V, F, shape="decomposition", convex_pieces=[np.zeros((3, 3))])
    with pytest.raises(ValueError, match=r"convex_pieces\[1\]"):
        physics.LiftTester(None, V, F, shape="decomposition", convex_pieces=[V, np.full((4, 3), np.nan)])
    with pytest.raises(ValueError, match=r"convex_pieces\[0\]"):
        physics.LiftTester(None, V, F, shape="decomposition", convex_pieces=[np.zeros((5, 2))])
    with pytest.raises(ValueError, match="vertices"):
        physics.convex_decomposition(V[:, :2], F)
    with pytest.raises(ValueError, match="faces"):
        physics.convex_decomposition(V, F + 100)
    with pytest.raises(ValueError, match="threshold"):
        physics.convex_decomposition(V, F, threshold=0.0)
    assert not physics.is_concave(V, F)


def test_box_as_its_own_single_piece_is_lifted_like_its_hull():
    t = physics.LiftTester(None, V, F, shape="decomposition", convex_pieces=[V], density=400.0)
    assert t.shape == "decomposition" and t.num_pieces == 1 and not t.concave
    r, h = t.run(POSE, GOOD), physics.lift_test(None, POSE, GOOD, V, F, density=400.0, shape="hull")
    assert r.shape == "decomposition" and r.lifted and h.lifted
    assert r.displacement == pytest.approx(h.displacement, abs=1e-3)
    assert not t.run(POSE, OPEN).lifted


def test_side_contacts_hold_a_cylinder_with_friction_in_both_tangent_directions():
    # A centred 60-degree top grasp of the cylinder (epsilon 0.96, mu 2): its fingertip contacts
    # press on the side wall and must hold the weight by friction along the vertical tangent.
    # (With friction along one tangent per contact, Bullet's default, it slides out.)
    from bayesgrasp.world import World
    w = World.single("cylinder", spread=np.radians(60), mu=2.0)
    g = w.grasp(0.0, 0.0, 3 * np.pi / 4)
    assert not g.collision_at_start and g.epsilon > 0.5
    r = w.lift_tester().run_batch(np.asarray([g.hand_pose]), np.asarray([g.joint_angles]))
    assert r.lifted[0], r.displacement[0]
    assert r.displacement[0] < 0.01
    assert r.height_gain[0] > 0.09


# ---- the squeeze model's trace and the options' bounds ------------------------------------------

def test_trace_ends_at_the_results_displacement_and_the_held_box_touches_two_fingers_throughout(tmp_path):
    from bayesgrasp.lift_trace import LiftTrace, plot_lift_trace
    t = physics.LiftTester(None, V, F, density=400.0)
    assert t.run(POSE, GOOD).trace is None  # off by default
    r = t.run(POSE, GOOD, trace_every=6)
    assert r.lifted
    tr = LiftTrace.from_core(r.trace)
    n = r.steps
    assert len(tr.time) == -(-n // 6)  # every 6th step and the last one
    assert tr.time[-1] == pytest.approx(n / 480.0)
    # The displacement is measured between the reference (after the squeeze) and the last pose.
    assert np.linalg.norm(tr.object_pose[-1, :3, 3] - tr.reference_pose[:3, 3]) == pytest.approx(r.displacement, abs=1e-12)
    assert tr.displacement[-1] == pytest.approx(r.displacement, abs=1e-12)
    assert tr.joints.shape == (len(tr.time), 7) and tr.driven.shape == (len(tr.time), 3)
    # Contacts on at least two fingers at every sample (links per finger from the hand).
    from bayesgrasp.hand import Hand
    h = Hand.load("barrett_bh8")
    assert list(tr.link_names) == h.links
    fingers = [list(l) for l in h.phalanx_links]
    assert np.all(tr.fingers_in_contact(fingers) >= 2)
    assert np.all(tr.contact_force >= 0) and tr.contact_force.max() > 0.1
    assert np.allclose(np.linalg.norm(tr.contact_normal, axis=1), 1.0, atol=1e-6)
    np.testing.assert_allclose(tr.phase_ends, [0.15, 0.55, 1.05])
    plot_lift_trace(tr, tmp_path / "trace.png")
    assert (tmp_path / "trace.png").stat().st_size > 1000
    with pytest.raises(ValueError, match="trace_every"):
        t.run(POSE, GOOD, trace_every=-1)


def test_breakaway_state_is_reported():
    r = physics.lift_test(None, POSE, GOOD, V, F, density=400.0)
    assert r.breakaway.shape == (3,) and set(r.breakaway.tolist()) <= {0, 1}


@pytest.mark.parametrize("opts, match", [
    (dict(squeeze_time=5e6), "squeeze_time"),  # used to overflow the step count: lifted with 0 steps
    (dict(time_step=1e-9), "time_step"),        # used to run for minutes
])
def test_step_count_is_bounded(opts, match):
    with pytest.raises(ValueError, match=match):
        physics.LiftTester(None, V, F, **opts)


def test_centred_top_grasps_hold_the_cube_with_three_fingers_in_contact_throughout():
    # The 6 cm cube grasped from above at its centre (yaw 0 and 45 deg, force closure): held,
    # every finger touching it at every traced step of the squeeze, lift, shake and hold.
    from bayesgrasp.lift_trace import LiftTrace
    from bayesgrasp.world import World
    w = World.single("cube")
    fingers = [list(l) for l in w.hand.phalanx_links]
    for yaw in (0.0, np.pi / 4):
        g = w.grasp(0.0, 0.0, yaw)
        assert g.epsilon > 0
        r = w.lift_tester().run(g.hand_pose, g.joint_angles, trace_every=4)
        assert r.lifted and r.displacement < 0.005
        tr = LiftTrace.from_core(r.trace)
        assert np.all(tr.fingers_in_contact(fingers) >= 2)
        assert tr.displacement[-1] == pytest.approx(r.displacement, abs=1e-12)


def test_a_concave_objects_decomposition_waits_for_a_grasp_that_needs_it():
    # The mug: a grasp around its body stays outside its hull (no decomposition made); one over
    # the opening reaches in (made then). The verdicts equal those of a tester given the pieces.
    from bayesgrasp.world import World
    w = World.single("mug")
    lo, hi = w.object.vertices.min(0), w.object.vertices.max(0)
    xs, ys = np.linspace(lo[0], hi[0], 9), np.linspace(lo[1], hi[1], 7)
    b = w.grasp_batch([[-0.0175, 0.0, 0.0], [xs[2], ys[3], np.pi / 2]], threads=1)
    made = []
    obj, T = w.object, w.scene.object_pose(w.object_index)

    def pieces():
        made.append(1)
        return [p @ T[:3, :3].T + T[:3, 3] for p in physics.convex_decomposition(obj.vertices, obj.faces)]
    lazy = physics.LiftTester(None, w.vertices, w.faces, convex_pieces=pieces, mu=w.mu, density=w.object.density)
    assert lazy.shapes(b.hand_pose, b.joint_angles) == ["hull", "decomposition"] and not made
    r0 = lazy.run(b.hand_pose[0], b.joint_angles[0])
    assert r0.shape == "hull" and not made
    rb = lazy.run_batch(b.hand_pose, b.joint_angles)
    assert made == [1] and rb.shape == ["hull", "decomposition"]
    eager = physics.LiftTester(None, w.vertices, w.faces, convex_pieces=pieces(), mu=w.mu, density=w.object.density)
    re = eager.run_batch(b.hand_pose, b.joint_angles)
    assert rb.lifted.tolist() == re.lifted.tolist()
    np.testing.assert_array_equal(rb.displacement, re.displacement)
    assert r0.displacement == re.displacement[0] and lazy.num_pieces == eager.num_pieces


def test_a_long_decomposition_says_it_is_still_working(monkeypatch):
    """CoACD on a large mesh says nothing for minutes: a line comes every PROGRESS_EVERY seconds
    while it runs, and its pieces come back as float64 arrays."""
    import time

    import coacd

    from bayesgrasp import decomposition

    def slow(mesh, **kw):
        time.sleep(0.35)
        return [(np.zeros((4, 3), np.float32), np.zeros((4, 3), np.int32))]

    monkeypatch.setattr(coacd, "run_coacd", slow)
    monkeypatch.setattr(decomposition, "PROGRESS_EVERY", 0.05)
    said = []
    V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], float)
    F = np.array([[0, 1, 2], [0, 1, 3], [0, 2, 3], [1, 2, 3]])
    pieces = decomposition._run_coacd(V, F, 0.05, 0, {}, said.append, "'box'")
    assert [p.dtype for p in pieces] == [np.float64] and pieces[0].shape == (4, 3)
    beats = [m for m in said if m.startswith("  decomposing 'box' for the lift test: ") and m.endswith(" s so far")]
    assert len(beats) >= 3, said
