"""ExactGP and SparseGP are scikit-learn estimators: clone, cross_val_score, GridSearchCV, Pipeline."""
import numpy as np
import pytest
from sklearn.base import clone, is_regressor
from sklearn.model_selection import GridSearchCV, KFold, cross_val_score
from sklearn.pipeline import make_pipeline
from sklearn.preprocessing import StandardScaler

from bayesgrasp.gp import ExactGP, SparseGP


def data(n=120, seed=0):
    rng = np.random.default_rng(seed)
    X = rng.uniform(-3, 3, (n, 1))
    return X, np.sin(2 * X[:, 0]) + rng.normal(0, 0.05, n)


@pytest.mark.parametrize("gp", [ExactGP(), SparseGP(n_inducing=30, seed=1)])
def test_cross_val_score_on_a_smooth_function(gp):
    X, y = data()
    assert is_regressor(gp)
    scores = cross_val_score(gp, X, y, cv=KFold(4, shuffle=True, random_state=0))
    assert scores.shape == (4,) and scores.min() > 0.9


def test_clone_keeps_the_parameters_and_drops_the_fit():
    X, y = data(40)
    gp = SparseGP(n_inducing=12, noise=0.1, seed=3).fit(X, y)
    c = clone(gp)
    assert c.get_params() == gp.get_params() and not hasattr(c, "models_")


def test_grid_search_prefers_a_learnt_fit_over_a_frozen_wrong_lengthscale():
    X, y = data()
    grid = GridSearchCV(ExactGP(lengthscale=20.0), {"optimize": [False, True]}, cv=3).fit(X, y)
    assert grid.best_params_ == {"optimize": True} and grid.best_score_ > 0.9


def test_pipeline_with_a_scaler():
    X, y = data()
    pipe = make_pipeline(StandardScaler(), ExactGP(normalize_x=False)).fit(X[:90] * 100.0, y[:90])
    assert pipe.score(X[90:] * 100.0, y[90:]) > 0.9
