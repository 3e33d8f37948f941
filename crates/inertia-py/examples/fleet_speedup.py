"""Speed-up of fleet runs from one to two Dask worker processes (README "Fleet runs on
Dask"). Usage: python fleet_speedup.py [RUNS] [FILES]

Times a Monte Carlo campaign (RUNS slew runs, discrete momentum estimator) and the
estimation of FILES telemetry files (60,001 samples each), each on a LocalCluster with
1 and then 2 worker processes of one thread; cluster start-up and the workers' first
import are not timed.
"""

import sys
import tempfile
import time
from pathlib import Path

from dask.distributed import Client, LocalCluster

import inertia
from inertia import fleet


def timed(f):
    t0 = time.perf_counter()
    r = f()
    return time.perf_counter() - t0, r


def main() -> None:
    runs = int(sys.argv[1]) if len(sys.argv) > 1 else 32
    nfiles = int(sys.argv[2]) if len(sys.argv) > 2 else 8
    d = Path(tempfile.mkdtemp())
    files = []
    for k in range(nfiles):
        p = d / f"sat{k}.csv"
        inertia.simulate("slew", seed=k + 1, duration=6000).telemetry.to_dataframe().to_csv(p, index=False)
        files.append(p)
    times = {}
    for workers in (1, 2):
        with LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None) as cluster, Client(cluster) as client:
            fleet.monte_carlo("slew", runs=2 * workers, runs_per_task=1, client=client, duration=10.0)  # warm-up
            t_mc, table = timed(lambda: fleet.monte_carlo("slew", runs=runs, runs_per_task=2, client=client))
            t_files, ft = timed(lambda: fleet.estimate_files(files, client=client))
            assert ft["error"].isna().all() and table["worker"].nunique() == workers
            times[workers] = (t_mc, t_files)
            print(f"{workers} worker(s): monte carlo {runs} runs {t_mc:.2f} s, {nfiles} files {t_files:.2f} s", flush=True)
    (m1, f1), (m2, f2) = times[1], times[2]
    print(f"speed-up 1 -> 2 workers: monte carlo {m1 / m2:.2f}x, files {f1 / f2:.2f}x")


if __name__ == "__main__":
    main()
