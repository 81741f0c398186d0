"""Cache files: atomic, checksummed writes; a damaged file is detected and rebuilt with a warning."""
import json
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
