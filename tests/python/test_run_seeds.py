"""The seed stored with a run is the seed the run was made with: the driver gives each run
run_seed(--seed, the experiment's seed name, object, run index), experiments that share a seed
name (the pub6 variants, pub1_variants) get the same seeds, and the run functions use the seed
they are given instead of deriving their own."""
import sqlite3
from functools import partial

import numpy as np
import pytest

from bayesgrasp.experiments import driver, pose_uncertainty, tactile_fusion
from bayesgrasp.experiments.registry import EXPERIMENTS, Experiment, get_experiment
from bayesgrasp.experiments.report import Report
from bayesgrasp.experiments.runner import run_seed
from bayesgrasp.loop.context import RUN_SEEDS, RunContext


def _echo(experiment, obj, run_index, seed, *, method):
    return {"method": method, "seed": seed}


def _toy(exp, method, ctx):
    return f"{exp.name}/{method}", partial(_echo, method=method)


def _report(exp, results, out):
    return Report(out, {m: [(k.seed, r["seed"]) for k, r in rs] for m, rs in results.items()})


@pytest.fixture
def toys(monkeypatch):
    for name in ("toy_a", "toy_b"):
        monkeypatch.setitem(EXPERIMENTS, name, Experiment(name, ("cube", "mug"), 2, "toy", _toy, _report,
                                                          methods=("m1", "m2"), reads=(), seed_name="toy"))


def test_each_stored_seed_is_the_one_the_run_was_given_and_shared_by_the_seed_name(toys, tmp_path):
    ctx = RunContext(seed=11)
    a = driver.run("toy_a", tmp_path / "a", ctx)
    b = driver.run("toy_b", tmp_path / "b", ctx)
    want = sorted(run_seed(11, "toy", o, i) for o in ("cube", "mug") for i in range(2))
    for summary in (a.summary, b.summary):
        for method in ("m1", "m2"):
            assert all(stored == used for stored, used in summary[method])
            assert sorted(s for s, _ in summary[method]) == want   # every method and both experiments
    with sqlite3.connect(tmp_path / "a" / "results.sqlite") as db:
        assert sorted(r[0] for r in db.execute("SELECT seed FROM runs WHERE experiment = 'toy_a/m1'")) == want
        assert RUN_SEEDS in db.execute("SELECT settings FROM settings").fetchone()[0]


def test_variants_share_their_base_experiments_seeds():
    assert get_experiment("pub1_variants").seeds == "pub1"
    pub6 = ("pub6", "pub6_vision", "pub6_part_aware", "pub6_avoid", "pub6_part_aware_avoid", "pub6_warped",
            "pub6_particles")
    assert {get_experiment(n).seeds for n in pub6} == {"pub6"}
    assert get_experiment("pub2").seeds == "pub2"


def test_an_episode_run_uses_its_seed_for_the_pose_and_the_episode(monkeypatch):
    seen = {}

    def record(obj, pose, episode, ctx, seed, **_):
        seen.update(pose=pose, seed=seed)
        return {"attempts": []}

    monkeypatch.setattr(pose_uncertainty, "run_episode", record)
    pose_uncertainty.episode_run("pub2/stability", "cube", 3, 12345, method="stability", stop_when_stable=True,
                                 ctx=RunContext())
    assert seen["seed"] == 12345
    np.testing.assert_array_equal(seen["pose"], pose_uncertainty.true_pose(12345))
    assert not np.array_equal(pose_uncertainty.true_pose(12345), pose_uncertainty.true_pose(12346))


def test_a_fusion_run_uses_its_seed_for_the_view_and_the_trial(monkeypatch):
    seen = {}

    class Trial:
        def __init__(self, obj, pose, ctx, settings=None, eye_offset=None, seed=0):
            seen.update(pose=pose, seed=seed)

        def run(self, mode, rounds=None):
            return Rounds()

    class Rounds:       # a FusionResult with no round run
        rounds = [None]

    monkeypatch.setattr(tactile_fusion, "FusionTrial", Trial)
    tactile_fusion.fusion_run("pub6/all", "mug/1", 0, 2**40 + 7, ctx=RunContext(), mode="vision", belief="map")
    assert seen["seed"] == (2**40 + 7) % 2**31
    np.testing.assert_array_equal(seen["pose"], tactile_fusion.view(2**40 + 7)[0])
