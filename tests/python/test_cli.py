import json

import numpy as np
import pytest

from bayesgrasp.cli import main
from bayesgrasp.world import World
from testkit import run_cli


def test_grasp_json_on_cube_has_the_documented_keys_and_contacts_on_the_surface():
    code, out, err = run_cli("grasp", "--object", "cube", "--top", "0,0,0", "--json")
    assert code == 0, err
    d = json.loads(out)
    for key in ("joint_angles", "contacts", "epsilon", "volume", "lifted", "collision_at_start"):
        assert key in d
    assert len(d["joint_angles"]) == 7 and d["collision_at_start"] is False
    obj = [c for c in d["contacts"] if not c["on_table"]]
    assert obj, "the fingers should touch the cube"
    half = World.single("cube").object.extent / 2
    for c in obj:   # every object contact lies on one of the cube's faces (object at the origin)
        p = np.array(c["point"])
        assert np.all(np.abs(p[:2]) <= half[:2] + 3e-4) and -3e-4 <= p[2] <= 2 * half[2] + 3e-4
        on_face = np.isclose(np.abs(p[:2]), half[:2], atol=3e-4).any() or np.isclose(p[2], 2 * half[2], atol=3e-4)
        assert on_face
    assert isinstance(d["lifted"], bool)


def test_grasp_relative_to_the_object_pose_is_invariant():
    a = World.single("cylinder", pose=(0.0, 0.0, 0.0)).grasp(0.01, 0.0, 0.2)
    b = World.single("cylinder", pose=(0.1, -0.05, 0.7)).grasp(0.01, 0.0, 0.2)
    np.testing.assert_allclose(a.joint_angles, b.joint_angles, atol=1e-3)
    assert len(a.contacts) == len(b.contacts)
    # (epsilon is not compared: a link lying across the cylinder's rim touches it along a
    # segment, and which point of it is reported as the one contact depends on round-off)


@pytest.mark.parametrize("args, needle", [
    (["grasp", "--object", "no_such_thing", "--top", "0,0,0"], "neither a built-in"),
    (["grasp", "--object", "cube", "--top", "0,0"], "--top"),
    (["grasp", "--object", "cube", "--top", "0,0,nan"], "finite"),
    (["grasp", "--object", "cube", "--top", "0,0,0", "--object-pose", "5,0,0"], "table"),
    (["demo", "--out", "/proc/forbidden/dir"], "--out"),
    (["plan", "--object", "no_such_thing", "--true-pose", "0,0,0"], "neither a built-in"),
    (["plan", "--object", "cube", "--true-pose", "3,0,0"], "table"),
    (["experiment", "pub9"], "unknown experiment"),
    (["plan", "--object", "cube", "--true-pose", "-1,0"], "--true-pose"),
    (["experiment", "pub2", "--objects", "no_such_thing"], "neither a built-in"),
    (["experiment", "pub2", "--out", "/proc/forbidden/dir"], "--out"),
    (["experiment", "pub2", "--no-lift"], "--success epsilon"),
    (["register", "--scene-object", "cube", "--object-pose", "1,2", "--models", "cube"], "--object-pose"),
])
def test_bad_input_gives_a_message_and_exit_status_2(args, needle, capsys):
    assert main(args) == 2
    err = capsys.readouterr().err
    assert needle in err and "Traceback" not in err


def test_plan_json_on_a_user_mesh_file(tmp_path):
    # a user's own mesh: the built-in cube written to an STL file
    import trimesh

    w = World.single("cube", pose=(0.0, 0.0, 0.0))
    path = tmp_path / "box.stl"
    trimesh.Trimesh(w.object.vertices, w.object.faces).export(path)
    code, out, err = run_cli("plan", "--object", str(path), "--true-pose", "0.02,-0.01,0.4", "--json",
                             "--cache", str(tmp_path / "cache"), "--png", str(tmp_path / "belief.png"))
    assert code == 0, err
    r = json.loads(out)
    assert isinstance(r["success"], bool) and 1 <= len(r["attempts"]) <= 4
    for a in r["attempts"]:
        assert a["plan_type"] in ("stability", "explore") and len(a["top_grasp"]) == 3
        assert 0.0 <= a["predicted_stability"] <= 1.0 and a["outcome"] in ("success", "failure")
        assert a["success"] == bool(a["lifted"])   # the default criterion: held in the lift test
        assert {"entropy", "epsilon", "lifted"} <= set(a)
    assert r["attempts"][-1]["outcome"] == ("success" if r["success"] else "failure")
    assert r["success_criterion"] == "lift"
    assert {"mean", "std", "entropy", "position_error"} <= set(r["final_belief"])
    assert (tmp_path / "belief.png").stat().st_size > 1000
    # the values, not only the keys: each attempt's recorded grasp, closed again on the mesh at the
    # true pose, closes to the recorded joints, whose fingers (the spread is not read) are the
    # reading (no noise), gets the recorded lift verdict and touches where the attempt's contacts say
    from bayesgrasp.objects.library import load_object

    world = World.single(load_object(str(path)), pose=(0.02, -0.01, 0.4))
    for a in r["attempts"]:
        g = a["grasp"]
        b = world.grasp_poses(np.array([g["pose"]]), spread=g["spread"], frame="world", lift=True)
        np.testing.assert_allclose(np.asarray(b.joint_angles[0]), g["joint_positions"], atol=1e-6)
        np.testing.assert_allclose(g["joint_positions"][1:], a["joint_angles"], atol=1e-9)
        assert bool(b.lifted[0]) == a["lifted"]
        fresh = [c for c in b.contact_records(0, world.hand.links) if not c.on_table]
        assert [c["link_name"] for c in a["contacts"]] == [c.link_name for c in fresh]
        if fresh:
            np.testing.assert_allclose([c["point"] for c in a["contacts"]], [c.point for c in fresh], atol=1e-5)
    assert any(a["contacts"] for a in r["attempts"])
    f = r["final_belief"]
    assert np.isclose(f["position_error"], np.hypot(f["mean"][0] - 0.02, f["mean"][1] + 0.01))


def test_experiment_writes_tables_and_plots_and_resumes(tmp_path):
    args = ["experiment", "pub2", "--objects", "cube", "--runs", "2", "--out", str(tmp_path / "e"),
            "--cache", str(tmp_path / "cache"), "--success", "epsilon", "--no-lift"]
    code, out, err = run_cli(*args)
    assert code == 0, err
    for f in ("summary.md", "summary.json", "stability.csv", "per_attempt.png", "belief_cube.png", "results.sqlite"):
        assert (tmp_path / "e" / f).exists(), f
    first = json.loads((tmp_path / "e" / "summary.json").read_text())
    # one more run: the two stored runs are kept, only the third is computed
    code, out, err = run_cli(*[a if a != "2" else "3" for a in args])
    assert code == 0, err
    assert "2/3" in err  # the progress bar starts at the stored runs
    again = json.loads((tmp_path / "e" / "summary.json").read_text())
    assert first["stability"]["runs"] == 2 and again["stability"]["runs"] == 3


@pytest.mark.parametrize("argv, dest, expected", [
    (["grasp", "--object", "cube", "--top", "-0.01,0,0"], "top", [-0.01, 0.0, 0.0]),
    (["grasp", "--object", "cube", "--top", "0,0,0", "--object-pose", "-0.05,-0.02,-1.5"], "object_pose",
     [-0.05, -0.02, -1.5]),
    (["plan", "--object", "cube", "--true-pose", "-0.02,0.01,0.3"], "true_pose", [-0.02, 0.01, 0.3]),
    (["plan", "--object", "cube", "--true-pose", "0,0,0", "--estimate", "-.5e-2,-0.01,-3"], "estimate",
     [-0.005, -0.01, -3.0]),
    (["register", "--scene-object", "mug/3", "--object-pose", "-0.05,0,1", "--models", "mug/0"], "object_pose", [-0.05, 0.0, 1.0]),
])
def test_comma_separated_options_take_negative_numbers(argv, dest, expected):
    from bayesgrasp.cli import build_parser
    from bayesgrasp.cli.args import floats, join_negative_values

    args = build_parser().parse_args(join_negative_values(argv))
    assert floats(getattr(args, dest), 3, dest) == pytest.approx(expected)


def test_negative_top_grasp_runs_end_to_end():
    code, out, err = run_cli("grasp", "--object", "cube", "--top", "-0.01,0,0", "--no-lift", "--json")
    assert code == 0, err
    assert json.loads(out)["top"] == [-0.01, 0.0, 0.0]


def test_negative_lone_numbers_and_option_like_values_are_left_to_argparse():
    from bayesgrasp.cli.args import join_negative_values

    assert join_negative_values(["plan", "--seed", "-1"]) == ["plan", "--seed=-1"]
    assert join_negative_values(["grasp", "--top", "--json"]) == ["grasp", "--top", "--json"]
    assert join_negative_values(["grasp", "--top=-1,0,0"]) == ["grasp", "--top=-1,0,0"]


def test_register_json_and_png(tmp_path, capsys):
    png = tmp_path / "reg.png"
    assert main(["register", "--scene-object", "cube", "--object-pose", "0.05,0.0,0.4", "--models", "cube", "cylinder",
                 "--json", "--png", str(png)]) == 0
    out = capsys.readouterr().out
    doc = json.loads(out[:out.rindex("}") + 1])
    assert [m["model"] for m in doc["models"]] == ["cube", "cylinder"]
    for m in doc["models"]:
        assert set(m) >= {"model", "transform", "fitness", "rmse", "weight"}
        assert np.asarray(m["transform"]).shape == (4, 4)
    assert doc["models"][0]["weight"] > doc["models"][1]["weight"]
    assert png.exists() and png.stat().st_size > 1000


def test_captured_view_of_an_object_sees_only_that_object():
    from bayesgrasp.objects.views import capture_view

    v = capture_view("cube", (0.05, 0.0, 0.4), seed=1)
    half = World.single("cube").object.extent / 2
    assert len(v.object_points) > 100 and len(v.cloud) > len(v.object_points)
    # the segmented points lie on the cube (noise of a few mm), the table is gone
    c, s = np.cos(-0.4), np.sin(-0.4)
    p = (v.object_points - [0.05, 0.0, 0.0]) @ np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]]).T
    assert np.all(np.abs(p[:, :2]) < half[:2] + 0.006) and np.all(p[:, 2] > 0.003)
    with pytest.raises(ValueError, match="pose"):
        capture_view("cube", (1.0, 2.0))


# ---- grasp: approaches and hand poses ------------------------------------------------------------

TOP_KEYS = ["object", "object_pose", "top", "hand", "joint_angles", "joint_names", "contacts", "epsilon", "volume",
            "lifted", "lift_displacement", "collision_at_start", "hand_pose"]


def grasp_json(capsys, *args):
    assert main(["grasp", *args, "--no-lift", "--json"]) == 0
    return json.loads(capsys.readouterr().out)


def test_grasp_top_json_keeps_its_keys_and_equals_the_approach_along_minus_z(capsys):
    top = grasp_json(capsys, "--object", "mug", "--top", "0.01,0,0.3", "--object-pose", "0.05,0,0")
    assert list(top)[:len(TOP_KEYS)] == TOP_KEYS
    assert top["mode"] == "top" and top["approach"] is None and top["stopped_by_table"] is False
    world = grasp_json(capsys, "--object", "mug", "--top", "0.06,0,0.3", "--object-pose", "0.05,0,0",
                       "--frame", "world")
    a = grasp_json(capsys, "--object", "mug", "--approach", "0,0,-1", "--roll", "0.3", "--at", "0.06,0,0",
                   "--object-pose", "0.05,0,0", "--frame", "world")
    assert world["joint_angles"] == a["joint_angles"] and world["hand_pose"] == a["hand_pose"]
    # the object frame's top grasp at (0.01, 0, 0.3) is the world's at (0.06, 0, 0.3)
    np.testing.assert_allclose(top["joint_angles"], world["joint_angles"], atol=1e-9)


def test_grasp_side_approach_of_the_cylinder(capsys, tmp_path):
    png = tmp_path / "side.png"
    assert main(["grasp", "--object", "cylinder", "--approach", "2,0,0", "--at", "0,0,0.06", "--spread", "0",
                 "--no-lift", "--json", "--png", str(png)]) == 0
    d = json.loads(capsys.readouterr().out)
    assert set(TOP_KEYS) <= set(d) and d["mode"] == "approach" and d["input_frame"] == "object" and d["grasp"]["frame"] == "world"
    assert d["approach"] == {"direction": [2.0, 0.0, 0.0], "roll": 0.0, "target": [0.0, 0.0, 0.06]}
    H = np.array(d["hand_pose"])
    np.testing.assert_allclose(H[:3, 2], [1, 0, 0], atol=1e-12)             # approaching along +x
    assert -0.035 - 2e-4 < H[0, 3] < -0.035 and d["collision_at_start"] is False
    assert {c["link_name"] for c in d["contacts"]} >= {"palm", "finger1/distal", "finger2/distal", "finger3/distal"}
    assert all(c["part"] == "body" and c["triangle"] >= 0 for c in d["contacts"])
    assert png.exists() and png.stat().st_size > 1000


def test_grasp_from_a_pose_file(capsys, tmp_path):
    T = [[1, 0, 0, 0.0], [0, -1, 0, 0.0], [0, 0, -1, 0.2], [0, 0, 0, 1]]   # palm down 20 cm above the origin
    (tmp_path / "list.json").write_text(json.dumps(T))
    (tmp_path / "dict.json").write_text(json.dumps({"pose": T}))
    a = grasp_json(capsys, "--object", "cube", "--hand-pose", str(tmp_path / "list.json"), "--object-pose", "0.1,0,0")
    b = grasp_json(capsys, "--object", "cube", "--hand-pose", str(tmp_path / "dict.json"), "--object-pose", "0.1,0,0")
    assert a["mode"] == "pose" and a["pose"] == T and a["joint_angles"] == b["joint_angles"]
    np.testing.assert_allclose(a["hand_pose_object"], T, atol=1e-12)
    np.testing.assert_allclose(np.array(a["hand_pose"])[:3, 3], [0.1, 0.0, 0.2], atol=1e-12)
    w = grasp_json(capsys, "--object", "cube", "--hand-pose", str(tmp_path / "list.json"), "--object-pose", "0.1,0,0",
                   "--frame", "world")
    np.testing.assert_allclose(w["hand_pose"], T, atol=1e-12)



def test_grasp_json_output_is_a_hand_pose_file(capsys, tmp_path):
    # the round trip: grasp --json's own output, given back as --hand-pose, closes the same grasp
    first = grasp_json(capsys, "--object", "mug", "--top", "0.01,0,0.4", "--object-pose", "0.05,0.02,0.3")
    (tmp_path / "g.json").write_text(json.dumps(first))
    for frame in ("object", "world"):
        again = grasp_json(capsys, "--object", "mug", "--hand-pose", str(tmp_path / "g.json"), "--frame", frame,
                           "--object-pose", "0.05,0.02,0.3")
        np.testing.assert_allclose(again["hand_pose"], first["hand_pose"], atol=1e-12)
        np.testing.assert_allclose(again["joint_angles"], first["joint_angles"], atol=1e-9)
        assert again["lifted"] == first["lifted"]


@pytest.mark.parametrize("args, needle", [
    (["--approach", "0,0,0"], "--approach: direction"),
    (["--approach", "0,0,-1", "--at", "0,0,-0.05"], "--approach: target: below the table"),
    (["--approach", "0,0,-1", "--at", "2,0,0.05"], "--approach: target: off the table"),
    (["--approach", "0,0"], "--approach"),
    (["--top", "0,0,0", "--roll", "1"], "--roll: only with --approach"),
    (["--hand-pose", "NOFILE"], "--hand-pose: cannot read"),
    (["--hand-pose", "BAD"], "--hand-pose: hand_pose: pose rotation"),
    (["--hand-pose", "SHAPE"], "--hand-pose: .* must hold a 4x4"),
])
def test_grasp_bad_input_is_a_clear_error(args, needle, tmp_path, capsys):
    (tmp_path / "bad.json").write_text(json.dumps([[2, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0.2], [0, 0, 0, 1]]))
    (tmp_path / "shape.json").write_text(json.dumps({"pose": [[1, 0, 0], [0, 1, 0]]}))
    files = {"NOFILE": str(tmp_path / "none.json"), "BAD": str(tmp_path / "bad.json"), "SHAPE": str(tmp_path / "shape.json")}
    assert main(["grasp", "--object", "cube", "--no-lift", *[files.get(a, a) for a in args]]) == 2
    err = capsys.readouterr().err
    import re
    assert re.search(needle, err), err


@pytest.mark.parametrize("args", [
    ["plan", "--object", "cube", "--true-pose", "0,0,0", "--attempts", "0"],
    ["experiment", "pub2", "--runs", "0"],
    ["experiment", "pub2", "--workers", "0"],
])
def test_integer_options_out_of_range_are_usage_errors_naming_the_flag(args, capsys):
    with pytest.raises(SystemExit) as e:
        main(args)
    assert e.value.code == 2 and f"argument {args[-2]}: expected an integer in" in capsys.readouterr().err


@pytest.mark.parametrize("args, needle", [
    ([], "one of the arguments --top --approach --hand-pose/--pose is required"),
    (["--top", "0,0,0", "--approach", "0,0,-1"], "not allowed with"),
])
def test_grasp_needs_exactly_one_of_top_approach_pose(args, needle, capsys):
    with pytest.raises(SystemExit) as e:
        main(["grasp", "--object", "cube", *args])
    assert e.value.code == 2 and needle in capsys.readouterr().err


def test_grasp_start_in_the_table_is_reported_not_an_error(capsys):
    d = grasp_json(capsys, "--object", "cube", "--approach", "1,0,0", "--at", "0,0,0.01")
    assert d["collision_at_start"] is True and d["contacts"] == [] and d["epsilon"] == 0.0


def test_the_demo_hides_the_mug_where_its_first_grasp_misses(tmp_path):
    """The demo shows the loop: of the poses its seed draws, it takes the first whose first planned
    grasp is not lifted (the earlier ones lifted at once: checked here by running them), and its
    loop then repeats that failed first attempt exactly."""
    import argparse

    import numpy as np

    from bayesgrasp.cli.plan import DEMO_DRAWS, _demo_pose
    from bayesgrasp.experiments import RunContext
    from bayesgrasp.loop.episode import EpisodeSettings, run_episode
    from bayesgrasp.models import ModelSettings

    tiny = ModelSettings(n_samples=200, n_inducing=30, max_iter=20, seed=5, n_lift_samples=60, n_calibration=0,
                         n_pilot=20, spread=0.0)
    ctx = RunContext(cache_dir=str(tmp_path), model_settings=tiny, seed=2)
    args = argparse.Namespace(method="explore")
    pose, skipped = _demo_pose(args, ctx, "mug")
    assert skipped == 2                          # seed 2: the first two draws' first grasps lift
    rng = np.random.default_rng(ctx.seed)
    draws = [[rng.uniform(-0.08, 0.08), rng.uniform(-0.08, 0.08), rng.uniform(-np.pi, np.pi)] for _ in range(DEMO_DRAWS)]
    assert pose == [float(v) for v in draws[skipped]]
    first = lambda p, n: run_episode("mug", p, EpisodeSettings(method="explore", attempts=n), ctx, seed=ctx.seed)  # noqa: E731
    assert all(first(draws[k], 1).attempts[0].success for k in range(skipped))
    full = first(pose, 4)
    assert not full.attempts[0].success and len(full.attempts) >= 2


def test_episode_new_offers_only_the_methods_an_episode_runs(capsys):
    """The parser's --method choices come from the episodes' own lists: part-aware (which no
    episode runs) is refused by the parser, not accepted and refused later."""
    from bayesgrasp.loop.outside_loop import METHODS
    from bayesgrasp.loop.outside_loop_category import CATEGORY_METHODS

    with pytest.raises(SystemExit):
        main(["episode", "new", "--category", "mug", "--task", "side", "--method", "part-aware", "--dir", "x"])
    err = capsys.readouterr().err
    assert "invalid choice: 'part-aware'" in err
    for m in METHODS + CATEGORY_METHODS + ("fusion",):
        assert f"'{m}'" in err
