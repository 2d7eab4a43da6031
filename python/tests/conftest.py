"""Shared data: the Hald cement set (Draper & Smith) and the default ship's zigzags."""
import os
import sys

import pandas as pd
import pytest

# `python -m pytest` from python/ puts the source folder first on the path, where the native
# module is not: the tests are of the installed package
_SOURCE = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path[:] = [p for p in sys.path if os.path.abspath(p or os.curdir) != _SOURCE]

import termid  # noqa: E402

ROOT = os.path.join(os.path.dirname(__file__), "..", "..")


@pytest.fixture(scope="session")
def hald() -> pd.DataFrame:
    return pd.read_csv(os.path.join(ROOT, "tests", "data", "hald.csv"))


@pytest.fixture(scope="session")
def ship() -> termid.Model:
    return termid.Model.default()


@pytest.fixture(scope="session")
def zigzags(ship):
    """The paper's five Z-manoeuvres simulated without noise by the default model."""
    runs = []
    for m in ["zigzag:15/10", "zigzag:20/10:port", "zigzag:30/10", "zigzag:20/20:port", "zigzag:25/10"]:
        run = ship.simulate(m)
        run.attrs["name"] = m
        runs.append(run)
    return runs
