"""termid.sklearn.TermRegressor is a scikit-learn regressor like any other."""
import numpy as np
import pytest
from sklearn.model_selection import GridSearchCV, cross_val_score
from sklearn.pipeline import make_pipeline
from sklearn.preprocessing import StandardScaler
from sklearn.utils.estimator_checks import check_estimator

from termid.sklearn import TermRegressor


def test_passes_check_estimator():
    results = check_estimator(TermRegressor(), on_fail=None)
    failed = [(r["check_name"], str(r["exception"])[:200]) for r in results if r["status"] == "failed"]
    assert len(results) > 40 and not failed, failed


def test_in_a_pipeline_a_grid_search_and_cross_validation(hald):
    X, y = hald[["x1", "x2", "x3", "x4"]], hald["y"]
    # feature names are the DataFrame's: terms are written over them
    model = TermRegressor(terms=["x1", "x2", "x4", "x1*x2"], backend="best-subset").fit(X, y)
    assert set(model.coef_.index) <= {"x1", "x2", "x4", "x1*x2"} and model.score(X, y) > 0.97
    pipe = make_pipeline(StandardScaler(), TermRegressor())
    assert cross_val_score(pipe, X.to_numpy(), y, cv=3).mean() > 0.5
    grid = GridSearchCV(TermRegressor(), {"backend": ["stepwise", "best-subset", "sparse"]}, cv=3)
    grid.fit(X, y)
    assert grid.best_params_["backend"] in {"stepwise", "best-subset", "sparse"}
    with pytest.raises(ValueError):
        TermRegressor(terms=["x1*"]).fit(X, y)
