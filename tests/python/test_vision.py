"""Vision: camera vs analytic depth, segmentation of two objects, registration of known transforms
(asymmetric and body of revolution), Open3D-like input, bad inputs, determinism, the CLI function."""
import json
import math

import numpy as np
import pytest

from bayesgrasp import vision
from bayesgrasp.vision import Camera, register, rotation_error, segment_table


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
    assert not few.success and "at least" in few.reason
    np.testing.assert_array_equal(few.transform, np.eye(4))
    # A model with no surface fails alone, with its reason.
    flat = (np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0.0]]), np.array([[0, 1, 2]]))
    cam = Camera.looking_at(eye=(0.4, -0.4, 0.4), target=(0.05, 0.05, 0.03))
    cloud = cam.capture([L], seed=1)
    r = register(cloud, [flat, L], viewpoint=cam.eye)
    assert not r[0].success and "no surface" in r[0].reason and r[0].weight == 0
    assert r[1].success
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


def test_register_command_json_and_png(tmp_path, capsys):
    pytest.importorskip("bayesgrasp.objects.library")
    png = tmp_path / "reg.png"
    doc = vision.register_command("cube", "0.05,0.0,0.4", ["cube", "cylinder"], json_out=True, png=str(png))
    printed = json.loads(capsys.readouterr().out)
    assert [m["model"] for m in printed["models"]] == ["cube", "cylinder"]
    for m in printed["models"]:
        assert set(m) >= {"model", "transform", "fitness", "rmse", "weight"}
        assert np.asarray(m["transform"]).shape == (4, 4)
    assert doc["models"][0]["weight"] > doc["models"][1]["weight"]
    assert png.exists() and png.stat().st_size > 1000
    with pytest.raises(ValueError, match="pose"):
        vision.register_command("cube", "1,2", ["cube"])


def test_registrar_reused_across_clouds_equals_one_shot():
    L, cyl = l_block(), cylinder(0.04, 0.12)
    reg = vision.Registrar([cyl, L], names=["cyl", "L"], restarts=6)  # flat faces: search longer
    assert len(reg) == 2 and reg.preparation_time(1) > 0
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
            assert a.delta == b.delta and a.weight == b.weight
            assert a.time_features >= b.time_features - 1e-3  # one shot includes the model's preparation
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
    assert not core.model_info(2)["ok"] and "no surface" in core.model_info(2)["reason"]
