import numpy as np
import pytest

from bayesgrasp.experiments import ResultStore, run_experiment, run_seed

CALLS = []


def square_run(experiment, obj, run_index, seed):
    CALLS.append((obj, run_index))
    rng = np.random.default_rng(seed)
    return {"value": run_index ** 2, "draw": float(rng.random()), "object": obj}


def failing_after_three(experiment, obj, run_index, seed):
    if run_index >= 3:
        raise KeyboardInterrupt
    return square_run(experiment, obj, run_index, seed)


def test_results_are_stored_and_resume_skips_finished_runs(tmp_path):
    CALLS.clear()
    store = ResultStore(tmp_path / "runs.sqlite")
    with pytest.raises(KeyboardInterrupt):
        run_experiment("toy", ["cube"], 6, failing_after_three, store, progress=False)
    assert len(store.done("toy")) == 3          # runs 0..2 were saved before the interruption
    CALLS.clear()
    results = run_experiment("toy", ["cube"], 6, square_run, store, progress=False)
    assert sorted(CALLS) == [("cube", 3), ("cube", 4), ("cube", 5)]  # only the missing runs
    assert [r["value"] for _, r in results] == [0, 1, 4, 9, 16, 25]
    # A fresh store object on the same file sees everything.
    assert len(ResultStore(tmp_path / "runs.sqlite").done("toy")) == 6


def test_runs_are_pure_functions_of_their_identity(tmp_path):
    a = run_experiment("toy", ["cube", "mug"], 3, square_run, ResultStore(tmp_path / "a.sqlite"),
                       base_seed=7, progress=False)
    b = run_experiment("toy", ["cube", "mug"], 3, square_run, ResultStore(tmp_path / "b.sqlite"),
                       base_seed=7, workers=2, progress=False)
    assert [r for _, r in a] == [r for _, r in b]
    assert run_seed(7, "toy", "cube", 0) != run_seed(7, "toy", "cube", 1)
    assert run_seed(7, "toy", "cube", 0) == run_seed(7, "toy", "cube", 0)


def test_bad_arguments(tmp_path):
    store = ResultStore(tmp_path / "r.sqlite")
    with pytest.raises(ValueError, match="runs"):
        run_experiment("toy", ["cube"], 0, square_run, store)
    with pytest.raises(ValueError, match="workers"):
        run_experiment("toy", ["cube"], 1, square_run, store, workers=0)
    blocker = tmp_path / "file"
    blocker.write_text("x")
    with pytest.raises(ValueError, match="cannot write"):
        ResultStore(blocker / "sub" / "r.sqlite")
