"""The Dask fleet example: shards reduced to statistics on worker processes, merged up a
tree, identified — the same model as one process fitting all rows."""
import os
import sys

import pytest

pytest.importorskip("dask.distributed")
pytest.importorskip("pyarrow")
sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "examples"))
import fleet  # noqa: E402


def test_fleet_on_a_local_cluster_equals_one_process(tmp_path):
    from dask.distributed import Client, LocalCluster

    runs = fleet.record_runs(6, duration=40.0)
    rows = fleet.write_shards(str(tmp_path), runs, shards=5, copies=2)
    assert rows == 2 * sum(len(r) for r in runs)
    model = fleet.fleet_model()
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster, Client(cluster) as client:
        # a tree of pairs: 5 shards → 3 → 2 → 1
        on_dask, spent = fleet.identify_on_dask(str(tmp_path), client, model, split_every=2)
    assert spent["rows"] == rows and spent["shards"] == 5
    alone = fleet.identify_in_process(str(tmp_path), model)
    for eq in fleet.EQUATIONS:
        a = on_dask.model.coefficients(eq).set_index("term")["value"]
        b = alone.model.coefficients(eq).set_index("term")["value"]
        assert list(a.index) == list(b.index), eq
        for term in a.index:
            assert a[term] == pytest.approx(b[term], rel=1e-9, abs=1e-12), (eq, term)
