"""Engines: local processes and Ray tasks store the same results for the same seeds; the models
are built once per object and shared through the cache; a Ray worker killed mid-run loses and
duplicates nothing; sweeps store every point with its parameters."""
import json
import os
import signal
import sqlite3
import sys
import threading
import time

import pytest

from bayesgrasp.cli import main
from bayesgrasp.experiments import RunContext, driver
from bayesgrasp.experiments.engines import LocalEngine, RayEngine, make_engine
from bayesgrasp.experiments.runner import ResultStore, Series, run_all
from bayesgrasp.models import ModelSettings

ray = pytest.importorskip("ray")

SMALL = dict(n_samples=300, n_inducing=40, max_iter=30, n_lift_samples=150, n_calibration=100, n_pilot=40,
             n_pilot_lifts=10)
TIMING = {"plan_seconds", "seconds"}


@pytest.fixture(scope="module")
def ray_engine():
    from ray import cloudpickle   # Ray's own serializer

    cloudpickle.register_pickle_by_value(sys.modules[__name__])   # this module's run functions, by value
    e = RayEngine(workers=2)
    yield e
    e.close()


def _strip(v):
    if isinstance(v, dict):
        return {k: _strip(x) for k, x in v.items() if k not in TIMING}
    if isinstance(v, list):
        return [_strip(x) for x in v]
    return v


def _rows(path, experiment):
    db = sqlite3.connect(path)
    try:
        return {(o, i, s): _strip(json.loads(r)) for o, i, s, r in
                db.execute("SELECT object, run_index, seed, result FROM runs WHERE experiment = ?", (experiment,))}
    finally:
        db.close()


def _stat(cache):
    files = sorted(p for p in (os.path.join(d, f) for d, _, fs in os.walk(cache) for f in fs))
    return {p: (os.stat(p).st_ino, os.stat(p).st_mtime_ns) for p in files}


def test_bad_engines_are_refused():
    with pytest.raises(ValueError, match="engine"):
        make_engine("dask")
    with pytest.raises(ValueError, match="address"):
        make_engine("local", address="127.0.0.1:6379")
    with pytest.raises(ValueError, match="workers 4 would be ignored"):
        make_engine("ray", workers=4, address="127.0.0.1:6379")    # one channel: the cluster's CPUs
    with pytest.raises(ValueError, match="workers"):
        LocalEngine(0)


def test_an_unreachable_cluster_is_refused_in_seconds_before_anything_is_written(tmp_path, capsys):
    """A Ray head that does not answer: one line naming --address within seconds (Ray's own client
    retries for minutes), and neither the cache nor the output directory is created."""
    from bayesgrasp.experiments.engines import check_address

    with pytest.raises(ValueError, match=r"^address: no Ray head at 127.0.0.1:1 "):
        check_address("127.0.0.1:1")                 # nothing listens on port 1
    with pytest.raises(ValueError, match="cannot resolve host 'head.invalid'"):
        check_address("head.invalid:6379")
    with pytest.raises(ValueError, match="expected HOST:PORT"):
        check_address("HEAD")
    cache, out = tmp_path / "shared" / "cache", tmp_path / "out"
    t0 = time.perf_counter()
    assert main(["experiment", "pub2", "--engine", "ray", "--address", "127.0.0.1:1", "--cache", str(cache),
                 "--out", str(out)]) == 2
    assert time.perf_counter() - t0 < 30
    err = capsys.readouterr().err
    assert "--address: no Ray head at 127.0.0.1:1" in err and len(err.strip().splitlines()) == 1
    assert not cache.exists() and not out.exists()


def test_ray_and_local_store_identical_results_and_share_the_models(ray_engine, tmp_path):
    cache = str(tmp_path / "cache")
    ctx = RunContext(cache_dir=cache, model_settings=ModelSettings(**SMALL), families=("top", "side"))
    # Ray first, from an empty cache: the per-object model builds are Ray tasks
    driver.run("pub2", tmp_path / "ray", ctx, runs=2, objects=["cube", "cylinder"], engine=ray_engine)
    built = _stat(cache)
    assert len([p for p in built if p.endswith(".json")]) == 4   # one model set per object and family
    driver.run("pub2", tmp_path / "local", ctx, runs=2, objects=["cube", "cylinder"], engine=LocalEngine(2))
    ray_rows = _rows(tmp_path / "ray" / "results.sqlite", "pub2/stability")
    local_rows = _rows(tmp_path / "local" / "results.sqlite", "pub2/stability")
    assert len(ray_rows) == 4 and ray_rows == local_rows
    assert all(a["family"] in ("top", "side") for r in ray_rows.values() for a in r["attempts"])
    # nothing was built again: neither the local runs nor a second Ray sweep rewrote a cache file
    driver.run("pub2", tmp_path / "ray2", ctx, runs=2, objects=["cube", "cylinder"], engine=ray_engine)
    assert _stat(cache) == built


def _slow_once(experiment, obj, run_index, seed, *, marker):
    """Run 1 of the first attempt parks (its pid in ``marker``) until it is killed."""
    if run_index == 1 and not os.path.exists(marker):
        with open(marker + ".tmp", "w") as f:
            f.write(str(os.getpid()))
        os.replace(marker + ".tmp", marker)
        time.sleep(120)
    return {"run_index": run_index, "seed": seed, "pid": os.getpid()}


def test_a_killed_ray_worker_loses_and_duplicates_nothing(ray_engine, tmp_path):
    from functools import partial

    marker = str(tmp_path / "pid")
    killed = []

    def killer():
        for _ in range(600):
            if os.path.exists(marker):
                pid = int(open(marker).read())
                os.kill(pid, signal.SIGKILL)
                killed.append(pid)
                return
            time.sleep(0.1)

    t = threading.Thread(target=killer)
    t.start()
    store = ResultStore(tmp_path / "results.sqlite")
    try:
        out = run_all([Series("killtest", ("a",), 4, partial(_slow_once, marker=marker))], store, 0, ray_engine,
                      progress=False)
    finally:
        t.join()
        n = store._db.execute("SELECT COUNT(*) FROM runs").fetchone()[0]
        store.close()
    assert killed, "the worker never started run 1"
    results = {k.run_index: r for k, r in out["killtest"]}
    assert sorted(results) == [0, 1, 2, 3] and n == 4              # every run once, none twice
    assert results[1]["pid"] != killed[0]                          # run 1 was retried on another worker


def test_sweep_stores_every_point_with_its_parameters(tmp_path, capsys):
    out = tmp_path / "sweep"
    args = ["experiment", "pub2", "--objects", "cube", "--runs", "2", "--out", str(out), "--cache", str(tmp_path / "c"),
            "--success", "epsilon", "--no-lift", "--sweep", "planner.n_particles=100,300",
            "--sweep", "episode.measurement_noise=0,0.05"]
    for k, v in SMALL.items():
        args += ["--set", f"models.{k}={v}"]
    assert main(args) == 0
    rows = json.loads((out / "sweep.json").read_text())
    assert [(r["planner.n_particles"], r["episode.measurement_noise"]) for r in rows] == \
        [(100, 0.0), (100, 0.05), (300, 0.0), (300, 0.05)]
    for r in rows:
        assert (out / r["dir"] / "summary.md").exists() and 0.0 <= r["stability.success_final"] <= 1.0
    assert (out / "sweep.png").stat().st_size > 1000 and (out / "sweep.csv").exists()
    db = sqlite3.connect(out / "results.sqlite")
    settings = {e: json.loads(s) for e, s in db.execute("SELECT experiment, settings FROM settings")}
    runs = db.execute("SELECT experiment, object, run_index, seed, result FROM runs").fetchall()
    db.close()
    assert len(settings) == 4 and len(runs) == 8
    for e, s in settings.items():
        assert s["planner"]["n_particles"] == s["sweep"]["planner.n_particles"]
        assert s["measurement_noise"] == s["sweep"]["episode.measurement_noise"]
        assert e.startswith("pub2/stability@")
    seeds = {}
    for e, o, i, seed, result in runs:
        seeds.setdefault((o, i), set()).add(seed)   # every point meets the same problems
        p, r = settings[e]["sweep"], json.loads(result)
        first = r["attempts"][0]
        # the point's settings reached the loop: the initial belief has n_particles equal weights,
        # and the measured joint angles are the executed ones exactly when there is no noise
        assert first["belief_before"]["ess"] == pytest.approx(p["planner.n_particles"])
        exact = all(any(abs(q - j) < 1e-12 for j in first["joint_positions"]) for q in first["joint_angles"])
        assert exact == (p["episode.measurement_noise"] == 0.0)
    assert all(len(v) == 1 for v in seeds.values())
    # bad sweeps are refused with the option named
    assert main(args[:-4] + ["--sweep", "planner.half_width=1,2,3"]) == 2
    assert "--sweep" in capsys.readouterr().err
    assert main(args[:-4] + ["--sweep", "planner.n_particles=x"]) == 2
    assert "--sweep" in capsys.readouterr().err
