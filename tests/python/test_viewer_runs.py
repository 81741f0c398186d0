"""`bayesgrasp view results.sqlite`: a stored experiment run picked by series, object and index, for
the three kinds of run that hold grasps (a pose-uncertainty episode as pub2 stores it, a category
run as pub5 stores it, a vision-then-touch run as pub6 stores it), each written by the experiments'
own functions into a real ResultStore (small models, two training mugs)."""
import json

import numpy as np
import pytest

pytest.importorskip("viser")

from bayesgrasp.cli import main  # noqa: E402
from bayesgrasp.experiments.runner import ResultStore, RunKey  # noqa: E402
from bayesgrasp.loop.context import RunContext  # noqa: E402
from bayesgrasp.models.settings import ModelSettings  # noqa: E402
from bayesgrasp.models.task_grasps import TaskGraspSettings, generate_task_grasps  # noqa: E402
from bayesgrasp.models.tasks import task_rule  # noqa: E402
from bayesgrasp.viewer import ResultError  # noqa: E402
from bayesgrasp.viewer.runs import list_runs, read_run, scene_from_run  # noqa: E402

from testkit import free_port, port_free, served_nodes  # noqa: E402

SMALL = ModelSettings(n_samples=300, n_inducing=50, max_iter=30, n_lift_samples=150, n_calibration=100, n_pilot=40,
                      n_pilot_lifts=10)
KEEP = ("mug/1", "mug/2")


@pytest.fixture(scope="module")
def store(tmp_path_factory):
    """A results.sqlite holding one run of each kind, made by the experiments' run code."""
    from bayesgrasp.loop.category import plan_and_execute, see
    from bayesgrasp.loop.episode import EpisodeSettings, run_episode
    from bayesgrasp.loop.fusion_trial import FusionTrial

    d = tmp_path_factory.mktemp("runs")
    ctx = RunContext(cache_dir=str(d / "models"), model_settings=SMALL)
    grasps = []
    for m in KEEP:
        grasps += generate_task_grasps(m, task_rule("mug", "top"),
                                       settings=TaskGraspSettings(candidates=150, spreads=(0.0, float(np.radians(60))),
                                                                  lift_tests=6, keep=2))
    s = ResultStore(d / "results.sqlite")
    pose = run_episode("mug", (0.02, -0.01, 0.4), EpisodeSettings(method="stability", attempts=2, stop_when_stable=False),
                       ctx, seed=5).to_dict()
    s.add(RunKey("pub2/stability", "mug", 0, 5), pose)
    exclude = tuple(f"mug/{i}" for i in range(7) if f"mug/{i}" not in KEEP)
    ep = see("mug/3", (0.01, 0.02, 0.7), "mug", exclude=exclude + ("mug/3",), seed=3)
    out = plan_and_execute(ep, "mug", "top", "laplace", ctx, seed=3, grasps=grasps).to_dict()
    s.add(RunKey("pub5", "mug/3", 0, 3), {"object": "mug/3", "category": "mug", "pose": [0.01, 0.02, 0.7],
                                          "tasks": {"top": {"laplace": out}}})
    trial = FusionTrial("mug/3", (0.01, 0.02, 0.7), ctx, exclude=exclude + ("mug/3",), seed=3, grasps=grasps)
    fused = trial.run("vision", rounds=1).to_dict()
    fused.update({"object": "mug/3", "pose": [0.01, 0.02, 0.7]})
    s.add(RunKey("pub6", "mug/3", 0, 3), json.loads(json.dumps(fused, default=float)))
    s.close()
    return d / "results.sqlite", pose, out, fused


def test_runs_are_listed_and_picked_by_series_object_and_index(store):
    path, *_ = store
    assert list_runs(path) == [("pub2/stability", "mug", 0), ("pub5", "mug/3", 0), ("pub6", "mug/3", 0)]
    key, r = read_run(path.parent, "pub5")              # the directory is enough; the only object and run 0
    assert key == ("pub5", "mug/3", 0) and "tasks" in r
    with pytest.raises(ResultError, match="several stored, pick one with --series: pub2/stability, pub5, pub6$"):
        read_run(path)
    with pytest.raises(ResultError, match="--object 'cube': not stored; stored: mug"):
        read_run(path, "pub2/stability", "cube")
    with pytest.raises(ResultError, match="--run 3"):
        read_run(path, "pub6", run=3)


def test_a_pose_run_shows_each_attempt_with_its_contacts(store):
    path, pose, *_ = store
    scene = scene_from_run(*read_run(path, "pub2/stability"))
    assert len(scene.steps) == len(pose["attempts"])
    np.testing.assert_allclose(scene.object_pose, pose["true_pose"])
    for step, a in zip(scene.steps, pose["attempts"]):
        np.testing.assert_allclose(step.grasp["pose"], a["hand_pose"])
        np.testing.assert_allclose(step.grasp["joint_positions"], a["joint_positions"])
        assert step.contacts, "the attempt simulated again gives its contacts"
    nodes, view = served_nodes(scene)
    assert "/object/body" in nodes and any(n.startswith("/steps/1/hand/") for n in nodes)
    assert "/steps/0/contacts" in nodes


def test_a_category_run_shows_the_executed_grasp_and_its_parts(store):
    path, _, out, _ = store
    scene = scene_from_run(*read_run(path, "pub5"))
    (step,) = scene.steps
    assert step.label.startswith("top (laplace)")
    np.testing.assert_allclose(step.grasp["pose"], out["hand_pose"])
    assert sorted(c.part for c in step.contacts) == sorted(out["contact_parts"])   # the same closing, again
    nodes, _ = served_nodes(scene)
    assert any(n.startswith("/steps/0/hand/") for n in nodes)


def test_a_fusion_run_shows_the_models_per_round(store):
    path, _, _, fused = store
    scene = scene_from_run(*read_run(path, "pub6"))
    assert len(scene.steps) == len(fused["rounds"])
    nodes, _ = served_nodes(scene)
    for k in range(len(fused["rounds"])):
        assert {f"/steps/{k}/models/mug_1", f"/steps/{k}/models/mug_2"} <= set(nodes)


def test_the_view_command_takes_a_results_file_and_refuses_in_one_line(store, capsys, tmp_path):
    path, *_ = store
    port = free_port()
    assert main(["view", str(path), "--series", "pub2/stability", "--object", "mug", "--seconds", "0.3",
                 "--port", str(port)]) == 0
    out = capsys.readouterr().out
    assert f"http://127.0.0.1:{port}" in out and "run, 2 step(s)" in out and port_free(port)
    assert main(["view", str(path), "--series", "pub9", "--seconds", "0.1"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--series 'pub9': not stored" in err[0]
    bad = tmp_path / "other.sqlite"
    bad.write_bytes(b"not a database at all, just text")
    assert main(["view", str(bad)]) == 2
    assert "not an experiment's results.sqlite" in capsys.readouterr().err
