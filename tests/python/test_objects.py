"""Objects: mesh loading, mass properties, the procedural library and bad input."""
import warnings

import numpy as np
import pytest

from bayesgrasp.objects import (DEFAULT_DENSITY, MeshWarning, ObjectModel, boolean_available,
                                builtin, category, list_objects, load_mesh, load_object,
                                mesh_is_watertight, object_params)
from bayesgrasp.objects.primitives import revolve

# ---------------------------------------------------------------------------------------------
# mass properties against analytic values
# ---------------------------------------------------------------------------------------------


def test_cube_mass_properties_are_analytic():
    o = load_object("cube")
    s, rho = 0.06, o.density
    m = rho * s ** 3
    assert o.volume == pytest.approx(s ** 3, rel=1e-12)
    assert o.mass == pytest.approx(m, rel=1e-12)
    np.testing.assert_allclose(o.com, [0, 0, s / 2], atol=1e-15)
    np.testing.assert_allclose(o.inertia, np.eye(3) * m * s ** 2 / 6, rtol=1e-10, atol=1e-15)
    assert o.max_radius_from_com == pytest.approx(np.sqrt(3) * s / 2, rel=1e-12)


def test_cylinder_mass_properties_match_the_polygonal_prism_and_the_true_cylinder():
    """The built-in cylinder is an inscribed regular n-gon prism.

    Prism (circumradius R, height H, theta = 2 pi / n), summing the n triangles (centre, two
    neighbouring vertices): area A = n R^2 sin(theta) / 2, polar area moment
    J = n R^4 sin(theta) (2 + cos(theta)) / 12, in-plane moments J / 2 each (n >= 3 symmetry).
    Then Izz = rho H J and Ixx = Iyy = rho H J / 2 + m H^2 / 12. The relative volume error against
    the true cylinder is 1 - sin(theta) / theta < theta^2 / 6, and Izz's is below theta^2 / 3
    (J's series: pi R^4 / 2 (1 - theta^2 / 3 + ...)).
    """
    o = load_object("cylinder")
    p = object_params("cylinder")
    R, H, n, rho = p["radius"], p["height"], p["segments"], o.density
    th = 2 * np.pi / n
    A = n * R ** 2 * np.sin(th) / 2
    J = n * R ** 4 * np.sin(th) * (2 + np.cos(th)) / 12
    m = rho * A * H
    assert o.volume == pytest.approx(A * H, rel=1e-10)
    np.testing.assert_allclose(o.com, [0, 0, H / 2], atol=1e-12)
    expected = np.diag([rho * H * J / 2 + m * H ** 2 / 12] * 2 + [rho * H * J])
    np.testing.assert_allclose(o.inertia, expected, rtol=1e-9, atol=1e-12)
    # against the true cylinder, within the derived discretisation bound
    V_true = np.pi * R ** 2 * H
    assert 0 < (V_true - o.volume) / V_true < th ** 2 / 6
    Izz_true = rho * V_true * R ** 2 / 2
    assert 0 < (Izz_true - o.inertia[2, 2]) / Izz_true < th ** 2 / 3


def test_revolve_of_a_box_profile_is_the_prism():
    V, F = revolve([[0, 0], [1.0, 0], [1.0, 2.0], [0, 2.0]], 4)
    o = ObjectModel("square", V, F, 1.0)
    # inscribed square of circumradius 1: side sqrt(2), area 2, height 2
    assert o.volume == pytest.approx(4.0, rel=1e-12)


def test_density_scales_mass_only():
    a, b = load_object("mug"), load_object("mug", density=1000.0)
    assert b.volume == pytest.approx(a.volume, rel=1e-12)
    assert b.mass == pytest.approx(1000.0 * a.volume, rel=1e-12)
    np.testing.assert_allclose(b.inertia, a.inertia * 1000.0 / a.density, rtol=1e-10)


# ---------------------------------------------------------------------------------------------
# the library
# ---------------------------------------------------------------------------------------------

ALL = list_objects()


def test_list_has_the_known_set_and_the_categories():
    for name in ["cube", "cylinder", "mug", "mug2", "pitcher"]:
        assert name in ALL
    for cat, n in [("mug", 7), ("bottle", 11), ("hammer", 4), ("knife", 2)]:
        members = category(cat)
        assert len(members) >= n
        assert all(m in ALL for m in members)


@pytest.mark.parametrize("name", ALL)
def test_every_builtin_is_closed_outward_and_deterministic(name):
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no "not watertight" warning
        o = load_object(name)
    assert o.is_watertight and o.mass_method == "mesh"
    assert o.to_trimesh().is_watertight                  # independent check
    assert o.volume > 0
    assert o.to_trimesh().volume == pytest.approx(o.volume, rel=1e-9)   # independent volume
    assert o.vertices.dtype == np.float64 and o.faces.dtype == np.int32
    assert o.vertices.shape[1] == 3 and o.faces.shape[1] == 3
    assert np.all(np.linalg.eigvalsh(o.inertia) > 0)
    # centre of mass inside the bounding box
    lo, hi = o.bounds
    assert np.all(o.com > lo) and np.all(o.com < hi)
    again = load_object(name)
    np.testing.assert_array_equal(again.vertices, o.vertices)
    np.testing.assert_array_equal(again.faces, o.faces)


def _body_radius(o):
    """Largest horizontal radius of the body, measured on the -x side (the handle is on +x)."""
    return -o.vertices[:, 0].min()


def test_the_default_mug_has_about_2000_triangles_and_a_handle():
    o = load_object("mug")
    assert 1400 <= o.n_faces <= 2600
    r = _body_radius(o)
    assert 0.035 <= r <= 0.05
    assert o.extent[2] == pytest.approx(0.095)
    assert o.vertices[:, 0].max() > r + 0.02          # the handle sticks out on +x
    # hollow: the cavity makes it much lighter than a solid of the same outer shape
    assert o.volume < 0.5 * np.pi * r ** 2 * o.extent[2]
    # a real mug weighs 0.2-0.5 kg
    assert 0.2 < o.mass < 0.5


def test_mug2_and_pitcher_differ_from_mug():
    mug, mug2, pitcher = load_object("mug"), load_object("mug2"), load_object("pitcher")
    assert mug2.extent[2] > mug.extent[2]
    # mug2 is tapered: wider at the top than at the bottom
    V = mug2.vertices[mug2.vertices[:, 0] < 0]
    r_low = -V[V[:, 2] < 0.01][:, 0].min()
    r_high = -V[V[:, 2] > mug2.extent[2] - 0.01][:, 0].min()
    assert r_high > r_low + 0.005
    assert pitcher.volume > 2 * mug.volume and pitcher.extent[2] > 0.15


@pytest.mark.parametrize("cat, z_range, r_range", [
    ("mug", (0.08, 0.12), (0.033, 0.056)),
    ("bottle", (0.18, 0.30), (0.030, 0.045)),
])
def test_category_sizes_are_realistic(cat, z_range, r_range):
    for name in category(cat):
        o = load_object(name)
        assert z_range[0] - 1e-9 <= o.extent[2] <= z_range[1] + 1e-9, name
        assert r_range[0] <= _body_radius(o) <= r_range[1] + 1e-9, name


def test_hammers_and_knives_have_realistic_lengths():
    for name in category("hammer"):
        o = load_object(name)
        assert 0.25 - 1e-9 <= o.extent[0] <= 0.35 + 1e-9, name
        assert 0.08 <= o.extent[1] <= 0.14, name          # the head across the handle
        assert 0.2 < o.mass < 1.0, name
    for name in category("knife"):
        o = load_object(name)
        assert 0.2 <= o.extent[0] <= 0.35, name
        assert o.extent[2] < 0.03, name                    # lies flat
        assert 0.02 < o.mass < 0.2, name


@pytest.mark.parametrize("cat", ["mug", "bottle", "hammer", "knife"])
def test_category_members_are_distinct(cat):
    objs = [load_object(n) for n in category(cat)]
    sigs = {(round(o.volume, 12), tuple(np.round(o.extent, 9))) for o in objs}
    assert len(sigs) == len(objs)


def test_members_beyond_the_list_are_reproducible_and_announced():
    import warnings

    from bayesgrasp.objects import NewMemberWarning

    with pytest.warns(NewMemberWarning, match=r"bottle/25: not one of the library's bottle/0 \.\.\. bottle/10"):
        a = load_object("bottle/25")
    with pytest.warns(NewMemberWarning):
        b = load_object("bottle/25")
    np.testing.assert_array_equal(a.vertices, b.vertices)
    assert a.params == object_params("bottle/25")
    with warnings.catch_warnings():
        warnings.simplefilter("error", NewMemberWarning)
        load_object("bottle/10"), load_object("mug/6"), load_object("mug")    # listed: no notice


@pytest.mark.skipif(not boolean_available(), reason="manifold3d not installed")
def test_boolean_and_touching_parts_give_the_same_solid():
    for name in ["mug", "mug2", "hammer/0", "knife/0"]:
        u = builtin(name, use_boolean=True)
        t = builtin(name, use_boolean=False)
        assert len(u.to_trimesh().split(only_watertight=False)) == 1
        assert u.volume == pytest.approx(t.volume, rel=0.02)
        np.testing.assert_allclose(u.com, t.com, atol=1e-3)


def test_touching_parts_fallback_is_watertight_per_component():
    o = builtin("mug", use_boolean=False)
    assert o.is_watertight
    parts = o.to_trimesh().split(only_watertight=False)
    assert len(parts) == 2 and all(p.is_watertight for p in parts)
    # disjoint parts: the total volume is the sum of the parts'
    assert sum(p.volume for p in parts) == pytest.approx(o.volume, rel=1e-9)


# ---------------------------------------------------------------------------------------------
# files: round trips and repairs
# ---------------------------------------------------------------------------------------------


@pytest.mark.parametrize("ext", [".obj", ".stl", ".ply"])
def test_save_load_round_trip(tmp_path, ext):
    o = load_object("mug/2")
    path = o.save(tmp_path / f"mug{ext}")
    back = load_mesh(path, density=o.density)
    assert back.name == "mug"
    assert back.is_watertight
    assert len(back.faces) == len(o.faces)
    assert back.volume == pytest.approx(o.volume, rel=1e-6)
    np.testing.assert_allclose(back.bounds, o.bounds, atol=1e-6)
    np.testing.assert_allclose(back.com, o.com, atol=1e-6)
    # load_object takes paths too
    assert load_object(str(path)).volume == pytest.approx(o.volume, rel=1e-6)


def test_default_density_for_files(tmp_path):
    p = load_object("cube").save(tmp_path / "c.stl")
    o = load_mesh(p)
    assert o.density == DEFAULT_DENSITY
    assert o.mass == pytest.approx(DEFAULT_DENSITY * 0.06 ** 3, rel=1e-6)


def test_inward_wound_mesh_is_flipped(tmp_path):
    c = load_object("cylinder")
    inward = ObjectModel("inward", c.vertices, c.faces[:, ::-1], c.density)
    assert inward.volume < 0                            # the core reports the signed volume
    back = load_mesh(inward.save(tmp_path / "inward.ply"))
    assert back.volume == pytest.approx(c.volume, rel=1e-6)   # PLY stores float32


def test_inconsistent_winding_is_repaired(tmp_path):
    c = load_object("cylinder")
    F = c.faces.copy()
    F[::3] = F[::3, ::-1]                               # every third face flipped
    bad = ObjectModel("mixed", c.vertices, F, c.density)
    back = load_mesh(bad.save(tmp_path / "mixed.obj"), density=c.density)
    assert back.volume == pytest.approx(c.volume, rel=1e-6)
    np.testing.assert_allclose(back.inertia, c.inertia, rtol=1e-5, atol=1e-12)


# ---------------------------------------------------------------------------------------------
# bad input
# ---------------------------------------------------------------------------------------------


def test_missing_file(tmp_path):
    p = tmp_path / "nope.obj"
    with pytest.raises(FileNotFoundError, match="nope.obj"):
        load_mesh(p)
    with pytest.raises(FileNotFoundError, match="nope.obj"):
        load_object(str(p))


def test_unknown_name_lists_the_builtins():
    with pytest.raises(ValueError, match="neither a built-in.*bottle/10"):
        load_object("teapot")
    with pytest.raises(ValueError, match="unknown category"):
        category("teapot")


@pytest.mark.parametrize("fname, content", [
    ("garbage.obj", b"hello world\nthis is not a mesh\n"),
    ("garbage.ply", b"ply\nthis is not a header\n"),
    ("garbage.stl", b"\x00\x01garbage" * 3),
])
def test_file_that_is_not_a_mesh(tmp_path, fname, content):
    p = tmp_path / fname
    p.write_bytes(content)
    with pytest.raises(ValueError, match=fname):
        load_mesh(p)


def test_unsupported_extension(tmp_path):
    p = tmp_path / "mesh.xyz"
    p.write_text("1 2 3\n")
    with pytest.raises(ValueError, match=r"mesh.xyz.*unsupported"):
        load_mesh(p)
    with pytest.raises(ValueError, match="unsupported"):
        load_object("cube").save(tmp_path / "c.step")


def test_mesh_without_faces(tmp_path):
    p = tmp_path / "points.obj"
    p.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\n")
    with pytest.raises(ValueError, match="no faces"):
        load_mesh(p)
    with pytest.raises(ValueError, match="no faces"):
        ObjectModel("empty", np.zeros((3, 3)), np.zeros((0, 3), int))


def test_nan_vertices(tmp_path):
    p = tmp_path / "nan.obj"
    p.write_text("v nan 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n")
    with pytest.raises(ValueError, match="NaN"):
        load_mesh(p)
    V = load_object("cube").vertices.copy()
    V[0, 1] = np.inf
    with pytest.raises(ValueError, match="NaN or infinite"):
        ObjectModel("inf", V, load_object("cube").faces)


def test_wrong_shapes_and_density():
    c = load_object("cube")
    with pytest.raises(ValueError, match=r"vertices.*\(N, 3\)"):
        ObjectModel("x", c.vertices[:, :2], c.faces)
    with pytest.raises(ValueError, match="out of range"):
        ObjectModel("x", c.vertices, c.faces + 100)
    with pytest.raises(ValueError, match="density"):
        ObjectModel("x", c.vertices, c.faces, density=-1.0)


def test_open_mesh_warns_and_weighs_the_solid_it_bounds(tmp_path):
    c = load_object("cube")
    F = c.faces[:-1]                                  # one triangle missing: a hole
    assert not mesh_is_watertight(F)
    p = ObjectModel("open", c.vertices, F, c.density, warn_if_open=False).save(tmp_path / "open.stl")
    with pytest.warns(MeshWarning, match=r"not watertight.*the solid it bounds"):
        o = load_mesh(p)
    assert not o.is_watertight and o.mass_method == "fill"
    # the sampled solid is the cube (jittered-grid sampling: within 1%)
    assert o.volume == pytest.approx(0.06 ** 3, rel=0.01)
    np.testing.assert_allclose(o.com, c.com, atol=1e-3)


def test_a_near_miss_of_a_built_in_name_says_which_was_meant():
    with pytest.raises(ValueError, match=r"'mgu' is neither a built-in object nor an existing file \(did you mean 'mug'\?\)"):
        load_object("mgu")
    with pytest.raises(ValueError, match=r"\(did you mean 'bottle/3'\?\)"):
        load_object("bottel/3")
    with pytest.raises(ValueError) as e:
        load_object("xyzzy")
    assert "did you mean" not in str(e.value)
