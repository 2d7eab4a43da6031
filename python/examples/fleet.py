"""A fleet of records identified on Dask: one pass over each shard where it lies, mergeable
statistics sent back, a tree reduction, one selection.

Records of many runs (termid's synthetic basin: the default ship's zigzags with sensor noise,
per-run approach speeds) are written as Parquet shards; every shard is read by a worker, its
runs' sufficient statistics computed (``termid.Moments``: per run, so leave-one-run-out
cross-validation still works after merging), the statistics merged pairwise up a tree
(``split_every`` at a time) and the model identified from the merged statistics: the same
model, to round-off, as one process fitting all rows together.

    python fleet.py generate FOLDER [--rows 1e7] [--shards 16]
    python fleet.py identify FOLDER [--workers 2] [--scheduler tcp://host:8786]

On a real cluster: start ``dask scheduler`` and ``dask worker tcp://host:8786`` on the
machines (each with ``pip install ./python``), put the shards where every worker reads them
(a shared file system, or ``s3://bucket/fleet/`` with s3fs), and pass ``--scheduler``.
"""
from __future__ import annotations

import argparse
import glob
import os
import time
from typing import Dict, List, Sequence, Tuple

import numpy as np
import pandas as pd

import termid

#: The columns a basin's record holds (the model's names, SI, radians) and the run's id.
COLUMNS = ["t", "u", "v", "r", "ψ", "x0", "y0", "δ"]
MANOEUVRES = [
    "zigzag:10/10", "zigzag:15/10", "zigzag:20/10", "zigzag:20/20", "zigzag:25/10", "zigzag:30/10",
]
EQUATIONS = ["u_dot", "v_dot", "r_dot"]


def fleet_model() -> termid.Model:
    """The default ship, its approach speed u0 averaged over each record's first 4 s (one
    noisy sample, the file's `first:u`, would put the noise into every coefficient)."""
    ship = termid.Model.default()
    return termid.Model.from_toml(ship.to_toml().replace('"first:u"', '"mean:u:4"'), "fleet ship")


def record_runs(runs: int, seed: int = 0, duration: float = 100.0) -> List[pd.DataFrame]:
    """``runs`` basin records: the zigzags above to both sides, approach speeds 0.95-1.05 u0."""
    ship = termid.Model.default()
    rng = np.random.default_rng(seed)
    out = []
    for k in range(runs):
        m = MANOEUVRES[k % len(MANOEUVRES)] + (":port" if (k // len(MANOEUVRES)) % 2 else "")
        run = ship.record(m, speed=float(rng.uniform(0.95, 1.05)), duration=duration, seed=seed * 100_000 + k)
        out.append(run[COLUMNS])
    return out


def write_shards(folder: str, runs: Sequence[pd.DataFrame], shards: int, copies: int = 1) -> int:
    """The runs (each ``copies`` times, under new run ids: a fleet's size without its
    simulation time) spread over ``shards`` Parquet files, whole runs per shard. Returns rows."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    os.makedirs(folder, exist_ok=True)
    ids = [(c * len(runs) + k, run) for c in range(copies) for k, run in enumerate(runs)]
    rows = 0
    for s in range(shards):
        mine = ids[s::shards]
        if not mine:
            continue
        frame = pd.concat([run.assign(run=rid) for rid, run in mine], ignore_index=True)
        pq.write_table(pa.Table.from_pandas(frame, preserve_index=False), os.path.join(folder, f"shard{s:04d}.parquet"))
        rows += len(frame)
    return rows


def runs_of(frame: pd.DataFrame) -> Tuple[List[Dict[str, np.ndarray]], List[str]]:
    """A shard's runs as dicts of array views (a run's rows are contiguous in its shard)."""
    ids = frame["run"].to_numpy()
    cuts = np.concatenate(([0], np.flatnonzero(ids[1:] != ids[:-1]) + 1, [len(ids)]))
    columns = {c: np.ascontiguousarray(frame[c].to_numpy(), dtype=np.float64) for c in frame.columns if c != "run"}
    runs = [{c: a[s:e] for c, a in columns.items()} for s, e in zip(cuts[:-1], cuts[1:])]
    return runs, [f"run{ids[s]}" for s in cuts[:-1]]


def shard_statistics(frame: pd.DataFrame, model: termid.Model, equations: Sequence[str] = EQUATIONS,
                     derivative: str = "central") -> Dict[str, termid.Moments]:
    """The statistics of every equation over the runs of one shard."""
    runs, names = runs_of(frame)
    return model.moments(list(equations), runs, derivative, names=names)


def merge(*parts: Dict[str, termid.Moments]) -> Dict[str, termid.Moments]:
    """Statistics of several shards as one (associative: any tree gives the same numbers)."""
    out = dict(parts[0])
    for p in parts[1:]:
        out = {eq: out[eq].merge(p[eq]) for eq in out}
    return out


def _timed_shard(path: str, model: termid.Model) -> Tuple[Dict[str, termid.Moments], Dict[str, float]]:
    t0 = time.perf_counter()
    frame = pd.read_parquet(path)
    t1 = time.perf_counter()
    stats = shard_statistics(frame, model)
    t2 = time.perf_counter()
    return stats, {"read_s": t1 - t0, "statistics_s": t2 - t1, "merge_s": 0.0, "rows": float(len(frame))}


def _timed_merge(*parts: Tuple[Dict[str, termid.Moments], Dict[str, float]]):
    t0 = time.perf_counter()
    stats = merge(*[p[0] for p in parts])
    spent = {k: sum(p[1][k] for p in parts) for k in parts[0][1]}
    spent["merge_s"] += time.perf_counter() - t0
    return stats, spent


def identify_on_dask(folder: str, client, model: termid.Model, split_every: int = 8):
    """Every shard of ``folder`` read and reduced to statistics on the workers, merged up a
    tree, the model identified from the result. Returns (identified, timings)."""
    import dask

    paths = sorted(glob.glob(os.path.join(folder, "*.parquet")))
    if not paths:
        raise FileNotFoundError(f"{folder}: no Parquet shards")
    started = time.perf_counter()
    level = [dask.delayed(_timed_shard)(p, model) for p in paths]
    while len(level) > 1:
        level = [dask.delayed(_timed_merge)(*level[i:i + split_every]) for i in range(0, len(level), split_every)]
    stats, spent = client.compute(level[0]).result()
    reduced = time.perf_counter()
    identified = model.identify_from_moments(list(stats.values()))
    spent.update(wall_s=time.perf_counter() - started, select_s=time.perf_counter() - reduced, shards=len(paths))
    return identified, spent


def identify_in_process(folder: str, model: termid.Model):
    """The same rows fitted in one process, for comparison."""
    runs, names = [], []
    for path in sorted(glob.glob(os.path.join(folder, "*.parquet"))):
        more, more_names = runs_of(pd.read_parquet(path))
        runs += more
        names += more_names
    return model.identify(runs, "central", names=names)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = ap.add_subparsers(dest="command", required=True)
    g = sub.add_parser("generate")
    g.add_argument("folder")
    g.add_argument("--rows", type=float, default=1e6, help="about this many rows in all")
    g.add_argument("--shards", type=int, default=16)
    g.add_argument("--runs", type=int, default=48, help="distinct recorded runs (copied up to --rows)")
    i = sub.add_parser("identify")
    i.add_argument("folder")
    i.add_argument("--workers", type=int, default=2)
    i.add_argument("--scheduler", help="address of a running Dask scheduler (default: a LocalCluster)")
    i.add_argument("--compare", action="store_true", help="also fit all rows in this process")
    a = ap.parse_args()
    if a.command == "generate":
        runs = record_runs(a.runs)
        per_copy = sum(len(r) for r in runs)
        copies = max(1, int(round(a.rows / per_copy)))
        rows = write_shards(a.folder, runs, a.shards, copies)
        print(f"wrote {rows:,} rows ({len(runs)} runs × {copies} copies) in {a.shards} shards to {a.folder}")
        return
    from dask.distributed import Client, LocalCluster

    model = fleet_model()
    if a.scheduler:
        client = Client(a.scheduler)
    else:
        client = Client(LocalCluster(n_workers=a.workers, threads_per_worker=1, processes=True))
    with client:
        identified, spent = identify_on_dask(a.folder, client, model)
    rows = spent["rows"]
    print(f"{rows:,.0f} rows in {spent['shards']} shards on {a.workers} workers: {spent['wall_s']:.2f} s wall, "
          f"{rows / spent['wall_s'] / 1e6:.2f} M rows/s")
    print(f"worker time: reading {spent['read_s']:.2f} s, statistics {spent['statistics_s']:.2f} s, "
          f"merging {spent['merge_s']:.3f} s; selection at the client {spent['select_s'] * 1e3:.1f} ms")
    for eq in EQUATIONS:
        print(f"{eq}: {len(identified.model.coefficients(eq))} terms")
    if a.compare:
        t0 = time.perf_counter()
        alone = identify_in_process(a.folder, model)
        print(f"one process: {time.perf_counter() - t0:.2f} s")
        for eq in EQUATIONS:
            x = identified.model.coefficients(eq).set_index("term")["value"]
            y = alone.model.coefficients(eq).set_index("term")["value"]
            print(f"{eq}: same terms {list(x.index) == list(y.index)}, "
                  f"largest relative difference {float(((x - y).abs() / y.abs()).max()):.1e}")


if __name__ == "__main__":
    main()
