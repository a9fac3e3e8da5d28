"""Benchmark of a monitoring campaign (issue 14): throughput and what the trend finds.

A synthetic campaign of ``--sets`` measured sets on the paper's beam (problems/
ss-steel-beam.toml; 5 modes at 15 sensors, 0.3 % shape and 0.05 % frequency noise; truths on
a fine independent mesh): no crack for the first fifth of the sets, then a crack at x = 0.19 m
growing linearly to a/d = 0.5 at the last set, E moving ±1 % with a daily cycle (hourly
sets).  Every set is updated with ``--add material --add crack`` three ways, side by side in
one run: serially (one process), with the local pool (``--workers``, default every core) and
on a local Dask cluster of as many worker processes.  Prints JSON:

* sets per second of each, the pool's speed-up over serial and Dask's overhead against the
  pool (positive: slower; Dask's workers with MALLOC_TRIM_THRESHOLD_ raised to 128 MiB, as
  the README advises);
* whether the three tables are identical (apart from the seconds column);
* the crack: the first set where the truth exceeds a/d = 0.1, the first set ``gfe-opt
  trend`` flags, their distance as a share of the campaign, the rms error of a/d after the
  flag, and whether a crack was flagged before one existed.

    python scripts/bench_batch.py [--sets 500] [--workers 2] [--keep DIR]
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from gfe_opt.batch import read_table, run_batch  # noqa: E402
from gfe_opt.model import load_model  # noqa: E402
from gfe_opt.trend import trend  # noqa: E402
from tests.truths import write_campaign  # noqa: E402

ADD = ["material", "crack"]
TRIM_THRESHOLD = 128 * 2**20


def _without_seconds(rows):
    return [{k: v for k, v in r.items() if k != "seconds"} for r in rows]


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sets", type=int, default=500)
    parser.add_argument("--workers", type=int, default=os.cpu_count() or 1)
    parser.add_argument("--keep", type=Path, default=None,
                        help="keep the campaign and the tables in this folder")
    args = parser.parse_args(argv)
    work = Path(tempfile.mkdtemp(prefix="gfe-bench-batch-")) if args.keep is None else args.keep
    work.mkdir(parents=True, exist_ok=True)
    model_path = ROOT / "problems" / "ss-steel-beam.toml"
    model = load_model(model_path)
    start = time.perf_counter()
    truths = write_campaign(model, work / "sets", args.sets)
    out = {"sets": args.sets, "workers": args.workers,
           "campaign_seconds": round(time.perf_counter() - start, 1)}

    def timed(name, **options):
        table = work / f"{name}.parquet"
        if table.exists():
            table.unlink()
        t0 = time.perf_counter()
        result = run_batch(model_path, work / "sets", table, add=ADD, **options)
        seconds = time.perf_counter() - t0
        out[name] = {"seconds": round(seconds, 1), "sets_per_second": round(args.sets / seconds, 3),
                     "failed": result.failed}
        print(f"{name}: {seconds:.1f} s", file=sys.stderr, flush=True)
        return read_table(table)

    serial = timed("serial", workers=1)
    pool = timed("pool", workers=args.workers)
    import dask as dask_config
    from distributed import LocalCluster

    # Dask's nannies start workers with MALLOC_TRIM_THRESHOLD_=65536: glibc then hands
    # memory back to the system after every numpy temporary, and each set takes 1.45 s
    # instead of 1.10 s (measured on 500 sets).  The README tells cluster users to raise it.
    with dask_config.config.set({"distributed.nanny.pre-spawn-environ."
                                 "MALLOC_TRIM_THRESHOLD_": TRIM_THRESHOLD}), \
            LocalCluster(n_workers=args.workers, threads_per_worker=1, processes=True,
                         dashboard_address=None) as cluster:
        dask = timed("dask", scheduler=cluster.scheduler_address)
    out["pool_speedup"] = round(out["serial"]["seconds"] / out["pool"]["seconds"], 3)
    out["dask_overhead_vs_pool"] = round(out["dask"]["seconds"] / out["pool"]["seconds"] - 1, 3)
    out["identical_tables"] = (_without_seconds(serial) == _without_seconds(pool)
                               == _without_seconds(dask))

    t = trend(pool)
    depth = np.array([d for d, _ in truths])
    exists = int(np.argmax(depth > 0))
    above = int(np.argmax(depth > 0.1))
    onset = next((o for o in t.onsets if o.effect == "crack"), None)
    found = t.parameters["crack.depth_ratio"][0]
    crack = {"truth_first_crack_set": exists + 1, "truth_first_set_above_0.1": above + 1,
             "flagged_set": None if onset is None else onset.index + 1}
    if onset is not None:
        crack["flag_after_0.1_share_of_campaign"] = round((onset.index - above) / args.sets, 4)
        after = np.arange(args.sets) >= onset.index
        crack["depth_rms_error_after_flag"] = round(float(np.sqrt(np.mean(
            (found[after] - depth[after]) ** 2))), 4)
        crack["flagged_before_it_existed"] = bool(onset.index < exists)
    sizes = np.array([r.get("crack.size_sigmas") or 0.0 for r in pool])
    crack["sets_before_crack_over_3_sigma"] = int(np.sum(sizes[:exists] >= 3.0))
    E = t.parameters["material.E"][0] / model.E
    crack["E_factor_rms_error"] = round(float(np.sqrt(np.mean(
        (E - np.array([f for _, f in truths])) ** 2))), 5)
    out["crack"] = crack
    print(json.dumps(out, indent=1))
    if args.keep is None:
        shutil.rmtree(work, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
