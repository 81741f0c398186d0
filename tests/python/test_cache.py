"""Cache files: atomic, checksummed writes; a damaged file is detected and rebuilt with a warning."""
import json
from dataclasses import replace
import warnings

import numpy as np
import pytest

from bayesgrasp.cache import CacheWarning, atomic_write, atomic_write_text, checked
from bayesgrasp.models import ModelSettings, build_models
from bayesgrasp.physics import convex_decomposition

TINY = ModelSettings(n_samples=120, n_inducing=20, xy_range=0.03, max_iter=10, seed=5, n_lift_samples=20,
                     n_calibration=20, n_pilot=20, spread=0.5)


def test_an_atomic_write_leaves_the_file_its_checksum_and_no_temporary(tmp_path):
    f = tmp_path / "sub" / "a.npz"
    atomic_write(f, lambda tmp: np.savez(tmp, x=np.arange(3)))
    assert sorted(p.name for p in f.parent.iterdir()) == ["a.npz", "a.npz.sha256"]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert checked(f)
    assert not checked(tmp_path / "missing.json")          # absent: no warning, just not there


@pytest.mark.parametrize("damage", ["truncate", "empty", "flip", "no checksum"])
def test_a_damaged_file_fails_its_check_with_a_warning(tmp_path, damage):
    f = tmp_path / "t.json"
    atomic_write_text(f, json.dumps({"grasps": list(range(100))}))
    raw = f.read_bytes()
    if damage == "truncate":
        f.write_bytes(raw[: len(raw) // 2])
    elif damage == "empty":
        f.write_bytes(b"")
    elif damage == "flip":
        f.write_bytes(raw[:10] + bytes([raw[10] ^ 0x01]) + raw[11:])
    else:
        (tmp_path / "t.json.sha256").unlink()
    with pytest.warns(CacheWarning, match="t.json"):
        assert not checked(f)


@pytest.mark.parametrize("damage", [lambda b: b[: len(b) // 3], lambda b: b"", lambda b: b[:-40] + b"\0" * 40])
def test_a_damaged_model_file_is_rebuilt_not_fatal(tmp_path, damage):
    first = build_models("cube", settings=TINY, cache_dir=tmp_path)
    assert not first.loaded_from_cache
    npz = next(tmp_path.glob("*_stability.npz"))
    npz.write_bytes(damage(npz.read_bytes()))
    with pytest.warns(CacheWarning, match="stability.npz"):
        again = build_models("cube", settings=TINY, cache_dir=tmp_path)
    assert not again.loaded_from_cache
    X = np.array([[0.0, 0.0, 0.0, 1.0]])
    np.testing.assert_array_equal(again.stability.predict(X), first.stability.predict(X))  # same seed, same model
    third = build_models("cube", settings=TINY, cache_dir=tmp_path)
    assert third.loaded_from_cache


def test_a_damaged_decomposition_is_recomputed(tmp_path):
    from bayesgrasp.objects import load_object

    mug = load_object("mug")
    pieces = convex_decomposition(mug.vertices, mug.faces, cache_dir=tmp_path)
    f = next(tmp_path.glob("*.npz"))
    f.write_bytes(f.read_bytes()[:100])
    with pytest.warns(CacheWarning, match="convex decomposition"):
        again = convex_decomposition(mug.vertices, mug.faces, cache_dir=tmp_path)
    assert len(again) == len(pieces) and all(np.array_equal(a, b) for a, b in zip(again, pieces))


def test_a_shipped_entry_is_read_when_the_users_cache_has_none(tmp_path, monkeypatch):
    """The shipped cache stands behind the user's: the same key's files are loaded from it, the
    models are not trained, and BAYESGRASP_SHIPPED_CACHE=0 turns it off."""
    import bayesgrasp.models.build as build
    from bayesgrasp import cache
    from bayesgrasp.models import models_cached

    shipped = tmp_path / "shipped"
    made = build_models("cube", settings=TINY, cache_dir=shipped / "models")
    monkeypatch.setattr(cache, "shipped_root", lambda: shipped)
    user = tmp_path / "user" / "models"
    assert models_cached("cube", settings=TINY, cache_dir=user)

    def no_training(*a, **k):
        raise AssertionError("trained although the shipped cache has the models")

    monkeypatch.setattr(build, "_train", no_training)
    got = build_models("cube", settings=TINY, cache_dir=user)
    assert got.loaded_from_cache and not user.exists()          # read from the shipped copy, nothing written
    X = np.array([[0.01, -0.02, 0.3, 1.0]])
    np.testing.assert_array_equal(got.stability.predict(X), made.stability.predict(X))
    with pytest.raises(AssertionError, match="trained"):          # another key: not shipped, so built
        build_models("cube", settings=replace(TINY, seed=6), cache_dir=user)
    monkeypatch.undo()
    monkeypatch.setenv("BAYESGRASP_SHIPPED_CACHE", "0")
    assert cache.shipped_root() is None and cache.shipped_copy(shipped / "models" / "x.json") is None


def test_the_users_entry_wins_and_a_damaged_shipped_one_is_rebuilt(tmp_path, monkeypatch):
    from bayesgrasp import cache

    monkeypatch.setattr(cache, "shipped_root", lambda: tmp_path / "shipped")
    ship, mine = tmp_path / "shipped" / "task_grasps" / "t.json", tmp_path / "mine" / "task_grasps" / "t.json"
    atomic_write_text(ship, '{"from": "shipped"}')
    assert cache.load_cached(mine, "task grasp cache file", lambda p: json.loads(p.read_text())) == {"from": "shipped"}
    atomic_write_text(mine, '{"from": "mine"}')
    assert cache.load_cached(mine, "task grasp cache file", lambda p: json.loads(p.read_text())) == {"from": "mine"}
    mine.unlink()
    ship.write_text('{"from": "altered"}')
    with pytest.warns(CacheWarning, match="shipped task grasp cache file"):
        assert cache.load_cached(mine, "task grasp cache file", lambda p: json.loads(p.read_text())) is None


def test_the_shipped_cache_is_current_for_the_first_calls():
    """Every shipped file passes its checksum, each model's info names its own key, and the
    demo's and pub2's models (the default settings on the built-in objects) are found by today's
    cache keys: a change of the keys without `make shipped-cache` fails here."""
    from bayesgrasp import cache
    from bayesgrasp.models import models_cached

    root = cache.shipped_root()
    assert root is not None, "no shipped cache in the package (make shipped-cache)"
    manifest = json.loads((root / "MANIFEST.json").read_text())
    for folder, names in manifest["files"].items():
        for name in names:
            if not name.endswith(".sha256"):
                with warnings.catch_warnings():
                    warnings.simplefilter("error")
                    assert checked(root / folder / name), name
            if name.endswith(".json") and folder == "models" and not name.startswith("task_"):
                assert json.loads((root / folder / name).read_text())["key"] == name[:-5]
    empty = root / "no-such-user-cache" / "models"
    for obj in ("cube", "cylinder", "mug", "mug2", "pitcher"):
        assert models_cached(obj, settings=ModelSettings(success="lift"), cache_dir=empty), obj


def test_the_cache_build_keeps_each_folders_entries_and_names_them(tmp_path):
    from bayesgrasp import cache_build

    cache, out = tmp_path / "cache", tmp_path / "out"
    atomic_write_text(cache / "models" / "k.json", "{}")
    atomic_write_text(cache / "task_grasps" / "task_t.json", "{}")
    (cache / "models" / ".k.123.tmp.json").write_text("half")      # a builder's temporary: not kept
    atomic_write_text(out / "convex_decomposition" / "stale.npz", "old")   # replaced by the cache's (none)
    m = cache_build.keep(cache, out, [{"name": "demo"}])
    assert m["files"] == {"models": ["k.json", "k.json.sha256"], "task_grasps": ["task_t.json", "task_t.json.sha256"]}
    assert checked(out / "models" / "k.json") and not (out / "convex_decomposition").exists()
    assert json.loads((out / "MANIFEST.json").read_text())["commands"] == [{"name": "demo"}]
    with pytest.raises(SystemExit):
        cache_build.main(["--only", "demo,nonsense", "--out", str(out)])
