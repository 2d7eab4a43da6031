# %% [markdown]
# # A fleet of records on Dask
#
# A notebook in plain text (open it with Jupytext, or run it as a script). Records of many runs
# are written as Parquet shards; every worker reduces its shards to termid's sufficient
# statistics (``termid.Moments``), the statistics are merged up a tree and the model is
# identified from them: the same model as one process fitting every row.
# (``examples/fleet.py`` is the command-line version, for millions of rows.) The cluster here
# runs its workers as threads of this process: termid releases the GIL, so they compute in
# parallel (a script with process workers needs the `if __name__ == "__main__":` guard).

# %%
import os
import sys
import tempfile

from dask.distributed import Client, LocalCluster

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
import fleet  # noqa: E402  (examples/fleet.py: recording, shards, the reduction)

folder = tempfile.mkdtemp(prefix="termid-fleet-")
runs = fleet.record_runs(6, duration=40.0)
rows = fleet.write_shards(folder, runs, shards=4, copies=2)
print(f"{rows:,} rows in 4 shards under {folder}")

# %%
model = fleet.fleet_model()
with LocalCluster(n_workers=2, threads_per_worker=1, processes=False, dashboard_address=None) as cluster, Client(cluster) as client:
    on_dask, spent = fleet.identify_on_dask(folder, client, model, split_every=2)
print(f"{spent['rows']:,.0f} rows, {spent['wall_s']:.2f} s on the cluster")

# %%
alone = fleet.identify_in_process(folder, model)
for eq in fleet.EQUATIONS:
    a = on_dask.model.coefficients(eq).set_index("term")["value"]
    b = alone.model.coefficients(eq).set_index("term")["value"]
    print(eq, "same terms:", list(a.index) == list(b.index), f"largest difference {float((a - b).abs().max()):.1e}")
