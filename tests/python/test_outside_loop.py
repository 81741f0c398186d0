"""The closed loop with the robot outside (`bayesgrasp episode`): the World as the stand-in robot
executes each printed grasp and feeds back its joints and lift verdict; the grasps and beliefs must
equal the in-process loop's (run_episode, what `plan` runs) bit for bit."""
import fcntl
import hashlib
import json

import numpy as np
import pytest

from bayesgrasp.cli import main
from bayesgrasp.cli.args import model_settings
from bayesgrasp.loop.context import RunContext
from bayesgrasp.loop.episode import EpisodeSettings, execute, run_episode
from bayesgrasp.loop.outside_loop import PoseEpisode
from bayesgrasp.world import World
from testkit import cli_json

SET = {"n_samples": 300, "n_inducing": 50, "max_iter": 30, "n_lift_samples": 150, "n_calibration": 100, "n_pilot": 40,
       "n_pilot_lifts": 10}
SMALL = [a for k, v in SET.items() for a in ("--set", f"models.{k}={v}")]
OBJ, TRUTH, EST, SEED = "cylinder", [0.01, -0.01, 0.4], [0.035, -0.04, 0.9], 3


@pytest.fixture(scope="module")
def cache(tmp_path_factory):
    return str(tmp_path_factory.mktemp("cache"))


def ctx_for(cache):
    return RunContext(cache_dir=cache, model_settings=model_settings([f"models.{k}={v}" for k, v in SET.items()],
                                                                     "lift"))


def belief_sha(planner):
    b = planner.belief
    return hashlib.sha256(np.ascontiguousarray(b.particles).tobytes() + np.ascontiguousarray(b.weights).tobytes()).hexdigest()


def drive(capsys, directory, cache, method, attempts):
    """`episode new`, then `observe` with the World executing each printed grasp at the truth."""
    ctx = ctx_for(cache)
    models = ctx.models(OBJ)
    robot = World.single(OBJ, pose=TRUTH, hand=ctx.hand)
    doc = cli_json(capsys, "episode", "new", "--object", OBJ, "--estimate", ",".join(map(repr, EST)), "--method",
                   method, "--attempts", attempts, "--seed", SEED, "--dir", directory, "--cache", cache, *SMALL, "--json")
    grasps = []
    while doc["next"] is not None:
        a = doc["next"]["top_grasp"]
        grasps.append(a)
        ex = execute(robot, models, np.array(a), np.array(TRUTH), ctx)
        doc = cli_json(capsys, "episode", "observe", directory, "--joints", ",".join(map(repr, ex.joint_angles.tolist())),
                       "--lifted", "yes" if ex.lifted else "no", "--json")
    return grasps, doc


@pytest.mark.parametrize("method", ["stability", "explore"])
def test_outside_loop_equals_the_in_process_loop_bit_for_bit(capsys, tmp_path, cache, method):
    attempts = 3
    r = run_episode(OBJ, TRUTH, EpisodeSettings(method=method, attempts=attempts), ctx_for(cache), seed=SEED,
                    estimate=EST, keep_planner=True)
    grasps, last = drive(capsys, tmp_path / "ep", cache, method, attempts)
    d = r.to_dict()
    assert grasps == [a["action"] for a in d["attempts"]]
    assert last["status"] == ("success" if d["success"] else "failed")
    shown = cli_json(capsys, "episode", "show", tmp_path / "ep", "--json")
    assert shown["belief"]["particles_sha256"] == belief_sha(r.planner)
    assert shown["belief"]["mean"] == d["final_belief"]["mean"] and shown["belief"]["std"] == d["final_belief"]["std"]
    for step, a in zip(shown["steps"], d["attempts"]):
        assert step["lifted"] == a["lifted"]
        if "belief_after" in a:
            assert step["belief_after"]["mean"] == a["belief_after"]["mean"]


def test_printed_grasp_is_a_schema_grasp_and_ros_shaped(capsys, tmp_path, cache):
    from bayesgrasp.io.grasp_schema import validate

    d = cli_json(capsys, "episode", "new", "--object", OBJ, "--estimate", "0,0,0", "--method", "stability", "--dir",
                 tmp_path / "e", "--cache", cache, *SMALL, "--json")
    validate(d["next"]["grasp"])
    x, y, _ = d["next"]["top_grasp"]
    np.testing.assert_allclose(np.array(d["next"]["grasp"]["pose"])[:2, 3], [x, y], atol=1e-9)
    assert d["status"] == "open" and d["attempts_made"] == 0


@pytest.fixture()
def episode_dir(capsys, tmp_path, cache):
    d = tmp_path / "ep"
    cli_json(capsys, "episode", "new", "--object", OBJ, "--estimate", "0.01,0,0.2", "--method", "stability",
             "--attempts", "2", "--dir", d, "--cache", cache, *SMALL, "--json")
    return d


def observe_fails(capsys, d, joints, lifted, needle):
    before = (d / "episode.json").read_bytes()
    code = main(["episode", "observe", str(d), "--joints", joints, "--lifted", lifted])
    err = capsys.readouterr().err
    assert code == 2 and needle in err and "Traceback" not in err, err
    assert len(err.strip().splitlines()) == 1
    assert (d / "episode.json").read_bytes() == before     # nothing changed


GOOD = "0,1.0,1.0,1.0,1.0,1.0,1.0"


@pytest.mark.parametrize("joints, lifted, needle", [
    ("0,1,1", "no", "expected 7 comma-separated numbers, got 3"),
    ("0,1,1,1,nan,1,1", "no", "finite"),
    ("0,80,40,80,40,80,40", "no", "degrees instead of radians"),
    (GOOD, "maybe", "--lifted: yes or no, got 'maybe'"),
])
def test_bad_observations_are_refused_and_change_nothing(capsys, episode_dir, joints, lifted, needle):
    observe_fails(capsys, episode_dir, joints, lifted, needle)


def test_finished_missing_damaged_foreign_and_busy_episodes_are_refused(capsys, episode_dir, tmp_path):
    d = episode_dir
    state_file = d / "episode.json"
    # two writers: another process holds the lock
    with open(d / ".lock", "a") as f:
        fcntl.flock(f, fcntl.LOCK_EX)
        observe_fails(capsys, d, GOOD, "no", "another process is writing this episode")
    # a damaged state (one byte changed) and a half-written one
    good = state_file.read_bytes()
    state_file.write_bytes(good.replace(b'"seed": 0', b'"seed": 1'))
    observe_fails(capsys, d, GOOD, "no", "damaged")
    state_file.write_bytes(good[: len(good) // 2])
    observe_fails(capsys, d, GOOD, "no", "half-written")
    # another version, checksum intact
    doc = json.loads(good)
    doc["state"]["bayesgrasp"] = "0.0.1"
    doc["sha256"] = hashlib.sha256(json.dumps(doc["state"], sort_keys=True).encode()).hexdigest()
    state_file.write_text(json.dumps(doc))
    observe_fails(capsys, d, GOOD, "no", "written by bayesgrasp 0.0.1")
    state_file.write_bytes(good)
    # a missing episode
    code = main(["episode", "observe", str(tmp_path / "nowhere"), "--joints", GOOD, "--lifted", "no"])
    assert code == 2 and "no episode here" in capsys.readouterr().err
    # finished: lifted at the first grasp
    assert main(["episode", "observe", str(d), "--joints", GOOD, "--lifted", "yes", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["status"] == "success"
    observe_fails(capsys, d, GOOD, "no", "the episode is finished (success)")
    # new into a directory that holds one
    code = main(["episode", "new", "--object", OBJ, "--estimate", "0,0,0", "--dir", str(d)])
    assert code == 2 and "already holds an episode" in capsys.readouterr().err


def test_python_api_resumes_in_a_new_object(tmp_path, cache):
    ctx = ctx_for(cache)
    ep = PoseEpisode.new(tmp_path / "p", OBJ, EST, ctx, method="stability", attempts=3, seed=SEED)
    first = ep.next["top_grasp"]
    again = PoseEpisode.open(tmp_path / "p")
    assert again.next == ep.next and again.belief() == ep.belief()
    nxt = again.observe([0.0] + [1.0] * 6, lifted=False)
    assert nxt is not None and nxt["attempt"] == 2 and nxt["top_grasp"] != first
    assert PoseEpisode.open(tmp_path / "p").belief() == again.belief()


def test_a_urdf_hand_s_episode_reads_joints_in_the_urdf_s_terms(capsys, tmp_path, cache):
    """With a URDF hand the printed joints are the URDF's, and --joints takes a reading in them: it
    updates the belief exactly as the same reading in our terms does (the Python API's observe)."""
    from bayesgrasp.loop.outside_loop_category import open_episode
    from bayesgrasp.hand import Hand

    hand = Hand.load("barrett_bh8.urdf")
    args = ["episode", "new", "--object", OBJ, "--estimate", ",".join(map(repr, EST)), "--method", "stability",
            "--attempts", "3", "--seed", SEED, "--hand", "barrett_bh8.urdf", "--cache", cache, *SMALL]
    main([str(a) for a in args + ["--dir", str(tmp_path / "a")]])
    text = capsys.readouterr().out
    urdf_names = hand.urdf_joints(hand.open_joints())[0]
    assert "  joints " + ",".join(urdf_names) in text           # the URDF's names, not ours
    doc = cli_json(capsys, *args, "--dir", tmp_path / "b", "--json")
    ctx = RunContext(cache_dir=cache, hand="barrett_bh8.urdf",
                     model_settings=model_settings([f"models.{k}={v}" for k, v in SET.items()], "lift"))
    ex = execute(World.single(OBJ, pose=TRUTH, hand=ctx.hand), ctx.models(OBJ), np.array(doc["next"]["top_grasp"]),
                 np.array(TRUTH), ctx)
    q = np.asarray(ex.joint_angles)
    values = hand.urdf_joints(q)[1]
    lifted = "yes" if ex.lifted else "no"
    via_cli = cli_json(capsys, "episode", "observe", tmp_path / "a", "--joints", ",".join(map(repr, values.tolist())),
                       "--lifted", lifted, "--json")
    ep = open_episode(tmp_path / "b", cache_dir=cache)
    ep.observe(q, lifted)
    assert via_cli["next"] == json.loads(json.dumps(ep.next))
    assert cli_json(capsys, "episode", "show", tmp_path / "a", "--json")["belief"] == \
        cli_json(capsys, "episode", "show", tmp_path / "b", "--json")["belief"]
    # a reading in our terms (7 values for the URDF's 8 joints) is refused, naming the URDF's joints
    code = main(["episode", "observe", str(tmp_path / "a"), "--joints", ",".join(map(repr, q.tolist())),
                 "--lifted", "no"])
    assert code == 2 and "--joints" in capsys.readouterr().err
