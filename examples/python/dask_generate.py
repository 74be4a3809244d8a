"""Generate a plan's data set on a Dask cluster: one shard per task, then one merge.

    python examples/python/dask_generate.py --plan paper34 --out data/paper34 --workers 2

Each task runs `railforce.generate(plan, out, shard=(i, N))` (the interpreter released: the
Rust code runs in parallel); the shards write their run files and manifest.shard-i-of-N.json
into the same folder, and `railforce.merge` joins them. The run files and manifest.json are
byte for byte those of one `railforce generate --plan PLAN --out OUT` (CI checks it). Without
--scheduler a LocalCluster with --workers processes of one thread each is started; give
--scheduler tcp://host:8786 to use a running cluster (every worker must see OUT).
"""

from __future__ import annotations

import argparse
import time

import railforce


def generate_shard(plan: str, out: str, i: int, n: int, settle_s: float, snr_db) -> int:
    """One shard, on a worker: returns how many runs it holds."""
    m = railforce.generate(plan, out, shard=(i, n), jobs=1, settle_s=settle_s, snr_db=snr_db)
    return len(m["runs"])


def main(argv=None) -> float:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--plan", default="demo")
    ap.add_argument("--out", required=True)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--shards", type=int, default=None, help="default: one per worker")
    ap.add_argument("--scheduler", default=None)
    ap.add_argument("--settle", type=float, default=3.0)
    ap.add_argument("--snr-db", type=float, default=None)
    args = ap.parse_args(argv)

    from dask.distributed import Client, LocalCluster

    shards = args.shards or args.workers
    t0 = time.perf_counter()
    if args.scheduler:
        client, cluster = Client(args.scheduler), None
    else:
        cluster = LocalCluster(n_workers=args.workers, threads_per_worker=1,
                               processes=True, dashboard_address=None)
        client = Client(cluster)
    try:
        futures = [
            client.submit(generate_shard, args.plan, args.out, i, shards, args.settle,
                          args.snr_db, pure=False)
            for i in range(1, shards + 1)
        ]
        runs = sum(client.gather(futures))
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
    m = railforce.merge(args.out)
    wall = time.perf_counter() - t0
    print(f"{runs} runs in {shards} shards on {args.workers} workers: {len(m['runs'])} merged "
          f"into {args.out}/manifest.json in {wall:.1f} s")
    return wall


if __name__ == "__main__":
    main()
