"""`bayesgrasp view`: each result type's scene graph has the named nodes (object parts, table, hand
links, pre-grasp, approach, contacts, model overlays), checked through viser's scene API; the
slider shows one step at a time; bad files are refused in one line; the server's port is free
again after stop."""
import json
import socket

import numpy as np
import pytest

pytest.importorskip("viser")

from bayesgrasp.cli import main  # noqa: E402
from bayesgrasp.viewer import ResultError, read_result, scene_from_result, serve  # noqa: E402
from testkit import cli_json, free_port, port_free  # noqa: E402


def nodes(server) -> set:
    return set(server.scene._handle_from_node_name)


@pytest.fixture()
def grasp_doc(capsys):
    return cli_json(capsys, "grasp", "--object", "mug/3", "--top", "0,0,0.3", "--json")


def test_grasp_scene_has_object_parts_table_hand_and_contacts(grasp_doc):
    scene = scene_from_result(grasp_doc)
    assert scene.kind == "grasp" and len(scene.steps) == 1
    port = free_port()
    server, view = serve(scene, port=port)
    try:
        names = nodes(server)
        assert {"/table", "/object/body", "/object/handle"} <= names
        hand = {n for n in names if n.startswith("/steps/0/hand/")}
        assert len(hand) >= 7 and any("finger1_distal" in n for n in hand)   # palm and every finger link
        assert any(n.startswith("/steps/0/pregrasp/") for n in names)
        assert {"/steps/0/approach", "/steps/0/contacts", "/steps/0/normals"} <= names
        assert len(grasp_doc["contacts"]) == len(server.scene._handle_from_node_name["/steps/0/contacts"].points)
    finally:
        server.stop()
    assert port_free(port)


def test_the_slider_shows_one_fusion_round_with_its_model_overlays(capsys, grasp_doc):
    """A fuse-shaped result: two rounds, each with its models' poses and weights."""
    rounds = [{"round": k, "grasp": grasp_doc["grasp"], "lifted": k == 1, "weights": {"mug/1": 0.7 - 0.4 * k,
               "mug/2": 0.3 + 0.4 * k}, "poses": {"mug/1": [0.0, 0.01 * k, 0.3], "mug/2": [0.01, 0.0, 0.2]}}
              for k in range(2)]
    doc = {"scene_object": "mug/3", "object_pose": [0, 0, 0], "rounds": rounds, "success": True}
    server, view = serve(scene_from_result(doc), port=free_port())
    try:
        h = server.scene._handle_from_node_name
        assert {"/steps/0/models/mug_1", "/steps/1/models/mug_2"} <= set(h)
        view.show(0)
        assert h["/steps/0/models/mug_1"].visible and not h["/steps/1/models/mug_1"].visible
        view.toggles["models"].value = False
        view.show(0)
        assert not h["/steps/0/models/mug_1"].visible and h["/object/body"].visible
    finally:
        server.stop()


def test_touch_and_register_results_have_scenes(capsys, tmp_path):
    touch = cli_json(capsys, "touch", "--object", "mug/3", "--true-pose", "0.01,0,0.3", "--estimate", "0,0,0",
                     "--budget", 100, "--json")
    s = scene_from_result(touch)
    assert s.kind == "touch" and s.steps[0].grasp is not None and s.steps[0].models[0][0] == "mug/3"
    np.testing.assert_allclose(s.object_pose, touch["true_state"][:3])


def test_bad_files_are_refused_in_one_line(capsys, tmp_path):
    f = tmp_path / "x.json"
    f.write_text('{"hello": 1}')
    assert main(["view", str(f)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "not a bayesgrasp result" in err[0]
    f.write_text("{not json")
    with pytest.raises(ResultError, match="not JSON"):
        read_result(f)
    with pytest.raises(ResultError, match="cannot read"):
        read_result(tmp_path / "missing.json")
    moved = {"object": str(tmp_path / "gone.stl"), "grasp": {}, "contacts": []}
    with pytest.raises(ResultError, match="moved"):
        scene_from_result(moved)


def test_a_busy_port_falls_back_to_the_next(grasp_doc):
    msgs = []
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        s.listen()
        busy = s.getsockname()[1]
        server, _ = serve(scene_from_result(grasp_doc), port=busy, say=msgs.append)
        try:
            assert server.get_port() != busy and msgs and f"port {busy} is in use" in msgs[0]
        finally:
            server.stop()


def test_view_command_serves_then_stops(capsys, tmp_path, grasp_doc):
    f = tmp_path / "g.json"
    f.write_text(json.dumps(grasp_doc))
    port = free_port()
    assert main(["view", str(f), "--port", str(port), "--seconds", "0.5"]) == 0
    assert f"http://127.0.0.1:{port}" in capsys.readouterr().out
    assert port_free(port)


def test_a_headless_screenshot_is_not_blank_and_differs_between_attempts(capsys, tmp_path, grasp_doc):
    from bayesgrasp.viewer.snapshot import NoBrowser, _variance, find_browser, snapshot_steps

    try:
        find_browser()
    except NoBrowser as e:
        pytest.skip(str(e))                      # names the Debian packages to install
    other = cli_json(capsys, "grasp", "--object", "mug/3", "--top", "0.03,0.0,1.4", "--json")
    rounds = [{"round": k, "grasp": g["grasp"], "lifted": g["lifted"], "weights": {}, "poses": {}}
              for k, g in enumerate([grasp_doc, other])]
    scene = scene_from_result({"scene_object": "mug/3", "object_pose": [0, 0, 0], "rounds": rounds})
    port = free_port()
    pa, pb = snapshot_steps(scene, {0: tmp_path / "a.png", 1: tmp_path / "b.png"}, port=port)   # one browser
    a, b = pa.read_bytes(), pb.read_bytes()
    assert _variance(a) > 1e-3 and _variance(b) > 1e-3
    import matplotlib.image as mpimg
    A, B = mpimg.imread(tmp_path / "a.png"), mpimg.imread(tmp_path / "b.png")
    assert A.shape == B.shape and np.abs(A[..., :3] - B[..., :3]).mean() > 1e-3
    assert port_free(port)


def test_the_demo_draws_its_pictures_with_matplotlib_when_the_browser_fails(capsys, tmp_path, grasp_doc, monkeypatch):
    """A browser whose renderer times out (a loaded machine) does not end the demo: the pictures
    are drawn by matplotlib instead, and stderr says why."""
    from selenium.common.exceptions import TimeoutException

    import bayesgrasp.viewer.snapshot as snap
    from bayesgrasp.cli.plan import _attempt_pictures

    def timed_out(*a, **k):
        raise TimeoutException("timeout: Timed out receiving message from renderer: 10.000")

    monkeypatch.setattr(snap, "find_browser", lambda: None)
    monkeypatch.setattr(snap, "snapshot_steps", timed_out)
    doc = {"scene_object": "mug/3", "object_pose": [0, 0, 0],
           "rounds": [{"round": 0, "grasp": grasp_doc["grasp"], "lifted": grasp_doc["lifted"], "weights": {}, "poses": {}}]}
    paths = _attempt_pictures(doc, tmp_path)
    assert [p.name for p in paths] == ["attempt_1.png"] and paths[0].stat().st_size > 1000
    assert "screenshots failed (Message: timeout: Timed out receiving message from renderer" in capsys.readouterr().err


def test_the_screenshots_say_they_are_still_working_while_the_browser_is_slow(tmp_path, grasp_doc, monkeypatch):
    """A browser that takes long to start (a loaded machine: 80 s of silence in a demo once) is
    covered by "still working" lines; none come once the screenshots are over."""
    import time as _time

    from selenium.common.exceptions import TimeoutException

    import bayesgrasp.progress as progress
    import bayesgrasp.viewer.snapshot as snap

    def slow_driver(size):
        _time.sleep(0.5)
        raise TimeoutException("renderer timed out")

    monkeypatch.setattr(progress, "HEARTBEAT_EVERY", 0.1)
    monkeypatch.setattr(snap, "_driver", slow_driver)
    said = []
    scene = scene_from_result({"scene_object": "mug/3", "object_pose": [0, 0, 0],
                               "rounds": [{"round": 0, "grasp": grasp_doc["grasp"], "lifted": grasp_doc["lifted"],
                                           "weights": {}, "poses": {}}]})
    port = free_port()
    with pytest.raises(TimeoutException):
        snap.snapshot_steps(scene, {0: tmp_path / "a.png"}, port=port, say=said.append)
    beats = [m for m in said if "screenshots of 1 step(s) in headless Chromium" in m and "s so far" in m]
    assert len(beats) >= 3, said
    n = len(said)
    _time.sleep(0.3)
    assert len(said) == n            # the heartbeat stopped with the screenshots
    assert port_free(port)           # and the server too


def test_a_browser_that_times_out_once_is_retried_in_a_new_session(tmp_path, grasp_doc, monkeypatch):
    """The renderer starved once (a loaded machine) costs a second session, not the pictures."""
    from io import BytesIO

    import matplotlib.pyplot as plt
    from selenium.common.exceptions import TimeoutException

    import bayesgrasp.viewer.snapshot as snap

    buf = BytesIO()
    plt.imsave(buf, np.random.default_rng(0).random((20, 30, 3)), format="png")
    noisy = buf.getvalue()

    class Driver:
        def get(self, url):
            self.url = url

        def get_screenshot_as_png(self):
            return noisy

        def execute_script(self, script):
            pass

        def quit(self):
            pass

    sessions = []

    def driver(size):
        sessions.append(size)
        if len(sessions) == 1:
            raise TimeoutException("timeout: Timed out receiving message from renderer: 10.000")
        return Driver()

    monkeypatch.setattr(snap, "_driver", driver)
    scene = scene_from_result({"scene_object": "mug/3", "object_pose": [0, 0, 0],
                               "rounds": [{"round": 0, "grasp": grasp_doc["grasp"], "lifted": grasp_doc["lifted"],
                                           "weights": {}, "poses": {}}]})
    said = []
    (p,) = snap.snapshot_steps(scene, {0: tmp_path / "a.png"}, port=free_port(), say=said.append, settle=0.0)
    assert len(sessions) == 2 and p.read_bytes() == noisy
    assert any("timed out" in m and "a new session" in m for m in said)
