"""Vision: camera vs analytic depth, segmentation of two objects, registration of known transforms
(asymmetric and body of revolution), Open3D-like input, the option classes and keywords, typed
failures, the shape weights, bad inputs, determinism, the CLI function."""
import math

import numpy as np
import pytest

from bayesgrasp import _core, vision
from bayesgrasp.belief import shape_weights
from bayesgrasp.vision import (Camera, FeatureEstimator, RegistrationOptions, RegistrationStatus, register,
                               registration_options, rotation_error, segment_table)


def prism(poly, h):
    """Prism over a CCW polygon (fan-triangulated from vertex 0; fine for the L below) z in [0, h]."""
    n = len(poly)
    V = np.array([[x, y, 0.0] for x, y in poly] + [[x, y, h] for x, y in poly])
    F = []
    for i in range(1, n - 1):
        F.append([0, i + 1, i])
        F.append([n, n + i, n + i + 1])
    for i in range(n):
        j = (i + 1) % n
        F += [[i, j, n + j], [i, n + j, n + i]]
    return V, np.array(F, dtype=np.int32)


def l_block():
    return prism([(0, 0), (0.12, 0), (0.12, 0.04), (0.04, 0.04), (0.04, 0.10), (0, 0.10)], 0.06)


def cylinder(r, h, n=64):
    return prism([(r * math.cos(2 * math.pi * k / n), r * math.sin(2 * math.pi * k / n)) for k in range(n)], h)


def planar(x, y, yaw):
    c, s = math.cos(yaw), math.sin(yaw)
    return np.array([[c, -s, 0, x], [s, c, 0, y], [0, 0, 1, 0], [0, 0, 0, 1.0]])


def moved(mesh, T):
    V, F = mesh
    return V @ T[:3, :3].T + T[:3, 3], F


def test_plane_depth_matches_analytic():
    cam = Camera.looking_at(eye=(0.2, -0.5, 0.7), target=(0, 0, 0), width=80, height=60, fx=70, fy=70)
    depth, label = cam.render([], table={"z": 0.0, "half_extents": (np.inf, np.inf)}, noise=False)
    v, u = np.mgrid[0:60, 0:80]
    d = np.stack([(u - cam.cx) / cam.fx, (v - cam.cy) / cam.fy, np.ones_like(u, float)], -1) @ cam.pose[:3, :3].T
    z = np.where(d[..., 2] < 0, -0.7 / d[..., 2], np.nan)
    np.testing.assert_allclose(depth, z, rtol=1e-9)
    assert (label[np.isfinite(z)] == -2).all()
    P = cam.points(depth)
    assert np.abs(P[:, 2]).max() < 1e-9


def test_sphere_depth_matches_analytic():
    import trimesh

    c, r = np.array([0.0, 0.05, 0.1]), 0.1
    s = trimesh.creation.icosphere(subdivisions=5, radius=r)
    eye = np.array([0.4, -0.5, 0.5])
    cam = Camera.looking_at(eye=eye, target=c, width=160, height=120, fx=160, fy=160)
    depth, _ = cam.render([(np.asarray(s.vertices) + c, np.asarray(s.faces))], noise=False)
    v, u = np.mgrid[0:120, 0:160]
    d = np.stack([(u - cam.cx) / cam.fx, (v - cam.cy) / cam.fy, np.ones_like(u, float)], -1) @ cam.pose[:3, :3].T
    A = (d * d).sum(-1)
    B = 2 * d @ (eye - c)
    C = (eye - c) @ (eye - c) - r * r
    q = B * B / (4 * A) - C  # r^2 - (distance of the ray from the centre)^2
    inner = q > (1 - 0.9 ** 2) * r * r
    t = (-B / 2 - np.sqrt(np.where(q > 0, q * A, 0))) / A
    assert inner.sum() > 1000
    # icosphere level 5: chord sag ~ r * 1e-3
    assert np.abs(depth[inner] - t[inner]).max() < 3e-4
    assert np.isnan(depth[q < 0]).all()


def test_noise_is_seeded_and_sized():
    cam = Camera.looking_at(eye=(0, 0, 1.2), target=(0, 0.001, 0), up=(0, 1, 0), width=64, height=48)
    a, _ = cam.render([], table={"half_extents": (np.inf, np.inf)}, seed=3)
    b, _ = cam.render([], table={"half_extents": (np.inf, np.inf)}, seed=3)
    c, _ = cam.render([], table={"half_extents": (np.inf, np.inf)}, seed=4)
    np.testing.assert_array_equal(a, b)
    assert not np.array_equal(a, c)
    sigma = 0.0012 + 0.0019 * 0.8 ** 2
    assert abs(np.nanstd(a) - math.hypot(sigma, 1.2 ** 2 * 0.125 / (525 * 0.075) / math.sqrt(12))) < 0.3 * sigma


def test_segmentation_finds_two_objects():
    cam = Camera.looking_at(eye=(0.0, -0.8, 0.6), target=(0, 0, 0.05))
    a = moved(cylinder(0.035, 0.15), planar(0.12, 0.0, 0.0))
    b = moved(l_block(), planar(-0.15, 0.05, 1.0))
    cloud = cam.capture([a, b], table=True, seed=1, organised=True)
    assert cloud.shape == (480, 640, 3)
    seg = segment_table(cloud)
    assert abs(seg.plane[2] - 1) < 1e-3 and abs(seg.plane[3]) < 2e-3
    assert len(seg.clusters) == 2
    centres = sorted(p.mean(axis=0)[0] for p in seg.cluster_points)
    assert -0.2 < centres[0] < -0.05 and 0.08 < centres[1] < 0.16


@pytest.mark.parametrize("yaw,eye", [(0.7, (0.4, -0.6, 0.55)), (2.5, (-0.5, -0.5, 0.6)), (-2.0, (0.1, 0.7, 0.5))])
def test_register_recovers_asymmetric_block(yaw, eye):
    L = l_block()
    T = planar(0.03, -0.02, yaw)
    V, F = moved(L, T)
    cam = Camera.looking_at(eye=eye, target=V.mean(axis=0))
    cloud = cam.capture([(V, F)], seed=2)
    res = register(cloud, [L], viewpoint=cam.eye, seed=1)[0]
    assert res.success, res.reason
    assert math.degrees(rotation_error(res.transform[:3, :3], T[:3, :3])) < 5
    assert np.linalg.norm(res.transform[:3, 3] - T[:3, 3]) < 0.005
    assert res.fitness > 0.9


def test_register_body_of_revolution_symmetry_aware():
    cyl = cylinder(0.04, 0.12)
    T = planar(-0.02, 0.04, 1.1)
    V, F = moved(cyl, T)
    cam = Camera.looking_at(eye=(0.5, 0.3, 0.5), target=V.mean(axis=0))
    res = register(cam.capture([(V, F)], seed=5), [cyl], viewpoint=cam.eye)[0]
    assert res.success, res.reason
    assert math.degrees(rotation_error(res.transform[:3, :3], T[:3, :3], axis=(0, 0, 1))) < 5
    assert np.linalg.norm(res.transform[:3, 3] - T[:3, 3]) < 0.005


def test_register_several_models_weights_and_open3d_like_input():
    L, cyl = l_block(), cylinder(0.04, 0.12)
    T = planar(0.0, 0.0, 0.3)
    V, F = moved(L, T)
    cam = Camera.looking_at(eye=(0.5, -0.4, 0.5), target=V.mean(axis=0))
    cloud = cam.capture([(V, F)], seed=7)

    class FakeO3D:  # duck-typed Open3D cloud
        def __init__(self, p):
            self.points = p

    r = register(FakeO3D(cloud), [cyl, L], viewpoint=cam.eye, names=["cyl", "L"])
    assert [x.model for x in r] == ["cyl", "L"]
    assert r[1].weight > r[0].weight and r[1].delta < r[0].delta
    assert abs(r[0].weight + r[1].weight - 1) < 1e-12
    for x in r:
        assert x.phi == pytest.approx(math.exp(-x.delta ** 2 / (2 * 0.0025 ** 2)))
    again = register(cloud, [cyl, L], viewpoint=cam.eye)
    for a, b in zip(r, again):  # same seed, same result
        np.testing.assert_array_equal(a.transform, b.transform)


def test_no_model_that_fits_is_warned_and_a_fitting_one_is_not():
    """Weights always sum to 1 over the models that registered; when none covers GOOD_FITNESS of
    the cloud (an L-block seen, cylinders and a box offered), a RegistrationWarning names the best."""
    import warnings

    from bayesgrasp.vision import RegistrationWarning
    from bayesgrasp.vision.registration import GOOD_FITNESS

    L = l_block()
    V, F = moved(L, planar(0.0, 0.0, 0.3))
    cam = Camera.looking_at(eye=(0.5, -0.4, 0.5), target=V.mean(axis=0))
    cloud = cam.capture([(V, F)], seed=7)
    with pytest.warns(RegistrationWarning, match="no model fits the cloud well: the best fitness is") as w:
        r = register(cloud, [cylinder(0.01, 0.3), cylinder(0.12, 0.01)], viewpoint=cam.eye, names=["rod", "disc"])
    ok = [x for x in r if x.success]
    assert ok and max(x.fitness for x in ok) < GOOD_FITNESS and sum(x.weight for x in r) == pytest.approx(1.0)
    assert len(w) == 1
    with warnings.catch_warnings():
        warnings.simplefilter("error", RegistrationWarning)
        r = register(cloud, [cylinder(0.04, 0.12), L], viewpoint=cam.eye, names=["cyl", "L"])
    assert r[1].fitness >= GOOD_FITNESS


def test_bad_inputs():
    L = l_block()
    with pytest.raises(ValueError, match="cloud"):
        register(np.zeros((0, 3)), [L])
    with pytest.raises(ValueError, match="cloud"):
        register(np.full((50, 3), np.nan), [L])
    with pytest.raises(ValueError, match="cloud"):
        register(np.full((50, 3), np.inf), [L])
    with pytest.raises(ValueError, match="cloud"):
        register(np.zeros((10, 2)), [L])
    with pytest.raises(ValueError, match="models"):
        register(np.random.default_rng(0).random((100, 3)), [])
    with pytest.raises(ValueError, match="voxel"):
        register(np.random.default_rng(0).random((100, 3)), [L], voxel=-1)
    few = register(np.random.default_rng(0).random((10, 3)) * 0.05, [L])[0]
    assert not few.success and "at least" in few.reason and few.status == RegistrationStatus.TooFewScenePoints
    np.testing.assert_array_equal(few.transform, np.eye(4))
    # A model with no surface fails alone, with its reason.
    flat = (np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0.0]]), np.array([[0, 1, 2]]))
    cam = Camera.looking_at(eye=(0.4, -0.4, 0.4), target=(0.05, 0.05, 0.03))
    cloud = cam.capture([L], seed=1)
    r = register(cloud, [flat, L], viewpoint=cam.eye)
    assert not r[0].success and "no surface" in r[0].reason and r[0].weight == 0
    assert r[0].status == RegistrationStatus.NoSurface
    assert r[1].success and r[1].status == RegistrationStatus.Ok and r[1].weight == 1.0
    # A camera that sees nothing gives an empty cloud, which registration rejects.
    up = Camera.looking_at(eye=(0, 0, 1), target=(0, 0.001, 2), up=(0, 1, 0))
    empty = up.capture([L], table=True)
    assert empty.shape == (0, 3)
    with pytest.raises(ValueError):
        register(empty, [L])
    with pytest.raises(ValueError):
        segment_table(empty)
    with pytest.raises(ValueError, match="pose"):
        Camera(pose=np.eye(3))
    with pytest.raises(ValueError, match="eye"):
        Camera.looking_at(eye=(0, 0, 1), target=(0, 0, 0))  # view parallel to up


def test_registrar_reused_across_clouds_equals_one_shot():
    L, cyl = l_block(), cylinder(0.04, 0.12)
    reg = vision.Registrar([cyl, L], names=["cyl", "L"], restarts=6)  # flat faces: search longer
    assert len(reg) == 2 and reg.options.ransac.restarts == 6
    for k, (yaw, eye, seed) in enumerate([(0.3, (0.5, -0.4, 0.5), 7), (2.0, (-0.4, -0.5, 0.6), 3)]):
        T = planar(0.01 * k, -0.02, yaw)
        V, F = moved(L, T)
        cam = Camera.looking_at(eye=eye, target=V.mean(axis=0))
        cloud = cam.capture([(V, F)], seed=seed)
        once = register(cloud, [cyl, L], viewpoint=cam.eye, seed=seed, names=["cyl", "L"], restarts=6)
        again = reg.register(cloud, viewpoint=cam.eye, seed=seed)
        assert [r.model for r in again] == ["cyl", "L"]
        for a, b in zip(once, again):
            assert a.success == b.success
            np.testing.assert_array_equal(a.transform, b.transform)
            assert a.delta == b.delta and a.phi == b.phi and a.weight == b.weight and a.status == b.status
            for t in (a.time_features, a.time_global, a.time_icp, b.time_features, reg.preparation_time(1)):
                assert math.isfinite(t) and t >= 0
        only = reg.register(cloud, viewpoint=cam.eye, seed=seed, models=["L"])
        assert len(only) == 1 and only[0].model == "L" and only[0].weight == pytest.approx(1.0)
        np.testing.assert_array_equal(only[0].transform, again[1].transform)
        assert math.degrees(rotation_error(again[1].transform[:3, :3], T[:3, :3])) < 5
        assert np.linalg.norm(again[1].transform[:3, 3] - T[:3, 3]) < 0.005
    # By index too.
    assert reg.register(cloud, viewpoint=cam.eye, seed=seed, models=[1])[0].model == "L"


def test_registrar_bad_inputs():
    L = l_block()
    with pytest.raises(ValueError, match="models"):
        vision.Registrar([])
    with pytest.raises(ValueError, match="voxel"):
        vision.Registrar([L], voxel=0)
    with pytest.raises(ValueError, match="seed"):
        vision.Registrar([L], seed=3)
    with pytest.raises(ValueError, match="names"):
        vision.Registrar([L], names=["a", "b"])
    flat = (np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0.0]]), np.array([[0, 1, 2]]))
    reg = vision.Registrar([flat, L], names=["flat", "L"])
    cam = Camera.looking_at(eye=(0.4, -0.4, 0.4), target=(0.05, 0.05, 0.03))
    cloud = cam.capture([L], seed=1)
    r = reg.register(cloud, viewpoint=cam.eye)
    assert not r[0].success and "no surface" in r[0].reason and r[0].weight == 0
    assert r[0].status == RegistrationStatus.NoSurface
    assert r[1].success
    with pytest.raises(ValueError, match="models"):
        reg.register(cloud, models=["mug"])
    with pytest.raises(ValueError, match="models"):
        reg.register(cloud, models=[5])
    with pytest.raises(ValueError, match="models"):
        reg.register(cloud, models=[])
    with pytest.raises(ValueError, match="cloud"):
        reg.register(np.zeros((0, 3)))
    with pytest.raises(ValueError, match="cloud"):
        reg.register(np.full((20, 3), np.nan))
    with pytest.raises(ValueError, match="viewpoint"):
        reg.register(cloud, viewpoint=(0, 0))
    with pytest.raises(ValueError, match="viewpoint"):
        reg.register(cloud, viewpoint=(0, np.nan, 1))
    core = reg._core
    with pytest.raises(ValueError, match="models"):
        core.register(cloud, models=[7])
    with pytest.raises(ValueError, match="cloud"):
        core.register(np.zeros((5, 2)))
    with pytest.raises(ValueError, match=r"models\[0\]"):
        core.add_models([(np.zeros((3, 3)), np.zeros((4, 3)))])
    with pytest.raises(ValueError, match="i"):
        core.model_info(9)
    assert core.add_models([(np.zeros((0, 3)), np.zeros((0, 3)))]) == 2
    info = core.model_info(2)
    assert not info.ok and info.status == RegistrationStatus.NoSurface and "no surface" in info.reason
    assert core.model_info(1).ok and core.model_info(1).points > 100


# ---- options, keywords, typed results, shape weights
def _option_classes():
    V = _core.vision
    return [V.RegistrationOptions, V.FeatureOptions, V.CorrespondenceOptions, V.RansacOptions, V.IcpOptions, V.UpPrior]


def _fields(cls):
    return [n for n, v in vars(cls).items() if isinstance(v, property)]


# A non-default valid value for every field of every option class (nested classes by path).
_NEW_VALUES = {
    "voxel": 0.004, "inlier_distance": 1.7, "weight_sigma": 0.6, "min_scene_points": 25, "model_samples": 5000,
    "threads": 1,
    "features.normal_radius": 2.5, "features.feature_radius": 4.5, "features.estimator": FeatureEstimator.Pcl,
    "correspondences.neighbours": 3, "correspondences.reverse": False, "correspondences.hellinger": False,
    "ransac.iterations": 9000, "ransac.min_iterations": 300, "ransac.confidence": 0.99, "ransac.edge_similarity": 0.8,
    "ransac.max_normal_angle": 0.7, "ransac.restarts": 5, "ransac.candidates": 8, "ransac.hypotheses": 3,
    "icp.distance": 1.2, "icp.iterations": 20, "icp.tolerance": 1e-6, "icp.coarse_points": 150,
    "icp.coarse_iterations": 5,
    "up_prior.enabled": False, "up_prior.upright": False, "up_prior.up": (0.0, 0.1, 1.0), "up_prior.max_tilt": 0.8,
    "up_prior.weight": 2.0,
}


def _get(options, path):
    for p in path.split("."):
        options = getattr(options, p)
    return options


def test_option_classes_document_every_field():
    for cls in _option_classes():
        fields = _fields(cls)
        assert fields, cls
        for f in fields:
            doc = getattr(cls, f).__doc__
            assert doc.startswith(f"{f} : ") and "\n    " in doc, (cls.__name__, f, doc)


def test_every_option_field_is_settable_and_reaches_the_core():
    nested = {"features", "correspondences", "ransac", "icp", "up_prior"}
    paths = [f for f in _fields(RegistrationOptions) if f not in nested]
    for name, cls in [("features", _core.vision.FeatureOptions), ("correspondences", _core.vision.CorrespondenceOptions),
                      ("ransac", _core.vision.RansacOptions), ("icp", _core.vision.IcpOptions),
                      ("up_prior", _core.vision.UpPrior)]:
        paths += [f"{name}.{f}" for f in _fields(cls)]
    assert sorted(paths) == sorted(_NEW_VALUES)  # every field has a test value
    o = RegistrationOptions()
    for path, value in _NEW_VALUES.items():
        *parents, last = path.split(".")
        target = o
        for p in parents:
            target = getattr(target, p)
        assert not np.array_equal(np.asarray(getattr(target, last)), np.asarray(value)), path  # not the default
        setattr(target, last, value)
    reg = vision.Registrar([l_block()], o)  # the C++ registrar holds a copy
    for path, value in _NEW_VALUES.items():
        np.testing.assert_array_equal(np.asarray(_get(reg.options, path)), np.asarray(value), err_msg=path)
    # Keyword construction, copies, repr.
    r = _core.vision.RansacOptions(restarts=7, candidates=4)
    assert (r.restarts, r.candidates, r.iterations) == (7, 4, 20000)
    with pytest.raises(ValueError, match="restart"):
        _core.vision.RansacOptions(restart=7)
    c = o.__copy__()
    c.ransac.restarts = 1
    assert o.ransac.restarts == 5 and "restarts=5" in repr(o)


def test_option_fields_take_effect():
    L = l_block()
    T = planar(0.03, -0.02, 0.7)
    V, F = moved(L, T)
    cam = Camera.looking_at(eye=(0.4, -0.6, 0.55), target=V.mean(axis=0))
    cloud = cam.capture([(V, F)], seed=2)
    base = RegistrationOptions()
    ref = register(cloud, [L], base, viewpoint=cam.eye, seed=1)[0]
    assert ref.success
    o = base.__copy__()
    o.weight_sigma = 1.0  # the same fit, phi with twice the sigma
    r = register(cloud, [L], o, viewpoint=cam.eye, seed=1)[0]
    assert r.delta == ref.delta and r.phi == pytest.approx(math.exp(-ref.delta ** 2 / (2 * 0.005 ** 2)), rel=1e-12)
    o = base.__copy__()
    o.ransac.restarts, o.ransac.iterations, o.ransac.min_iterations = 2, 6, 0
    assert register(cloud, [L], o, viewpoint=cam.eye, seed=1)[0].ransac_iterations <= 12
    o = base.__copy__()
    o.min_scene_points = ref.scene_points + 1
    assert register(cloud, [L], o, viewpoint=cam.eye)[0].status == RegistrationStatus.TooFewScenePoints
    o = base.__copy__()
    o.model_samples = 20  # the Registrar samples meshes with options.model_samples
    assert register(cloud, [L], o, viewpoint=cam.eye)[0].model_points < 20
    o = base.__copy__()
    o.icp.iterations = 0
    assert not np.array_equal(register(cloud, [L], o, viewpoint=cam.eye, seed=1)[0].transform, ref.transform)
    o = base.__copy__()
    o.features.estimator = FeatureEstimator.Pcl
    r = register(cloud, [L], o, viewpoint=cam.eye, seed=1)[0]
    assert r.success and math.degrees(rotation_error(r.transform[:3, :3], T[:3, :3])) < 5


def test_keywords_map_to_fields():
    # A keyword is a field of RegistrationOptions or of exactly one of its steps, named as the
    # bound classes name them (no list of aliases in Python).
    cases = {
        "voxel": (0.004, "voxel", 0.004), "inlier_distance": (2.0, "inlier_distance", 2.0),
        "weight_sigma": (0.7, "weight_sigma", 0.7), "min_scene_points": (12, "min_scene_points", 12),
        "threads": (1, "threads", 1), "normal_radius": (2.5, "features.normal_radius", 2.5),
        "feature_radius": (4.0, "features.feature_radius", 4.0),
        "estimator": (FeatureEstimator.Pcl, "features.estimator", FeatureEstimator.Pcl),
        "neighbours": (3, "correspondences.neighbours", 3),
        "reverse": (False, "correspondences.reverse", False),
        "hellinger": (False, "correspondences.hellinger", False), "restarts": (6, "ransac.restarts", 6),
        "hypotheses": (2, "ransac.hypotheses", 2), "distance": (1.1, "icp.distance", 1.1),
        "up_prior": (False, "up_prior.enabled", False), "upright": (False, "up_prior.upright", False),
        "up": ((0, 0, 2.0), "up_prior.up", (0, 0, 2.0)), "max_tilt": (math.pi / 6, "up_prior.max_tilt", math.pi / 6),
    }
    for kw, (value, path, want) in cases.items():
        got = _get(registration_options(**{kw: value}), path)
        if isinstance(want, FeatureEstimator):
            assert got == want, kw
        else:
            np.testing.assert_allclose(np.asarray(got, float), np.asarray(want, float), rtol=1e-15, err_msg=kw)
    # A field two steps share goes through its step; a step's options object replaces it.
    with pytest.raises(ValueError, match="iterations: a field of ransac and icp"):
        registration_options(iterations=12)
    o = registration_options(icp=_core.vision.IcpOptions(iterations=12))
    assert (o.icp.iterations, o.ransac.iterations) == (12, RegistrationOptions().ransac.iterations)
    # Keywords apply over a given options object, which is not changed.
    o = RegistrationOptions(voxel=0.006)
    k = registration_options(o, restarts=4)
    assert (k.voxel, k.ransac.restarts, o.ransac.restarts) == (0.006, 4, 3)
    with pytest.raises(ValueError, match="bogus"):
        registration_options(bogus=1)
    with pytest.raises(ValueError, match="bogus"):
        register(np.zeros((10, 3)), [l_block()], bogus=1)
    with pytest.raises(ValueError, match="bogus"):
        vision.Registrar([l_block()], bogus=1)
    with pytest.raises(ValueError, match="ransac.confidence"):
        registration_options(RegistrationOptions(ransac=_core.vision.RansacOptions(confidence=2.0)))
    with pytest.raises(ValueError, match="options"):
        registration_options(0.005)
    with pytest.raises(ValueError, match="threads"):
        vision.Registrar([l_block()], threads=-1)
    with pytest.raises(ValueError, match="up_prior.max_tilt"):
        registration_options(max_tilt=0.0)


def test_typed_failures_and_model_info():
    L = l_block()
    cam = Camera.looking_at(eye=(0.4, -0.4, 0.4), target=(0.05, 0.05, 0.03))
    cloud = cam.capture([L], seed=1)
    two = (np.array([[0, 0, 0], [0.1, 0, 0.0]]), np.array([[0, 0, 1], [0, 0, 1.0]]))
    r = register(cloud, [two, L], viewpoint=cam.eye)
    assert r[0].status == RegistrationStatus.TooFewModelPoints and not r[0].success and r[0].weight == 0
    assert r[1].status == RegistrationStatus.Ok and r[1].reason == ""
    # A vertical needle: no pair of its points is 2 voxels apart horizontally, no upright hypothesis.
    z = np.linspace(0, 0.2, 400)
    jitter = np.random.default_rng(3).uniform(-0.0009, 0.0009, (400, 2))
    needle = np.column_stack([0.0025 + jitter, z])
    n = register(needle, [L])[0]
    assert n.status == RegistrationStatus.NoHypothesis and not n.success
    np.testing.assert_array_equal(n.transform, np.eye(4))
    raw = _core.vision.register_models(cloud, [two], _core.vision.RegistrationOptions())[0]
    assert isinstance(raw, _core.vision.RegistrationResult) and raw.status == RegistrationStatus.TooFewModelPoints
    assert raw.transform.shape == (4, 4) and not raw.success
    assert set(RegistrationStatus.__members__) == {"Ok", "NoSurface", "InvalidModel", "TooFewModelPoints",
                                                   "TooFewScenePoints", "NoHypothesis", "NonFiniteTransform"}


def test_shape_weights():
    w = shape_weights([0.5, 0.2, 0.3, 0.9], [True, True, True, False])
    np.testing.assert_allclose(w, [0.5, 0.2, 0.3, 0.0], rtol=1e-15)  # sum of the registered phi is 1
    np.testing.assert_array_equal(shape_weights([0.2, 0.6], [True, True]), np.array([0.2, 0.6]) / 0.8)
    np.testing.assert_array_equal(shape_weights([0.0, 0.0], [True, True]), [0.0, 0.0])  # no evidence: all zero
    np.testing.assert_array_equal(shape_weights([0.7, np.nan], [False, False]), [0.0, 0.0])
    assert shape_weights([], []).shape == (0,)
    with pytest.raises(ValueError, match="phi"):
        shape_weights([0.1, 0.2], [True])
    with pytest.raises(ValueError, match="phi"):
        shape_weights([-0.1, 0.2], [True, True])
    with pytest.raises(ValueError, match="phi"):
        shape_weights([np.inf, 0.2], [True, True])


def test_registration_keywords_are_validated_together():
    """The options are checked once all keywords are set, so their order does not matter: a zero
    `up` is fine once the up prior is off, whichever keyword comes first."""
    for kw in (dict(up=(0.0, 0.0, 0.0), up_prior=False), dict(up_prior=False, up=(0.0, 0.0, 0.0))):
        o = registration_options(**kw)
        assert not o.up_prior.enabled and not np.any(o.up_prior.up)
    with pytest.raises(ValueError, match="up_prior.up"):
        registration_options(up=(0.0, 0.0, 0.0))
    with pytest.raises(ValueError, match="ransac.restarts"):
        registration_options(restarts=2**40)   # does not fit a C++ int: named with its step
