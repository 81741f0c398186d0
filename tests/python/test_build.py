import pickle

import numpy as np
import pytest

from bayesgrasp import _core


def _unit_cube():
    V = np.array([[i & 1, (i >> 1) & 1, (i >> 2) & 1] for i in range(8)], dtype=float)
    F = np.array([[0, 2, 1], [1, 2, 3], [4, 5, 6], [5, 7, 6], [0, 1, 4], [1, 5, 4],
                  [2, 6, 3], [3, 6, 7], [0, 4, 2], [2, 4, 6], [1, 3, 5], [3, 7, 5]])
    return V, F


def test_mass_properties_of_unit_cube():
    V, F = _unit_cube()
    mp = _core.geometry.mass_properties(V, F, 1000.0)
    assert isinstance(mp, _core.geometry.MassProperties)
    assert mp.volume == pytest.approx(1.0)
    assert mp.mass == pytest.approx(1000.0)
    np.testing.assert_allclose(mp.com, [0.5, 0.5, 0.5])
    np.testing.assert_allclose(np.diag(mp.inertia), [1000 / 6] * 3)
    d = mp.to_dict()
    assert set(d) == {"volume", "mass", "com", "inertia"} and d["com"].shape == (3,) and d["inertia"].shape == (3, 3)
    back = pickle.loads(pickle.dumps(mp))  # objects holding it go to spawned workers
    assert back.mass == mp.mass and np.array_equal(back.inertia, mp.inertia)


@pytest.mark.parametrize("bad, match", [
    (lambda V, F: (V[:, :2], F), "vertices"),
    (lambda V, F: (V, F[:0]), "no faces"),
    (lambda V, F: (np.where(V == 0, np.nan, V), F), "NaN"),
    (lambda V, F: (V, F + 100), "out of range"),
])
def test_mass_properties_rejects_bad_input(bad, match):
    V, F = bad(*_unit_cube())
    with pytest.raises(ValueError, match=match):
        _core.geometry.mass_properties(V, F, 1000.0)
