"""Grasp quality from Python: hand-derived epsilon/volume, batches, bad input."""
import numpy as np
import pytest

from bayesgrasp import quality


def _twelve_contacts(a, b):
    """Two frictionless contacts per cube face (see tests/cpp/test_quality.cpp)."""
    P, N = [], []
    for s in (1, -1):
        for t in (1, -1):
            P += [(s * a, 0, t * b), (t * b, s * a, 0), (0, t * b, s * a)]
            N += [(s, 0, 0), (0, s, 0), (0, 0, s)]
    return np.array(P, float), np.array(N, float)


def test_twelve_frictionless_contacts_hand_derived():
    # The GWS is the free sum of three rectangles [-1,1] x [-beta,beta] in orthogonal
    # planes: epsilon = min(1, beta)/sqrt(3), volume = 2!2!2!/6! (4 beta)^3.
    a, b = 0.05, 0.02
    P, N = _twelve_contacts(a, b)
    rho = a * np.sqrt(3)
    beta = b / rho
    eps, vol = quality.epsilon_volume(P, N, np.zeros(3), rho, mu=0.0)
    assert eps == pytest.approx(beta / np.sqrt(3), abs=1e-9)
    assert vol == pytest.approx(512 * beta**3 / 720, rel=1e-9)


def test_face_centre_grasp_with_friction_hand_derived():
    # Six face-centre contacts, 4-edge cones: gamma = a mu / rho,
    # epsilon = min(gamma/sqrt(3), gamma/sqrt(1 + gamma^2)); frictionless: 0.
    a = 0.05
    P = np.array([[a, 0, 0], [-a, 0, 0], [0, a, 0], [0, -a, 0], [0, 0, a], [0, 0, -a]])
    N = P / a
    assert quality.epsilon_volume(P, N, np.zeros(3), a, mu=0.0) == (0.0, 0.0)
    for mu in (0.3, 0.8):
        g = mu
        eps, vol = quality.epsilon_volume(P, N, np.zeros(3), a, mu=mu, n_edges=4)
        assert eps == pytest.approx(min(g / np.sqrt(3), g / np.sqrt(1 + g * g)), abs=1e-9)
        assert vol > 0


def test_wrenches_have_unit_normal_force_and_scaled_torque():
    W = quality.contact_wrenches([[0.1, 0, 0]], [[1, 0, 0]], [0, 0, 0], 0.2, mu=0.5, n_edges=8)
    assert W.shape == (8, 6)
    np.testing.assert_allclose(W[:, 0], -1.0)  # unit inward normal component
    np.testing.assert_allclose(np.linalg.norm(W[:, 1:3], axis=1), 0.5)  # mu tangential
    # torque = (p - com) x f / scale, p = (0.1, 0, 0): tau = (0, -0.1 f_z, 0.1 f_y) / 0.2
    np.testing.assert_allclose(W[:, 3:], np.c_[np.zeros(8), -0.5 * W[:, 2], 0.5 * W[:, 1]], atol=1e-15)


def test_no_force_closure_is_not_an_error():
    eps, vol = quality.epsilon_volume([[0.05, 0, 0]], [[1, 0, 0]], np.zeros(3), 0.05, mu=0.0)
    assert eps <= 0 and vol == 0
    eps, vol = quality.epsilon_volume(np.zeros((0, 3)), np.zeros((0, 3)), np.zeros(3), 0.05)
    assert (eps, vol) == (0.0, 0.0)
    # Antipodal pair with friction: no torque about the grasp axis.
    eps, vol = quality.epsilon_volume([[0.03, 0, 0], [-0.03, 0, 0]], [[1, 0, 0], [-1, 0, 0]], np.zeros(3), 0.05)
    assert (eps, vol) == (0.0, 0.0)


def test_batch_equals_one_by_one_and_accepts_both_layouts():
    rng = np.random.default_rng(3)
    axes = np.array([0.04, 0.03, 0.02])
    Ps, Ns = [], []
    for k in [0, 1, 3, 4, 5, 6, 4, 5]:
        u = rng.normal(size=(k, 3))
        u /= np.linalg.norm(u, axis=1, keepdims=True) if k else 1
        p = u * axes
        n = p / axes**2
        Ps.append(p)
        Ns.append(n)
    eps, vol = quality.epsilon_volume_batch(Ps, Ns, np.zeros(3), 0.04, threads=2)
    for i, (p, n) in enumerate(zip(Ps, Ns)):
        assert (eps[i], vol[i]) == quality.epsilon_volume(p, n, np.zeros(3), 0.04)
    eps2, vol2 = quality.epsilon_volume_batch(np.concatenate(Ps), np.concatenate(Ns), np.zeros(3), 0.04,
                                              counts=[len(p) for p in Ps])
    np.testing.assert_array_equal(eps, eps2)
    np.testing.assert_array_equal(vol, vol2)
    assert (eps > 0).any() and (eps <= 0).any()


@pytest.mark.parametrize("kwargs, match", [
    (dict(points=np.zeros((2, 2))), "points"),
    (dict(normals=np.zeros((3, 3))), "points and normals"),
    (dict(normals=np.zeros((2, 3))), "normals: row 0 is zero"),
    (dict(points=np.full((2, 3), np.nan)), "points: contains NaN"),
    (dict(com=np.zeros(2)), "com"),
    (dict(torque_scale=0.0), "torque_scale"),
    (dict(mu=-1.0), "mu"),
    (dict(n_edges=2), "n_edges"),
])
def test_bad_input_raises_value_error_naming_the_argument(kwargs, match):
    args = dict(points=np.ones((2, 3)), normals=np.ones((2, 3)), com=np.zeros(3), torque_scale=0.05)
    args.update(kwargs)
    with pytest.raises(ValueError, match=match):
        quality.epsilon_volume(**args)


def test_batch_bad_counts():
    P = np.ones((3, 3))
    with pytest.raises(ValueError, match="counts"):
        quality.epsilon_volume_batch(P, P, np.zeros(3), 0.05, counts=[1, 1])
    with pytest.raises(ValueError, match="counts"):
        quality.epsilon_volume_batch(P, P, np.zeros(3), 0.05, counts=[4, -1])


def test_batch_threads_zero_is_all_cores_and_negative_is_rejected():
    rng = np.random.default_rng(5)
    Ps = [rng.normal(size=(5, 3)) for _ in range(6)]
    Ns = [p / np.linalg.norm(p, axis=1, keepdims=True) for p in Ps]
    Ps = [0.04 * n for n in Ns]
    all_cores = quality.epsilon_volume_batch(Ps, Ns, np.zeros(3), 0.04, threads=0)
    one = quality.epsilon_volume_batch(Ps, Ns, np.zeros(3), 0.04, threads=1)
    np.testing.assert_array_equal(all_cores[0], one[0])
    np.testing.assert_array_equal(all_cores[1], one[1])
    with pytest.raises(ValueError, match="threads"):
        quality.epsilon_volume_batch(Ps, Ns, np.zeros(3), 0.04, threads=-1)
