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
    assert r["finite"] and r["lifted"]
    assert r["displacement"] < 0.01
    assert abs(r["height_gain"] - 0.1) <= r["displacement"] + r["squeeze_displacement"] + 1e-9
    r = physics.lift_test(physics.BARRETT_HAND, POSE, OPEN, V, F, density=400.0)
    assert not r["lifted"]
    assert abs(r["height_gain"]) < 2e-3  # still on the table


def test_tester_batch_equals_single_runs():
    t = physics.LiftTester(None, V, F, density=400.0)
    assert t.mass == pytest.approx(400.0 * 0.08 * 0.05 * 0.12)
    assert t.shape == "hull"
    out = t.run_batch(np.stack([POSE, POSE]), np.stack([GOOD, OPEN]), threads=2)
    for i, q in enumerate([GOOD, OPEN]):
        r = t.run(POSE, q)
        assert out["lifted"][i] == r["lifted"]
        assert out["displacement"][i] == r["displacement"]
    assert out["lifted"].tolist() == [True, False]


def test_options_and_shapes():
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
