"""termid as a scikit-learn regressor (scikit-learn, an optional extra): candidate terms over
the features, a back-end that selects among them, in ``Pipeline``, ``GridSearchCV`` and
``cross_val_score`` like any estimator.

    >>> import numpy as np
    >>> from termid.sklearn import TermRegressor
    >>> X = np.random.default_rng(0).normal(size=(50, 2))
    >>> y = 1.5 * X[:, 0] * X[:, 1] - 2.0 * X[:, 1]
    >>> model = TermRegressor(terms=["x0", "x1", "x0*x1", "x0^2"], backend="best-subset").fit(X, y)
    >>> sorted(model.coef_.round(6).items())
    [('x0*x1', 1.5), ('x1', -2.0)]
"""

from __future__ import annotations

from typing import Any, Dict, Optional, Sequence

import numpy as np

try:
    from sklearn.base import BaseEstimator, RegressorMixin
    from sklearn.utils.validation import check_is_fitted, validate_data
except ImportError as e:  # the optional extra
    raise ImportError("termid.sklearn needs scikit-learn ≥ 1.6: pip install scikit-learn") from e

from . import TermidError, fit


class TermRegressor(RegressorMixin, BaseEstimator):
    """Fits the target by candidate ``terms`` written over the features' names (a
    DataFrame's columns, else ``x0``, ``x1``, ...; default: every feature, linear) with a
    back-end (``stepwise``, ``best-subset``, ``sparse``, ``efroymson``, ``stlsq``) and its
    ``settings``. After ``fit``: ``coef_`` (a Series by term), ``intercept_``, ``fit_`` (the
    :class:`termid.Fit`, with its steps and ``summary()``).

    Parameters: ``terms`` the candidates; ``backend`` the selection; ``intercept`` whether a
    constant is fitted; ``settings`` the back-end's settings (``termid.settings(backend)``).

    >>> from termid.sklearn import TermRegressor
    >>> X = pd.DataFrame({"a": [0.0, 1, 2, 3, 4, 5], "b": [1.0, 0, 2, 1, 3, 2]})
    >>> model = TermRegressor(terms=["a", "b", "a*b"]).fit(X, 2 * X.a * X.b + 1)
    >>> model.coef_.round(6).to_dict()
    {'a*b': 2.0}
    """

    def __init__(
        self,
        terms: Optional[Sequence[str]] = None,
        backend: str = "stepwise",
        intercept: bool = True,
        settings: Optional[Dict[str, Any]] = None,
    ):
        self.terms = terms
        self.backend = backend
        self.intercept = intercept
        self.settings = settings

    def _names(self, n: int) -> list:
        names = getattr(self, "feature_names_in_", None)
        return [str(c) for c in names] if names is not None else [f"x{j}" for j in range(n)]

    def fit(self, X: Any, y: Any) -> "TermRegressor":
        """Selects and fits the terms on features ``X`` (an array or a DataFrame) and target
        ``y``; returns the estimator.

        >>> from termid.sklearn import TermRegressor
        >>> X = np.arange(12.0).reshape(6, 2)
        >>> TermRegressor().fit(X, 3 * X[:, 0]).coef_.round(6).to_dict()
        {'x0': 3.0}
        """
        X, y = validate_data(self, X, y, y_numeric=True, dtype=np.float64)
        names = self._names(X.shape[1])
        target = "y"
        while target in names:
            target += "_"
        columns = {n: np.ascontiguousarray(X[:, j]) for j, n in enumerate(names)}
        columns[target] = np.ascontiguousarray(y, dtype=np.float64)
        try:
            self.fit_ = fit(
                columns,
                target,
                list(self.terms) if self.terms is not None else names,
                self.backend,
                intercept=self.intercept,
                **(self.settings or {}),
            )
        except TermidError as e:
            # scikit-learn's callers catch ValueError for data a model cannot be fitted on
            raise ValueError(f"{e} (n_samples = {X.shape[0]})") from e
        self.coef_ = self.fit_.coefficients
        self.intercept_ = self.fit_.intercept or 0.0
        return self

    def predict(self, X: Any) -> np.ndarray:
        """The fitted equation on features ``X``, as an array.

        >>> from termid.sklearn import TermRegressor
        >>> X = np.arange(12.0).reshape(6, 2)
        >>> TermRegressor().fit(X, 3 * X[:, 0] + 1).predict([[10.0, 0.0]]).round(6).tolist()
        [31.0]
        """
        check_is_fitted(self, "fit_")
        X = validate_data(self, X, reset=False, dtype=np.float64)
        names = self._names(X.shape[1])
        columns = {n: np.ascontiguousarray(X[:, j]) for j, n in enumerate(names)}
        return self.fit_.predict(columns).to_numpy()
