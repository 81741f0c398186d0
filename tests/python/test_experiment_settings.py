"""Issue 17: a resume must not mix runs made under different settings. The settings that change a
result are stored beside the runs; resuming under other ones is refused with the difference named,
and nothing is written."""
import json
import sqlite3

import pytest

from bayesgrasp.experiments.runner import ResultStore, RunKey, run_experiment, settings_difference
from bayesgrasp.loop.context import RunContext

from testkit import run_cli


def _square(experiment, obj, run_index, seed):
    return {"value": run_index * run_index}


def test_settings_are_recorded_and_a_resume_under_others_is_refused(tmp_path):
    store = ResultStore(tmp_path / "results.sqlite")
    a = {"lift": True, "models": {"n_train": 400, "success": "lift"}, "hand": "BH8"}
    run_experiment("e", ["cube"], 2, _square, store, progress=False, settings=a)
    assert store.settings("e") == a
    # the same settings resume: one more run computed, the stored two kept
    assert len(run_experiment("e", ["cube"], 3, _square, store, progress=False, settings=a)) == 3
    b = {"lift": False, "models": {"n_train": 800, "success": "lift"}, "hand": "BH8"}
    with pytest.raises(ValueError) as e:
        run_experiment("e", ["cube"], 4, _square, store, progress=False, settings=b)
    msg = str(e.value)
    assert "lift: stored true, now false" in msg and "models.n_train: stored 400, now 800" in msg
    assert "hand" not in msg and "models.success" not in msg  # only what differs
    assert len(store.results("e")) == 3 and store.settings("e") == a  # nothing written
    # another series in the same file has its own settings
    run_experiment("f", ["cube"], 1, _square, store, progress=False, settings=b)
    assert store.settings("f") == b
    store.close()


def test_runs_stored_without_settings_are_not_resumed(tmp_path):
    path = tmp_path / "results.sqlite"
    db = sqlite3.connect(str(path))  # a file written before settings were stored
    db.execute("CREATE TABLE runs (experiment TEXT, object TEXT, run_index INTEGER, seed INTEGER, result TEXT,"
               " PRIMARY KEY (experiment, object, run_index, seed))")
    db.execute("INSERT INTO runs VALUES ('e', 'cube', 0, 1, ?)", (json.dumps({"value": 0}),))
    db.commit()
    db.close()
    store = ResultStore(path)
    with pytest.raises(ValueError, match="1 runs of e stored without their settings"):
        store.check_settings("e", {"lift": True})
    assert store.settings("e") is None
    store.add(RunKey("g", "cube", 0, 1), {"value": 0})  # runs added without settings are refused too
    with pytest.raises(ValueError):
        store.check_settings("g", {"lift": True})
    store.check_settings("h", {"lift": True})  # a new series is fine
    store.close()


def test_the_difference_names_nested_and_missing_keys():
    d = settings_difference({"a": 1, "m": {"x": [1, 2], "y": "s"}}, {"a": 1, "m": {"x": [1, 3]}, "z": False})
    assert d == ['m.x: stored [1, 2], now [1, 3]', 'm.y: stored "s", now "(unset)"', 'z: stored "(unset)", now false']


def test_result_settings_cover_what_changes_a_result():
    s = RunContext().result_settings().to_dict()
    assert {"bayesgrasp", "cache_version", "hand", "hand_file_sha256", "success", "lift", "models"} <= set(s)
    assert s == json.loads(json.dumps(s))  # plain JSON
    other = RunContext(success="epsilon", lift=False).result_settings().to_dict()
    diff = settings_difference(s, other)
    assert any(x.startswith("lift:") for x in diff) and any(x.startswith("success:") for x in diff)
    assert any(x.startswith("models.success:") for x in diff)
    robotiq = RunContext(hand="robotiq_3f").result_settings()
    assert robotiq.hand_file_sha256 != s["hand_file_sha256"] and robotiq.hand.startswith("Robotiq")


def test_the_context_carries_its_loaded_hand_and_still_goes_to_workers():
    """RunContext.hand_model: the context's hand loaded once per process (the same object on every
    call, the named hand); the context itself stays picklable for spawned workers (by name)."""
    import pickle

    ctx = RunContext(hand="parallel_jaw.urdf")
    assert ctx.hand_model is ctx.hand_model and ctx.hand_model.name.startswith("Parallel-jaw")
    assert RunContext().hand_model.name.startswith("Barrett")
    back = pickle.loads(pickle.dumps(ctx.for_workers()))
    assert back.hand == "parallel_jaw.urdf" and back.hand_model is ctx.hand_model


def test_the_cli_refuses_to_resume_a_no_lift_run_with_the_lift_test(tmp_path):
    base = ["experiment", "pub2", "--objects", "cube", "--runs", "1", "--out", str(tmp_path / "e"),
            "--cache", str(tmp_path / "cache"), "--success", "epsilon"]
    code, out, err = run_cli(*base, "--no-lift")
    assert code == 0, err
    before = (tmp_path / "e" / "results.sqlite").read_bytes()
    code, out, err = run_cli(*base, "--runs", "2")  # the lift test on now
    assert code != 0
    assert "other settings" in err and "lift: stored false, now true" in err, err
    assert (tmp_path / "e" / "results.sqlite").read_bytes() == before


# ---- per-attempt rows as SQL tables; `bayesgrasp results` ------------------------------------------
def _episode(experiment, obj, run_index, seed):
    return {"success": run_index % 2 == 0, "attempts_used": 2, "true_pose": [0.0, 0.01, 0.2],
            "attempts": [{"lifted": False, "epsilon": 0.01 * run_index, "hand_pose": [[1, 0], [0, 1]]},
                         {"lifted": run_index % 2 == 0, "epsilon": None, "new-field": "x"}]}


def test_attempts_become_rows_with_real_columns(tmp_path):
    store = ResultStore(tmp_path / "results.sqlite")
    run_experiment("e", ["cube", "mug"], 3, _episode, store, progress=False, settings={"lift": True})
    store.flatten()
    store.close()
    db = sqlite3.connect(str(tmp_path / "results.sqlite"))
    # one row per run, one per attempt of a run, and no table for anything else
    assert db.execute("SELECT COUNT(*) FROM run_rows").fetchone()[0] == 6
    assert db.execute("SELECT COUNT(*) FROM attempts").fetchone()[0] == 12
    assert {r[0] for r in db.execute("SELECT name FROM sqlite_master WHERE type = 'table'")} \
        == {"runs", "settings", "run_rows", "attempts"}
    # plain SQL, no JSON functions: the share lifted at the second attempt, per object
    rows = db.execute("SELECT object, AVG(lifted), COUNT(*) FROM attempts WHERE position = 1 GROUP BY object"
                      " ORDER BY object").fetchall()
    assert rows == [("cube", 2 / 3, 3), ("mug", 2 / 3, 3)]
    assert db.execute("SELECT SUM(success) FROM run_rows").fetchone()[0] == 4  # runs 0 and 2 of each object
    cols = [r[1] for r in db.execute("PRAGMA table_info(attempts)")]
    assert cols == ["experiment", "object", "run_index", "seed", "position", "lifted", "epsilon", "hand_pose",
                    "new_field"]
    assert json.loads(db.execute("SELECT hand_pose FROM attempts LIMIT 1").fetchone()[0]) == [[1, 0], [0, 1]]
    run_cols = [r[1] for r in db.execute("PRAGMA table_info(run_rows)")]
    assert run_cols == ["experiment", "object", "run_index", "seed", "success", "attempts_used", "true_pose"]
    assert json.loads(db.execute("SELECT true_pose FROM run_rows LIMIT 1").fetchone()[0]) == [0.0, 0.01, 0.2]


def test_the_results_command_lists_tables_and_runs_queries_read_only(tmp_path):
    store = ResultStore(tmp_path / "results.sqlite")
    run_experiment("e", ["cube"], 2, _episode, store, progress=False, settings={"lift": True})
    store.close()  # not flattened: the command builds the tables
    code, out, err = run_cli("results", str(tmp_path))
    assert code == 0, err
    assert "attempts (4 rows)" in out and "run_rows (2 rows)" in out and 'settings of e: {"lift": true}' in out
    code, out, err = run_cli("results", str(tmp_path), "--sql",
                             "SELECT run_index, position, lifted FROM attempts ORDER BY run_index, position", "--csv")
    assert code == 0, err
    assert out.splitlines() == ["run_index,position,lifted", "0,0,0", "0,1,1", "1,0,0", "1,1,0"]
    code, out, err = run_cli("results", str(tmp_path), "--sql", "DELETE FROM runs")
    assert code != 0 and "readonly" in err.replace("-", "").lower()
    code, out, err = run_cli("results", str(tmp_path), "--sql", "SELECT nope FROM attempts")
    assert code != 0 and "--sql: no such column: nope" in err
    code, out, err = run_cli("results", str(tmp_path / "missing"))
    assert code != 0 and "no results.sqlite" in err


# ---- experiments configured by file ----------------------------------------------------------------
def test_a_config_file_sets_the_run_and_the_models_and_the_command_line_wins(tmp_path):
    cfg = tmp_path / "pub2.toml"
    cfg.write_text('objects = ["cube"]\nruns = 1\nsuccess = "epsilon"\nlift = false\n'
                   f'cache = "{tmp_path / "cache"}"\n[models]\nn_samples = 300\n')
    out = tmp_path / "e"
    code, _, err = run_cli("experiment", "pub2", "--config", str(cfg), "--out", str(out))
    assert code == 0, err
    db = sqlite3.connect(str(out / "results.sqlite"))
    settings = json.loads(db.execute("SELECT settings FROM settings").fetchone()[0])
    assert settings["lift"] is False and settings["success"] == "epsilon" and settings["models"]["n_samples"] == 300
    assert db.execute("SELECT COUNT(*) FROM runs").fetchone()[0] == 1
    # the command line's --set wins over the file's [models]: a different setting, refused by the resume check
    code, _, err = run_cli("experiment", "pub2", "--config", str(cfg), "--out", str(out), "--set", "models.n_samples=400")
    assert code != 0 and "models.n_samples: stored 300, now 400" in err


@pytest.mark.parametrize("text, message", [
    ("speed = 3\n", "unknown key 'speed'"),
    ("runs = \"many\"\n", "runs must be int"),
    ("lift = 1\n", "lift must be bool"),
    ("objects = [1, 2]\n", "objects must be a list of names"),
    ("hand = \"no_such_hand\"\n", "unknown hand 'no_such_hand'"),
    ("[models]\nno_such_field = 1\n", "--set: expected models.FIELD=VALUE"),
    ("runs = [\n", "--config"),
])
def test_a_bad_config_file_is_refused_in_one_line(tmp_path, text, message):
    cfg = tmp_path / "bad.toml"
    cfg.write_text(text)
    code, _, err = run_cli("experiment", "pub2", "--config", str(cfg), "--out", str(tmp_path / "e"))
    assert code != 0 and message in err, err
    assert not (tmp_path / "e" / "results.sqlite").exists()


def test_config_tables_reach_the_planner_the_episode_and_the_sweep(tmp_path):
    from bayesgrasp.cli import build_parser
    from bayesgrasp.cli.args import context
    from bayesgrasp.cli.experiment import apply_config, sweep_points

    cfg = tmp_path / "sweep.toml"
    cfg.write_text('[planner]\nn_particles = 120\nhalf_width = [0.02, 0.02, 0.5]\n[episode]\nmeasurement_noise = 0.01\n'
                   '[sweep]\n"planner.pso_iter" = [5, 10]\n[sweep.models]\nn_samples = [300, 400]\n')
    args = build_parser().parse_args(["experiment", "pub2", "--config", str(cfg), "--sweep", "models.n_samples=350"])
    assert args.config_defaults["hand"] == "barrett_bh8" and args.config_defaults["workers"] == 1
    apply_config(args, str(cfg), args.config_defaults)
    ctx = context(args, progress=False)
    assert ctx.planner_settings().n_particles == 120 and tuple(ctx.planner_settings().half_width) == (0.02, 0.02, 0.5)
    assert ctx.measurement_noise == 0.01
    s = ctx.result_settings()
    assert s.planner.n_particles == 120 and s.to_dict()["measurement_noise"] == 0.01
    # the file's sweep axes, the command line's value list winning for the axis it names
    points = sweep_points(args)
    assert [p for p, _ in points] == [{"planner.pso_iter": 5, "models.n_samples": 350},
                                      {"planner.pso_iter": 10, "models.n_samples": 350}]
    for params, a in points:
        c = context(a, progress=False)
        assert c.planner_settings().pso_iter == params["planner.pso_iter"] and c.planner_settings().n_particles == 120
        assert c.model_settings.n_samples == 350
    bad = tmp_path / "bad.toml"
    bad.write_text("[planner]\nn_particles = 1\n")
    code, _, err = run_cli("experiment", "pub2", "--config", str(bad), "--out", str(tmp_path / "e"))
    assert code != 0 and "n_particles" in err


@pytest.mark.parametrize("key, option", [("models.success", "--success"), ("models.family", "--families")])
def test_a_setting_with_an_option_of_its_own_is_refused_by_set(key, option):
    from bayesgrasp.cli.args import CliError, SetOverrides, parse_set

    with pytest.raises(CliError, match=f"{key} is set by {option}"):
        parse_set([f"{key}=epsilon"])
    assert parse_set(["models.n_samples=300"]) == SetOverrides(models={"n_samples": 300})


@pytest.mark.parametrize("other", ["0.02", "0.01"])
def test_plan_refuses_the_noise_by_two_names(other):
    code, _, err = run_cli("plan", "--object", "cube", "--true-pose", "0,0,0", "--noise", "0.01",
                           "--set", f"episode.measurement_noise={other}")
    assert code == 2 and "two names for one setting" in err


@pytest.mark.parametrize("extra, option", [(["--engine", "local", "--address", "127.0.0.1:6379"], "--address"),
                                           (["--engine", "ray", "--address", "127.0.0.1:6379", "--workers", "2"],
                                            "--workers")])
def test_engine_errors_name_the_option_at_fault(tmp_path, extra, option):
    code, _, err = run_cli("experiment", "pub2", "--runs", "1", "--out", tmp_path / "o", *extra)
    assert code == 2 and f"error: {option}: " in err, err


@pytest.mark.parametrize("argv, refused", [
    (["pub5", "--families", "side"], "--families"),
    (["pub1_variants", "--set", "planner.n_particles=100"], "--set planner.n_particles"),
    (["pub6", "--no-lift", "--success", "epsilon"], "--no-lift"),
    (["entropy_order", "--sweep", "episode.measurement_noise=0,0.01"], "--sweep episode.measurement_noise"),
])
def test_an_option_the_experiment_does_not_read_is_refused(tmp_path, argv, refused):
    import re

    code, _, err = run_cli("experiment", *argv, "--out", tmp_path / "o")
    assert code == 2 and re.search(f"{re.escape(refused)}.*experiment {argv[0]} does not read", err), err
    assert not (tmp_path / "o").exists()       # refused before anything is written


def test_the_closed_loop_experiments_read_every_run_setting():
    from bayesgrasp.cli import build_parser
    from bayesgrasp.cli.args import GivenSetting, given_settings
    from bayesgrasp.experiments import get_experiment

    args = build_parser().parse_args(["experiment", "pub2", "--families", "top,side", "--success", "epsilon",
                                      "--no-lift", "--set", "planner.n_particles=100",
                                      "--sweep", "episode.measurement_noise=0,0.01", "--set", "models.n_samples=300"])
    given = {g.setting: g.option for g in given_settings(args)}
    assert len(given) == len(given_settings(args))      # each setting once
    assert set(given) == {"families", "success", "lift", "planner", "measurement_noise", "models"}
    assert given["lift"] == "--no-lift" and given["planner"] == "--set planner.n_particles"
    for name in ("pub2", "baselines", "pub4"):
        assert set(get_experiment(name).reads) == set(given)
    # options at the context's defaults are not given; a --set is given even at its default value
    at_defaults = build_parser().parse_args(["experiment", "pub5", "--families", "top", "--success", "lift"])
    assert given_settings(at_defaults) == ()
    assert given_settings(build_parser().parse_args(["experiment", "pub5", "--set", "planner.n_particles=500"])) \
        == (GivenSetting("planner", "--set planner.n_particles"),)
    with pytest.raises(ValueError, match="not run-context settings"):
        from bayesgrasp.experiments.registry import Experiment
        Experiment("x", ("cube",), 1, "", None, None, reads=("threads",))


@pytest.mark.parametrize("argv, refused", [
    (["category", "--category", "mug", "--task", "top", "--scene-object", "mug/3", "--set", "models.n_samples=300"],
     "--set models.n_samples: `category` does not read models"),
    (["fuse", "--category", "mug", "--task", "top", "--scene-object", "mug/3", "--set", "planner.n_particles=100"],
     "--set planner.n_particles: `fuse` does not read planner"),
])
def test_a_command_refuses_a_run_setting_it_does_not_read(argv, refused):
    code, _, err = run_cli(*argv)
    assert code == 2 and refused in err
