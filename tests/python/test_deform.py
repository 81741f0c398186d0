"""The non-rigid warp (vision.deform, Coherent Point Drift in the core) on oracles that follow
from the construction: a training mug warped onto a scaled or a stretched copy of itself
recovers the scale, follows each vertex, and its part labels land on the copy's same parts."""
import numpy as np
import pytest

from bayesgrasp.objects import load_object
from bayesgrasp.vision import CpdOptions, coherent_point_drift, model_samples, warp_mesh
from bayesgrasp.vision.deform import cpd_options


def placed(yaw=0.4, t=(0.05, -0.02, 0.0)):
    T = np.eye(4)
    c, s = np.cos(yaw), np.sin(yaw)
    T[:2, :2] = [[c, -s], [s, c]]
    T[:3, 3] = t
    return T


def _cloud_of(V, F, T, n=1500, seed=1):
    P, _ = model_samples((V, F), samples=n, seed=seed)
    return P @ T[:3, :3].T + T[:3, 3]


def test_a_mug_warped_onto_its_scaled_copy_recovers_the_scale_within_2_percent():
    mug = load_object("mug/0")
    V, F = mug.vertices, mug.faces
    c = V.mean(axis=0)
    T = placed()
    cloud = _cloud_of(c + 1.1 * (V - c), F, T)            # the copy, placed where the registration put the model
    w = warp_mesh(mug, T, cloud)
    scale = np.linalg.norm(w.vertices - w.vertices.mean(0), axis=1).mean() / np.linalg.norm(V - V.mean(0), axis=1).mean()
    assert scale == pytest.approx(1.1, abs=0.022)
    np.testing.assert_allclose(w.vertices.std(axis=0) / V.std(axis=0), 1.1, atol=0.03)      # each axis
    assert np.median(np.linalg.norm(w.vertices - (c + 1.1 * (V - c)), axis=1)) < 0.004      # each vertex, 4 mm
    assert w.result.converged and w.faces is not None and np.array_equal(w.faces, F)


def test_a_stretch_is_followed_vertex_by_vertex_and_the_labels_land_on_the_same_parts():
    """The handle (on +x) moves out with a 25% stretch along x: the warped vertices lie on the
    stretched copy's surface, and the warped model's handle triangles are nearest to the copy's
    handle triangles (the rigid fit alone leaves 15% of them nearest to the body)."""
    mug = load_object("mug/2")
    V, F = mug.vertices, mug.faces
    S = V * [1.25, 1.0, 1.0]
    T = placed(-1.0, (0.0, 0.03, 0.0))
    w = warp_mesh(mug, T, _cloud_of(S, F, T, n=2000))
    # each warped vertex lies on the stretched surface (CPD matches surfaces: a vertex may slide along it)
    from scipy.spatial import cKDTree

    surface = cKDTree(model_samples((S, F), samples=30000, seed=3)[0])
    after, before = surface.query(w.vertices)[0], surface.query(V)[0]
    assert np.median(after) < 0.0015 and np.percentile(after, 90) < 0.5 * np.percentile(before, 90)
    handle = mug.part_names.index("handle")
    Cw, Cs = w.vertices[F].mean(axis=1), S[F].mean(axis=1)
    mine = np.flatnonzero(mug.parts == handle)
    nearest = np.argmin(((Cw[mine, None, :] - Cs[None, :, :]) ** 2).sum(-1), axis=1)
    assert np.mean(mug.parts[nearest] == handle) > 0.95
    # without the warp (the rigid fit alone) the handle's triangles fall short of the stretched handle
    nearest0 = np.argmin(((V[F].mean(axis=1)[mine, None, :] - Cs[None, :, :]) ** 2).sum(-1), axis=1)
    assert np.mean(mug.parts[nearest0] == handle) < np.mean(mug.parts[nearest] == handle)


def test_points_warp_like_the_mesh_and_a_partial_view_moves_the_hidden_side():
    mug = load_object("mug/0")
    V, F = mug.vertices, mug.faces
    T = placed()
    big = V * 1.1
    cloud = _cloud_of(big, F, T)
    seen = cloud[(cloud - T[:3, 3]) @ T[:3, 0] > 0]          # only the half the camera faces (+x of the model)
    w = warp_mesh(mug, T, seen)
    np.testing.assert_allclose(w.warp_points(V[:50]), w.vertices[:50], atol=1e-12)
    hidden = V[:, 0] < -0.02
    grow = np.linalg.norm(w.vertices[hidden][:, :2], axis=1) / np.linalg.norm(V[hidden][:, :2], axis=1)
    assert np.median(grow) == pytest.approx(1.1, abs=0.06)


def test_options_and_bad_input_are_named():
    assert cpd_options(lam=3.0).lam == 3.0 and cpd_options(beta=1.5).beta == 1.5
    o = CpdOptions()
    cpd_options(o, rank=10)
    assert o.rank == 120                                        # the options given are not changed
    with pytest.raises(ValueError, match="outlier_weight"):
        cpd_options(outlier_weight=1.0)
    with pytest.raises(ValueError, match="nope: not a field of CpdOptions"):
        cpd_options(nope=1)
    P = np.random.default_rng(0).normal(size=(50, 3)) * 0.03
    with pytest.raises(ValueError, match="observed"):
        coherent_point_drift(P, np.zeros((0, 3)))
    with pytest.raises(ValueError, match="model: all its points are in one place"):
        coherent_point_drift(np.zeros((5, 3)), P)
    with pytest.raises(ValueError, match="transform: is not a rigid"):
        warp_mesh(load_object("cube"), np.diag([2.0, 1, 1, 1]), P)
    r = coherent_point_drift(P, P + [0.001, 0, 0], rank=0)
    assert r.field.landmarks.shape == (50, 3) and r.residual < 0.002
