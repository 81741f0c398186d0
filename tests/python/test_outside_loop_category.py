"""The category task (Pub. V) and vision-then-touch (Pub. VI) episodes with the robot outside: the
World, as the stand-in robot, executes each printed grasp on the mug and feeds back its joints and
lift verdict; the grasps and beliefs must equal what `category` and `fuse` produce in-process, bit
for bit (small models, two training mugs, a few demonstrated grasps)."""
import json

import numpy as np
import pytest

from bayesgrasp.cli import main
from bayesgrasp.loop.outside_loop import STATE_FILE
from bayesgrasp.loop.fusion_trial import top_grasp
from bayesgrasp.loop.outside_loop_category import VIEW_FILE, CategoryTaskEpisode, FusionEpisode, open_episode
from bayesgrasp.hand import Hand
from bayesgrasp.io.grasp_schema import validate
from testkit import task_grasp_options, without_set
from bayesgrasp.world import World
from testkit import cli_json

SET = {"n_samples": 400, "n_inducing": 60, "max_iter": 40, "n_lift_samples": 200, "n_calibration": 150, "n_pilot": 60,
       "n_pilot_lifts": 15}
KEEP = ("mug/1", "mug/2")
SCENE, POSE, SEED = "mug/3", [0.01, 0.02, 0.7], 3


@pytest.fixture(scope="module")
def options(tmp_path_factory):
    """The options both sides share: the small models' cache and settings, the task grasps file."""
    return task_grasp_options(tmp_path_factory.mktemp("cat"), KEEP, SEED, SET)


def pose_text():
    return ",".join(map(repr, POSE))


def test_category_task_episode_equals_the_category_command(capsys, tmp_path, options):
    inproc = cli_json(capsys, "category", "--category", "mug", "--task", "top", "--scene-object", SCENE,
                      "--object-pose", pose_text(), *without_set(options), "--json")
    d = tmp_path / "ep"
    doc = cli_json(capsys, "episode", "new", "--category", "mug", "--task", "top", "--object", SCENE, "--object-pose",
                   pose_text(), "--dir", d, *without_set(options), "--json")
    nxt = doc["next"]
    assert doc["kind"] == "category" and nxt["planned_pose"] == inproc["planned_pose"]   # the same plan, bit for bit
    validate(nxt["grasp"])
    assert nxt["grasp"]["joint_positions"] != inproc["grasp"]["joint_positions"]      # printed open, to approach
    # the stand-in robot approaches along the printed pose, closes and lifts: the category command's execution
    A = np.array(nxt["grasp"]["pose"])
    g = World.single(SCENE, pose=POSE).approach(A[:3, 2], A[:3, 3], Hand.approach_roll(A),
                                                spread=nxt["grasp"]["spread"], frame="world", lift=True)
    assert np.asarray(g.joint_angles).tolist() == inproc["grasp"]["joint_positions"]
    assert bool(g.lifted) == inproc["lifted"]
    end = cli_json(capsys, "episode", "observe", d, "--joints", ",".join(map(repr, np.asarray(g.joint_angles).tolist())),
                   "--lifted", "yes" if g.lifted else "no", "--json")
    assert end["next"] is None and end["status"] == ("success" if g.lifted else "failed")   # Pub. V: one grasp
    shown = cli_json(capsys, "episode", "show", d, "--json")
    assert shown["steps"][0]["planned_pose"] == inproc["planned_pose"]
    assert shown["belief"]["weights"] == {m["model"]: m["weight"] for m in inproc["models"]}


def test_fusion_episode_equals_the_fuse_command(capsys, tmp_path, options):
    inproc = cli_json(capsys, "fuse", "--category", "mug", "--task", "top", "--scene-object", SCENE, "--object-pose",
                      pose_text(), "--rounds", 3, *options, "--json")
    d = tmp_path / "ep"
    doc = cli_json(capsys, "episode", "new", "--category", "mug", "--task", "top", "--method", "fusion", "--object",
                   SCENE, "--object-pose", pose_text(), "--attempts", 4, "--dir", d, *options, "--json")
    assert doc["kind"] == "fusion"
    world = World.single(SCENE, pose=POSE)
    grasps, beliefs = [], []
    while doc["next"] is not None:
        nxt = doc["next"]
        validate(nxt["grasp"])
        grasps.append(nxt["top_grasp"])
        beliefs.append(nxt["belief"])
        ex = top_grasp(world, np.array(nxt["top_grasp"]), np.array(POSE), nxt["grasp"]["spread"])
        doc = cli_json(capsys, "episode", "observe", d, "--joints", ",".join(map(repr, ex.joint_angles.tolist())),
                       "--lifted", "yes" if ex.lifted else "no", "--json")
    # fuse and an episode both end at the first lift (the experiment, as the thesis ran it, makes
    # round 1 even after a lifted round 0)
    rounds = inproc["rounds"]
    n = next((k + 1 for k, r in enumerate(rounds) if r["lifted"]), len(rounds))
    assert n == len(rounds)
    assert n >= 2, "the scene should take a tactile round (a round-0 lift tests no update)"
    assert grasps == [r["top_grasp"] for r in rounds[:n]]
    assert [b["weights"] for b in beliefs] == [r["weights"] for r in rounds[:n]]
    assert [b["poses"] for b in beliefs] == [r["poses"] for r in rounds[:n]]
    assert doc["status"] == ("success" if rounds[n - 1]["lifted"] else "failed")
    # a later process resumes it from disk to the same belief
    again = open_episode(d)
    last = json.loads((d / STATE_FILE).read_text())["state"]["steps"][-1]
    assert isinstance(again, FusionEpisode)
    assert again.belief() == (beliefs[-1] if last["lifted"] else last["belief_after"])


def test_category_episodes_refuse_bad_starts_and_damaged_views(capsys, tmp_path, options):
    d = tmp_path / "ep"
    assert main(["episode", "new", "--category", "mug", "--dir", str(d), *options]) == 2
    assert "--category, --task" in capsys.readouterr().err
    assert main(["episode", "new", "--category", "mug", "--task", "top", "--method", "explore", "--object", SCENE,
                 "--dir", str(d), *options]) == 2
    assert "pose-uncertainty method" in capsys.readouterr().err
    assert main(["episode", "new", "--category", "mug", "--task", "top", "--dir", str(d), *options]) == 2
    assert "--cloud, --depth or --object" in capsys.readouterr().err
    assert main(["episode", "new", "--category", "mug", "--task", "lid", "--object", SCENE, "--dir", str(d),
                 *options]) == 2
    assert not (d / STATE_FILE).exists() and not (d / VIEW_FILE).exists()      # nothing written
    cli_json(capsys, "episode", "new", "--category", "mug", "--task", "top", "--object", SCENE, "--object-pose",
             pose_text(), "--dir", d, *without_set(options), "--json")
    assert isinstance(open_episode(d), CategoryTaskEpisode)
    before = (d / STATE_FILE).read_bytes()
    with np.load(d / VIEW_FILE) as z:
        view = dict(z)
    with open(d / VIEW_FILE, "wb") as f:                                       # another view behind its back
        np.savez(f, cloud=view["cloud"] + 0.001, viewpoint=view["viewpoint"])
    assert main(["episode", "observe", str(d), "--joints", "0,0,0,0,0,0,0", "--lifted", "no"]) == 2
    assert "checksum" in capsys.readouterr().err
    assert (d / STATE_FILE).read_bytes() == before
