"""Real meshes as they come: open scans' mass properties against an analytic oracle, a weighed
object's mass, label files of a mesh with degenerate triangles, and a decomposition that never
fails (slivers dropped, the hull as the fallback)."""
import json
import warnings

import numpy as np
import pytest
import trimesh

from bayesgrasp import decomposition, physics
from bayesgrasp.objects import ObjectModel, load_mesh, load_object
from bayesgrasp.objects.mass import shell_mass_properties
from bayesgrasp.objects.mesh_io import MeshWarning

N_SIDES = 64
R, r, H, TB = 0.04, 0.035, 0.10, 0.006   # outer / inner radius, height, bottom thickness (m)
RHO = 2000.0


def _polygon_area(radius: float) -> float:
    """Area of the regular N_SIDES-gon trimesh inscribes in a circle of ``radius``."""
    return N_SIDES / 2 * radius ** 2 * np.sin(2 * np.pi / N_SIDES)


def _open_cup() -> trimesh.Trimesh:
    """A hollow cylinder (regular N_SIDES-gon section), open at the top: outer wall, bottom,
    inner floor at TB and inner wall, but no top ring between the radii, so not watertight."""
    t = 2 * np.pi * np.arange(N_SIDES) / N_SIDES
    ring = lambda rad, z: np.column_stack([rad * np.cos(t), rad * np.sin(t), np.full(N_SIDES, z)])  # noqa: E731
    V = np.vstack([ring(R, 0), ring(R, H), ring(r, TB), ring(r, H), [[0, 0, 0]], [[0, 0, TB]]])
    o0, o1, i0, i1, c0, c1 = 0, N_SIDES, 2 * N_SIDES, 3 * N_SIDES, 4 * N_SIDES, 4 * N_SIDES + 1
    F = []
    for k in range(N_SIDES):
        n = (k + 1) % N_SIDES
        F += [[o0 + k, o0 + n, o1 + n], [o0 + k, o1 + n, o1 + k]]      # outer wall, facing out
        F += [[i0 + k, i1 + n, i0 + n], [i0 + k, i1 + k, i1 + n]]      # inner wall, facing the axis
        F += [[c0, o0 + n, o0 + k], [c1, i0 + k, i0 + n]]              # bottom (down), inner floor (up)
    return trimesh.Trimesh(V, np.array(F), process=False)


def test_open_cup_mass_matches_the_analytic_hollow_cylinder():
    cup = _open_cup()
    assert not cup.is_watertight
    with pytest.warns(MeshWarning, match="not watertight.*solid it bounds"):
        o = ObjectModel("cup", cup.vertices, cup.faces, density=RHO)
    assert o.mass_method == "fill"
    wall = (_polygon_area(R) - _polygon_area(r)) * (H - TB)
    bottom = _polygon_area(R) * TB
    m_wall, m_bottom = RHO * wall, RHO * bottom
    assert o.volume == pytest.approx(wall + bottom, rel=0.03)
    assert o.mass == pytest.approx(m_wall + m_bottom, rel=0.03)
    com_z = (m_wall * (TB + (H - TB) / 2) + m_bottom * TB / 2) / (m_wall + m_bottom)
    np.testing.assert_allclose(o.com, [0, 0, com_z], atol=0.02 * H)
    izz = m_wall / 2 * (R ** 2 + r ** 2) + m_bottom / 2 * R ** 2      # about the axis
    assert o.inertia[2, 2] == pytest.approx(izz, rel=0.05)
    # the convex hull (the old fallback) would weigh the whole inside: 3.6x as much
    assert RHO * _polygon_area(R) * H > 3.5 * o.mass


def test_a_sheet_that_encloses_nothing_is_a_thin_shell():
    # a card folded by 2 degrees (two 5 cm squares, one triangle pair each): the fill finds only the
    # sliver under the fold, less than a quarter of the 3 mm shell, so the object is the shell
    s, h = 0.05, 0.05 * np.tan(np.radians(2.0))
    V = np.array([[0, 0, 0], [0, s, 0], [s, 0, h], [s, s, h], [2 * s, 0, 0], [2 * s, s, 0]], float)
    F = np.array([[0, 2, 1], [1, 2, 3], [2, 4, 5], [2, 5, 3]])
    with pytest.warns(MeshWarning, match="3 mm shell"):
        o = ObjectModel("folded card", V, F, density=1000.0)
    assert o.mass_method == "shell"
    assert o.mass == pytest.approx(1000.0 * 0.003 * 2 * s * np.hypot(s, h))   # area x thickness x density
    np.testing.assert_allclose(o.com, [s, s / 2, h / 2], atol=1e-12)


def test_shell_mass_properties_of_two_square_laminae():
    # an L of two 5 cm squares (floor and wall): centre of mass and the inertia about y analytic
    s = 0.05
    V = np.array([[0, 0, 0], [s, 0, 0], [s, s, 0], [0, s, 0], [0, 0, s], [0, s, s]], float)
    F = np.array([[0, 1, 2], [0, 2, 3], [0, 3, 5], [0, 5, 4]])
    p = shell_mass_properties(V, F, 1000.0, thickness=0.002)
    assert p.mass == pytest.approx(1000.0 * 2 * s ** 2 * 0.002)
    np.testing.assert_allclose(p.com, [s / 4, s / 2, s / 4], atol=1e-12)
    # each lamina (mass m) about its own centre: m s^2 / 12 about y; both s^2 / 8 off the common centre in x-z
    m = p.mass / 2
    assert p.inertia[1, 1] == pytest.approx(2 * m * s ** 2 / 12 + 2 * m * s ** 2 / 8)
    assert p.inertia[0, 0] == pytest.approx(p.inertia[2, 2])                    # the L is symmetric in x <-> z


def test_a_one_sheet_open_box_reads_as_the_solid_box():
    # the documented ambiguity: five faces of a box are also a solid box with its lid missing
    s = 0.05
    V = np.array([[0, 0, 0], [s, 0, 0], [s, s, 0], [0, s, 0], [0, 0, s], [s, 0, s], [s, s, s], [0, s, s]], float)
    F = np.array([[0, 2, 1], [0, 3, 2], [0, 1, 5], [0, 5, 4], [1, 2, 6], [1, 6, 5], [2, 3, 7], [2, 7, 6],
                  [3, 0, 4], [3, 4, 7]])
    with pytest.warns(MeshWarning, match="pass mass="):
        o = ObjectModel("tray", V, F, density=1000.0)
    assert o.mass_method == "fill" and o.volume == pytest.approx(s ** 3, rel=0.01)


def test_given_mass_sets_the_density_and_the_lift_test_uses_it(tmp_path):
    p = tmp_path / "cup.stl"
    _open_cup().export(p)
    with warnings.catch_warnings():
        warnings.simplefilter("error", MeshWarning)           # weighed: no warning about its volume
        o = load_mesh(p, mass=0.25)
    assert o.mass == pytest.approx(0.25)
    assert o.density == pytest.approx(0.25 / o.volume)
    with pytest.raises(ValueError, match="mass, density"):
        load_mesh(p, mass=0.25, density=900.0)
    with pytest.raises(ValueError, match="mass must be finite and > 0"):
        o.with_mass(-1.0)
    moved = o.transformed(np.eye(4))
    assert moved.mass == pytest.approx(0.25)
    # the world's lift test weighs what the object weighs (an open convex box: no decomposition)
    from bayesgrasp.world import World

    c = load_object("cube")
    with pytest.warns(MeshWarning):
        box = ObjectModel("open box", c.vertices, c.faces[:-1], c.density)
    w = World.single(box.with_mass(0.3))
    assert w.lift_tester().mass == pytest.approx(0.3)
    assert World.single(box).lift_tester().mass == pytest.approx(c.mass, rel=0.02)


def test_an_open_meshs_mass_properties_follow_it_into_the_world():
    cup = _open_cup()
    with pytest.warns(MeshWarning):
        o = ObjectModel("cup", cup.vertices, cup.faces, density=RHO).with_mass(0.2)
    from bayesgrasp.world import World

    w = World.single(o, pose=(0.1, -0.05, 0.7))
    lt = w.lift_tester()
    placed = w.scene.object_mass_properties_world(0)
    assert lt.mass == pytest.approx(0.2)
    np.testing.assert_allclose(lt.com, placed["com"], atol=1e-12)
    np.testing.assert_allclose(w.com, placed["com"], atol=1e-12)
    # the cup's axis is off the origin of its frame after the placement: the com moved with it
    assert abs(lt.com[0] - 0.1) < 1e-3 and abs(lt.com[1] + 0.05) < 1e-3
    # a rigid copy carries the sampled properties; sampling the moved mesh again agrees (1%)
    T = np.eye(4)
    T[:3, :3] = [[0, -1, 0], [1, 0, 0], [0, 0, 1]]
    T[:3, 3] = [0.02, 0.03, 0.0]
    moved, fresh = o.transformed(T), ObjectModel("cup", o.vertices @ T[:3, :3].T + T[:3, 3], o.faces, o.density,
                                                 warn_if_open=False)
    assert moved.mass == pytest.approx(fresh.mass, rel=0.01)
    np.testing.assert_allclose(moved.com, fresh.com, atol=1e-3)
    np.testing.assert_allclose(moved.inertia, fresh.inertia, atol=0.01 * np.abs(fresh.inertia).max())
    # a scaled copy is a new shape: weighed again at the same density (8x the mass at 2x the size)
    big = o.transformed(np.diag([2.0, 2.0, 2.0, 1.0]))
    assert big.given_mass is None and big.mass == pytest.approx(8 * 0.2, rel=0.02)


def test_lift_tester_refuses_bad_mass_properties():
    from bayesgrasp import _core

    V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], float) * 0.05
    F = np.array([[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]])
    with pytest.raises(ValueError, match="mass"):
        _core.geometry.MassProperties(1e-4, -1.0, np.zeros(3), np.eye(3))
    bad = _core.geometry.MassProperties(1e-4, 0.1, np.zeros(3), np.array([[1, 2, 0], [0, 1, 0], [0, 0, 1.0]]))
    with pytest.raises(ValueError, match="symmetric"):
        physics.LiftTester(None, V, F, mass_properties=bad)


def _cube_with_degenerate_faces(tmp_path):
    """The built-in cube as an STL with 3 degenerate triangles (a repeated corner) among its 12."""
    c = load_object("cube")
    V, F = c.vertices, c.faces
    bad = np.array([[F[0, 0], F[0, 0], F[0, 1]], [F[3, 1], F[3, 2], F[3, 2]], [F[5, 2], F[5, 0], F[5, 2]]])
    F_file = np.insert(F, [2, 7, 9], bad, axis=0)                 # 15 triangles in file order
    p = tmp_path / "cube_scan.stl"
    trimesh.Trimesh(V, F_file, process=False).export(p)
    return p, F_file


def test_labels_in_file_order_or_of_the_loaded_faces(tmp_path):
    p, F_file = _cube_with_degenerate_faces(tmp_path)
    top = load_mesh(p)                                      # 12 faces: the 3 degenerate ones dropped
    assert top.n_faces == 12
    labels_file = (trimesh.Trimesh(*[load_object("cube").vertices, F_file], process=False)
                   .triangles_center[:, 2] > 0.03).astype(int)   # 1: upper half, per file triangle
    label_path = p.with_name("cube_scan.parts.json")
    label_path.write_text(json.dumps({"parts": ["lower", "upper"], "faces": labels_file.tolist()}))
    a = load_mesh(p)
    expected = (a.vertices[a.faces].mean(axis=1)[:, 2] > 0.03).astype(int)
    np.testing.assert_array_equal(a.parts, expected)
    # written from the loader's own faces (one per loaded face): accepted, the same labels
    label_path.write_text(json.dumps({"parts": ["lower", "upper"], "faces": expected.tolist()}))
    np.testing.assert_array_equal(load_mesh(p).parts, expected)
    # any other count: refused, naming both counts it takes and why
    label_path.write_text(json.dumps({"parts": ["lower", "upper"], "faces": expected[:-1].tolist()}))
    with pytest.raises(ValueError, match=r"expected 15, one per triangle of the mesh file in file order, "
                                         r"or 12, one per face of the loaded mesh \(3 degenerate"):
        load_mesh(p)


def test_decomposition_drops_flat_pieces_and_falls_back_to_the_hull(monkeypatch, tmp_path):
    box = np.array([[i & 1, i >> 1 & 1, i >> 2 & 1] for i in range(8)], float) * 0.05
    flat = box.copy()
    flat[:, 2] = 0.0                                       # a sliver: no volume
    kept, dropped = decomposition.solid_pieces([box, flat, box + 0.1])
    assert dropped == 1 and len(kept) == 2
    mug = load_object("mug")
    monkeypatch.setattr(decomposition, "_run_coacd", lambda *a, **k: [box, flat])
    with pytest.warns(decomposition.DecompositionWarning, match="dropped 1 of 2"):
        pieces = decomposition.convex_decomposition(mug.vertices, mug.faces, cache_dir=False, name="mug")
    assert len(pieces) == 1

    def fail(*a, **k):
        raise RuntimeError("no manifold")
    monkeypatch.setattr(decomposition, "_run_coacd", fail)
    with pytest.warns(decomposition.DecompositionWarning, match="'mug'.*CoACD failed.*convex hull"):
        pieces = decomposition.convex_decomposition(mug.vertices, mug.faces, cache_dir=tmp_path, name="mug")
    assert len(pieces) == 1 and np.array_equal(pieces[0], mug.vertices)
    # the lift test runs on the fallback
    t = physics.LiftTester(None, mug.vertices, mug.faces, convex_pieces=pieces, density=mug.density)
    assert t.num_pieces == 1


def test_big_meshes_are_simplified_for_the_decomposition_only():
    sphere = trimesh.creation.icosphere(subdivisions=6, radius=0.04)   # 81,920 triangles
    V, F = decomposition.simplify(np.asarray(sphere.vertices), np.asarray(sphere.faces), 2000)
    assert len(F) <= 2000
    # every simplified vertex stays within 0.5 mm of the sphere
    assert np.abs(np.linalg.norm(V, axis=1) - 0.04).max() < 5e-4
    small_V, small_F = decomposition.simplify(V, F, 6000)
    assert small_F is F


def test_part_rules_label_a_scan_in_file_order(tmp_path):
    from bayesgrasp.objects.part_rules import label_by_rules, parse_rule, write_label_file

    assert parse_rule("handle:r>0.05") == ("handle", "r", ">", 0.05)
    with pytest.raises(ValueError, match="rule 'handle=r>0.05'"):
        parse_rule("handle=r>0.05")
    p, F_file = _cube_with_degenerate_faces(tmp_path)
    out = write_label_file(p, [parse_rule("top:z>0.05"), parse_rule("side:x>0.029")])
    assert out == p.with_name("cube_scan.parts.json")
    doc = json.loads(out.read_text())
    assert doc["parts"] == ["body", "top", "side"] and len(doc["faces"]) == 15   # file order, degenerate ones too
    o = load_mesh(p)
    C = o.vertices[o.faces].mean(axis=1) - [0, 0, o.bounds[0, 2]]
    lo, hi = o.bounds
    C[:, :2] -= (lo[:2] + hi[:2]) / 2
    expected = np.where(C[:, 2] > 0.05, 1, np.where(C[:, 0] > 0.029, 2, 0))
    np.testing.assert_array_equal(o.parts, expected)
    assert set(expected) == {0, 1, 2}
    labels, names = label_by_rules(o.vertices, o.faces, [("top", "z", ">", 1.0)])
    assert names == ["body", "top"] and not labels.any()


def test_grasp_cli_names_the_mesh_and_takes_units_and_mass(tmp_path, capsys):
    from bayesgrasp.cli import main

    flat = tmp_path / "flat.stl"
    trimesh.Trimesh([[0, 0, 0], [0.05, 0, 0], [0, 0.05, 0], [0.05, 0.05, 0]], [[0, 1, 2], [1, 3, 2]],
                    process=False).export(flat)
    assert main(["grasp", "--object", str(flat), "--top", "0,0,0"]) == 2
    assert f"error: --object {flat}: " in capsys.readouterr().err
    box_mm = tmp_path / "box_mm.stl"
    trimesh.creation.box(extents=[60, 50, 120]).export(box_mm)
    assert main(["grasp", "--object", str(box_mm), "--top", "0,0,0", "--no-lift"]) == 2
    assert "--units mm" in capsys.readouterr().err                        # the error names the option ...
    assert main(["grasp", "--object", str(box_mm), "--top", "0,0,0", "--units", "mm", "--mass", "0.4",
                 "--json"]) == 0                                          # ... which grasp takes
    doc = json.loads(capsys.readouterr().out)
    assert doc["mass"] == {"kg": pytest.approx(0.4), "from": "given (--mass)",
                           "density": pytest.approx(0.4 / (0.06 * 0.05 * 0.12))}
    assert main(["grasp", "--object", str(box_mm), "--top", "0,0,0", "--units", "mm", "--mass", "-1"]) == 2
    assert "--mass: must be a weight > 0 kg" in capsys.readouterr().err
    # touch reads the mesh in --units too (and takes no --mass: it lifts nothing)
    assert main(["touch", "--object", str(box_mm), "--units", "mm", "--true-pose", "0.01,0,0.1", "--estimate", "0,0,0",
                 "--budget", "40", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["errors_before"]["position_error"] == pytest.approx(0.01)


TINY_SET = ["--set", "models.n_samples=120", "--set", "models.n_inducing=20", "--set", "models.max_iter=10",
            "--set", "models.n_lift_samples=20", "--set", "models.n_calibration=0", "--set", "models.n_pilot=20",
            "--set", "models.spread=0.0", "--set", "models.xy_range=0.03"]


def test_every_command_that_reads_a_mesh_takes_units_and_its_results_keep_them(tmp_path, capsys, monkeypatch):
    """--units through one helper in every command with --object (demo, plan, grasp, touch, episode;
    register, category and fuse through the camera options); the unit is stored with the result, so
    `view` and a later `episode observe` read the mesh alike."""
    from bayesgrasp.cli import build_parser, main
    from bayesgrasp.viewer import read_result, scene_from_result

    parser = build_parser()
    sub = next(a for a in parser._actions if a.dest == "command").choices
    for name, p in sub.items():
        dests = {a.dest for a in p._actions}
        if ("object" in dests or "scene_object" in dests) and name != "view":   # view: the unit stored in the result
            assert "units" in dests, f"{name} reads a mesh but takes no --units"
    box_mm = tmp_path / "box_mm.stl"
    trimesh.creation.box(extents=[60, 50, 120]).export(box_mm)
    assert main(["grasp", "--object", str(box_mm), "--top", "0,0,0", "--units", "mm", "--no-lift", "--json"]) == 0
    g = tmp_path / "g.json"
    g.write_text(capsys.readouterr().out)
    assert json.loads(g.read_text())["units"] == "mm"
    scene = scene_from_result(read_result(g))
    assert scene.object.extent == pytest.approx([0.06, 0.05, 0.12])
    monkeypatch.chdir(tmp_path)
    cache = ["--cache", str(tmp_path / "cache")]
    assert main(["episode", "new", "--object", str(box_mm), "--units", "mm", "--estimate", "0,0,0", "--method",
                 "stability", "--dir", "ep", *TINY_SET, *cache]) == 0
    capsys.readouterr()
    state = json.loads((tmp_path / "ep" / "episode.json").read_text())["state"]
    assert state["object"] == str(box_mm) and state["units"] == "mm"
    assert main(["episode", "observe", "ep", "--joints", "0,1.2,0.8,1.2,0.8,1.2,0.8", "--lifted", "no", *cache]) == 0
    assert "attempt 2" in capsys.readouterr().out
