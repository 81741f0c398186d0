"""Table-top scenes: placement rule, poses, world-frame meshes and mass properties, plots."""
import numpy as np
import pytest

from bayesgrasp.objects import ObjectModel, Scene, load_object


def _rz(yaw):
    c, s = np.cos(yaw), np.sin(yaw)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1.0]])


def _shifted(name, shift, yaw=0.0):
    """A built-in moved off its own origin (and turned), as a file from elsewhere would be."""
    o = load_object(name)
    T = np.eye(4)
    T[:3, :3] = _rz(yaw)
    T[:3, 3] = shift
    return o.transformed(T, name=f"{name}-shifted")


def test_default_placement_centres_the_xy_box_and_rests_on_the_table():
    o = _shifted("mug/3", [0.3, -0.2, 0.15], yaw=0.4)
    s = Scene()
    i = s.add_object(o, x=0.1, y=-0.05, yaw=0.0)
    can = s.canonical_object(i)
    lo, hi = can.bounds
    assert lo[2] == pytest.approx(0.0, abs=1e-15)
    np.testing.assert_allclose((lo[:2] + hi[:2]) / 2, [0, 0], atol=1e-15)
    np.testing.assert_allclose(can.vertices, o.vertices + s.object_offset(i), atol=1e-15)
    V, F = s.object_mesh_world(i)
    wlo, whi = V.min(axis=0), V.max(axis=0)
    assert wlo[2] == pytest.approx(0.0, abs=1e-15)
    np.testing.assert_allclose((wlo[:2] + whi[:2]) / 2, [0.1, -0.05], atol=1e-15)
    np.testing.assert_array_equal(F, o.faces)


def test_yaw_turns_about_the_xy_box_centre():
    s = Scene.single("cube", x=-0.2, y=0.3, yaw=0.7)
    V, _ = s.object_mesh_world()
    # a square centred on the pose stays centred on it when turned; min z unchanged
    np.testing.assert_allclose((V.min(0)[:2] + V.max(0)[:2]) / 2, [-0.2, 0.3], atol=1e-15)
    assert V[:, 2].min() == pytest.approx(0.0, abs=1e-15)
    # distances from the vertical through the pose are those in the object frame
    can = s.canonical_object().vertices
    np.testing.assert_allclose(np.linalg.norm(V[:, :2] - [-0.2, 0.3], axis=1),
                               np.linalg.norm(can[:, :2], axis=1), atol=1e-15)
    # the xy half-diagonal of a 6 cm square turned by 0.7 rad: 0.03 (cos 0.7 + sin 0.7)
    half = 0.03 * (np.cos(0.7) + np.sin(0.7))
    np.testing.assert_allclose(V.max(0)[:2] - [-0.2, 0.3], [half, half], atol=1e-15)


def test_world_mesh_is_the_pose_applied_to_the_canonical_mesh():
    s = Scene()
    s.add_object("bottle/2", 0.05, 0.02, -1.1)
    T = s.object_pose(0)
    assert T.shape == (4, 4)
    np.testing.assert_allclose(T[:3, :3], _rz(-1.1), atol=1e-15)
    np.testing.assert_allclose(T[:3, 3], [0.05, 0.02, 0.0])
    V, F = s.object_mesh_world(0)
    assert V.dtype == np.float64 and F.dtype == np.int32
    assert V.flags["C_CONTIGUOUS"] and F.flags["C_CONTIGUOUS"]
    can = s.canonical_object(0).vertices
    np.testing.assert_allclose(V, can @ _rz(-1.1).T + [0.05, 0.02, 0.0], atol=1e-15)


def test_keep_origin_keeps_the_meshs_xy_origin():
    shift = np.array([0.02, 0.03, 0.05])
    o = _shifted("cylinder", shift)
    s = Scene()
    i = s.add_object(o, 0.1, 0.0, np.pi / 2, keep_origin=True)
    can = s.canonical_object(i)
    # only lifted/lowered: the cylinder's base was at z = 0.05
    np.testing.assert_allclose(s.object_offset(i), [0, 0, -0.05], atol=1e-15)
    np.testing.assert_allclose(can.vertices[:, :2], o.vertices[:, :2], atol=1e-15)
    assert can.bounds[0, 2] == pytest.approx(0.0, abs=1e-15)
    # the cylinder's axis, at (0.02, 0.03) in its own frame, turned by 90 degrees about the pose
    mp = s.object_mass_properties_world(i)
    H = 0.12
    np.testing.assert_allclose(mp["com"], [0.1 - 0.03, 0.02, H / 2], atol=1e-12)


def test_world_mass_properties_rotate_the_inertia():
    s = Scene.single("hammer/1", 0.0, 0.0, np.pi / 2)
    can = s.canonical_object()
    mp = s.object_mass_properties_world()
    assert mp["mass"] == pytest.approx(can.mass)
    R = _rz(np.pi / 2)
    np.testing.assert_allclose(mp["inertia"], R @ can.inertia @ R.T, atol=1e-15)
    # a quarter turn swaps the x and y moments
    assert mp["inertia"][0, 0] == pytest.approx(can.inertia[1, 1])
    assert mp["inertia"][1, 1] == pytest.approx(can.inertia[0, 0])


def test_set_pose_moves_only_that_object():
    s = Scene()
    a = s.add_object("cube", 0.0, 0.0, 0.0)
    b = s.add_object("cylinder", 0.2, 0.2, 0.0)
    Vb = s.object_mesh_world(b)[0].copy()
    s.set_pose(a, -0.3, 0.1, 0.2)
    assert s.planar_pose(a) == (-0.3, 0.1, 0.2)
    np.testing.assert_array_equal(s.object_mesh_world(b)[0], Vb)
    assert len(s) == 2


@pytest.mark.parametrize("pose, match", [
    ((np.nan, 0.0, 0.0), "x must be finite"),
    ((0.0, np.inf, 0.0), "y must be finite"),
    ((0.0, 0.0, np.nan), "yaw must be finite"),
    ((0.51, 0.0, 0.0), "outside the table"),
    ((0.0, -0.6, 0.0), "outside the table"),
    (("a", 0.0, 0.0), "three numbers"),
])
def test_bad_poses(pose, match):
    s = Scene()
    with pytest.raises(ValueError, match=match):
        s.add_object("cube", *pose)
    i = s.add_object("cube")
    with pytest.raises(ValueError, match=match):
        s.set_pose(i, *pose)


def test_table_size_and_bad_indices():
    s = Scene(table_size=(2.0, 0.5))
    s.add_object("cube", 0.9, 0.2)                  # fits the 2 m x 0.5 m table
    with pytest.raises(ValueError, match="outside the table"):
        s.add_object("cube", 0.0, 0.3)
    with pytest.raises(ValueError, match="table_size"):
        Scene(table_size=(1.0, -1.0))
    with pytest.raises(ValueError, match="object index"):
        s.object_mesh_world(5)
    V, F = s.table_mesh()
    assert V[:, 2].max() == pytest.approx(0.0)
    np.testing.assert_allclose(V.max(0)[:2] - V.min(0)[:2], [2.0, 0.5])
    tbl = ObjectModel("table", V, F, 1.0)
    assert tbl.is_watertight and tbl.volume == pytest.approx(2.0 * 0.5 * 0.02)


def test_plot_scene_writes_a_png(tmp_path):
    from bayesgrasp import viz

    s = Scene()
    s.add_object("mug", 0.0, 0.0, 0.5)
    s.add_object("knife/0", -0.1, -0.15, 0.3)
    extra = [viz.box_mesh(np.eye(4), [0.01, 0.02, 0.03]) + ("tab:gray",),
             viz.capsule_mesh([0, 0, 0.1], [0.05, 0, 0.15], 0.01) + ("tab:gray",)]
    out = viz.plot_scene(s, tmp_path / "scene.png", extra_meshes=extra)
    data = out.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 10_000
    # the helper meshes are closed and outward-wound (needed for back-face culling)
    for V, F, _ in extra:
        assert ObjectModel("part", V, F, 1.0).volume > 0
