"""`bayesgrasp view` on the real output of every command: plan (belief particles per attempt, the
contacts), category and register (the camera's cloud, each registered model placed by its
transform), fuse (the cloud, the models per round), grasp --lift-trace (the object's path in the
hand), an episode on disk; `--view` on a command; the demo's per-attempt pictures; the matplotlib
fallback (small models, two training mugs, a few demonstrated grasps)."""
import json

import numpy as np
import pytest

pytest.importorskip("viser")

from bayesgrasp.cli import main  # noqa: E402
from bayesgrasp.viewer import read_result, scene_from_result  # noqa: E402
from testkit import cli_json, free_port, port_free, served_nodes, small, without_set  # noqa: E402



def test_plan_shows_each_attempts_particles_and_contacts(capsys, tmp_path):
    doc = cli_json(capsys, "plan", "--object", "mug", "--true-pose", "0.02,-0.01,0.4", "--attempts", 2,
                   *small(tmp_path / "m"), "--json")
    for a in doc["attempts"]:
        b = a["belief"]
        assert b["n"] >= len(b["particles"]) == len(b["weights"]) > 0
        assert np.all(np.diff(b["weights"]) <= 0)                       # heaviest first
        assert a["contacts"] and all(len(c["point"]) == 3 for c in a["contacts"])
    scene = scene_from_result(doc)
    nodes, view = served_nodes(scene)
    for k in range(len(doc["attempts"])):
        assert {f"/steps/{k}/particles", f"/steps/{k}/particle_copies", f"/steps/{k}/contacts"} <= set(nodes)
        assert len(nodes[f"/steps/{k}/particles"].points) == len(doc["attempts"][k]["belief"]["particles"])
    # the particles are where the belief says: their weighted mean near the attempt's belief mean
    X, w = np.asarray(doc["attempts"][0]["belief"]["particles"]), np.asarray(doc["attempts"][0]["belief"]["weights"])
    assert np.all(np.abs(X[:, :2] - np.asarray(doc["true_pose"][:2])) < 0.1)
    assert "particles" in view.toggles and w.sum() <= 1 + 1e-9


def test_register_places_each_model_by_its_transform_over_the_cloud(capsys):
    doc = cli_json(capsys, "register", "--scene-object", "mug/3", "--object-pose", "0.01,0,0.5",
                   "--models", "mug/1", "mug/3", "--json")
    assert len(doc["cloud"]) > 100
    scene = scene_from_result(doc)
    nodes, _ = served_nodes(scene)
    assert {"/cloud", "/steps/0/models/mug_1", "/steps/0/models/mug_3", "/object/body"} <= set(nodes)
    # each model drawn where its registration put it, and mug/3 (registered to its own view) around the cloud
    from bayesgrasp.objects import load_object

    m = load_object("mug/3")
    T = np.asarray(next(r["transform"] for r in doc["models"] if r["model"] == "mug/3"))
    V = nodes["/steps/0/models/mug_3"].vertices
    np.testing.assert_allclose(V, m.vertices @ T[:3, :3].T + T[:3, 3], atol=1e-5)
    C = np.asarray(doc["cloud"])
    inside = np.all((C > V.min(axis=0) - 0.01) & (C < V.max(axis=0) + 0.01), axis=1)
    assert inside.mean() > 0.95


def test_category_and_fuse_show_cloud_models_and_rounds(capsys, cat_options):
    cat = cli_json(capsys, "category", "--category", "mug", "--task", "top", "--scene-object", "mug/3",
                   "--object-pose", "0.01,0.02,0.7", *without_set(cat_options), "--json")
    assert cat["cloud"] and all(len(m["transform"]) == 4 for m in cat["models"])
    nodes, _ = served_nodes(scene_from_result(cat))
    assert {"/cloud", "/steps/0/models/mug_1", "/steps/0/models/mug_2"} <= set(nodes)
    assert any(n.startswith("/steps/0/hand/") for n in nodes)
    fuse = cli_json(capsys, "fuse", "--category", "mug", "--task", "top", "--scene-object", "mug/3",
                    "--object-pose", "0.01,0.02,0.7", "--rounds", 2, *cat_options, "--json")
    scene = scene_from_result(fuse)
    nodes, view = served_nodes(scene)
    assert "/cloud" in nodes and len(scene.steps) == len(fuse["rounds"])
    for k in range(len(fuse["rounds"])):
        assert {f"/steps/{k}/models/mug_1", f"/steps/{k}/models/mug_2"} <= set(nodes)


def test_a_lift_trace_is_the_objects_path_in_the_hand(capsys):
    doc = cli_json(capsys, "grasp", "--object", "mug/3", "--top", "0,0,0.3", "--lift-trace", "--json")
    tr = doc["lift_trace"]
    assert tr["lifted"] == doc["lifted"]                     # the same lift test, run again with its trace
    assert len(tr["path"]) == len(tr["time"]) >= 10
    nodes, _ = served_nodes(scene_from_result(doc))
    assert {"/steps/0/lift_trace", "/steps/0/lift_end"} <= set(nodes)
    assert main(["grasp", "--object", "mug/3", "--top", "0,0,0.3", "--lift-trace", "--no-lift"]) == 2
    assert "--lift-trace" in capsys.readouterr().err


def test_an_episode_on_disk_is_viewed_from_its_state_file(capsys, tmp_path):
    d = tmp_path / "ep"
    cli_json(capsys, "episode", "new", "--object", "mug", "--estimate", "0,0,0", "--dir", d, *small(tmp_path / "m"),
             "--json")
    scene = scene_from_result(read_result(d / "episode.json"))
    assert scene.kind == "episode" and scene.steps[-1].outcome == "planned"
    nodes, _ = served_nodes(scene)
    assert any(n.startswith("/steps/0/hand/") for n in nodes) and "/object/body" in nodes


def test_view_on_a_command_keeps_stdout_json_and_frees_the_port(capsys):
    port = free_port()
    code = main(["grasp", "--object", "mug/3", "--top", "0,0,0.3", "--json", "--view", str(port),
                 "--view-seconds", "0.3"])
    out, err = capsys.readouterr()
    assert code == 0 and json.loads(out)["grasp"]["hand"]            # stdout: the JSON only (no banner)
    assert f"http://127.0.0.1:{port}" in err and port_free(port)


def test_demo_writes_a_picture_of_the_hand_on_the_mug_per_attempt(capsys, tmp_path):
    out = tmp_path / "demo"
    assert main(["demo", "--out", str(out), *small(tmp_path / "m")]) == 0
    doc = json.loads((out / "demo.json").read_text())
    pictures = sorted(out.glob("attempt_*.png"))
    assert len(pictures) == len(doc["attempts"]) >= 1 and (out / "belief_evolution.png").exists()
    import matplotlib.image as mpimg

    assert all(np.asarray(mpimg.imread(p))[..., :3].var() > 1e-3 for p in pictures)
    assert scene_from_result(doc).kind == "plan"                      # demo.json opens in the viewer


def test_the_matplotlib_fallback_draws_the_same_step(capsys, tmp_path):
    from bayesgrasp.viewer.static import render_step

    doc = cli_json(capsys, "grasp", "--object", "mug/3", "--top", "0.03,0,1.4", "--json")
    png = render_step(scene_from_result(doc), 0, tmp_path / "s.png")
    import matplotlib.image as mpimg

    assert np.asarray(mpimg.imread(png))[..., :3].var() > 1e-3
