"""Speed-up of fleet runs from one to two Dask worker processes (README "Fleet runs on
Dask"). Usage: python fleet_speedup.py [RUNS] [FILES] [REPEATS]

Times a Monte Carlo campaign (RUNS slew runs, discrete momentum estimator, 2 runs per
task) and the estimation of FILES telemetry files (60,001 samples each, one task per
file) on a LocalCluster of 1 and one of 2 worker processes (one thread each),
alternating, REPEATS times, and prints the medians. Cluster start-up and the workers'
first import are not timed. On a shared machine the figure is what the other load
leaves: run it on an idle one.
"""

import os
import statistics
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
    repeats = int(sys.argv[3]) if len(sys.argv) > 3 else 3
    d = Path(tempfile.mkdtemp())
    files = []
    for k in range(nfiles):
        p = d / f"sat{k}.csv"
        inertia.simulate("slew", seed=k + 1, duration=6000).telemetry.to_dataframe().to_csv(p, index=False)
        files.append(p)
    clusters = {
        w: LocalCluster(n_workers=w, threads_per_worker=1, processes=True, dashboard_address=None)
        for w in (1, 2)
    }
    clients = {w: Client(c) for w, c in clusters.items()}
    for w, c in clients.items():  # warm-up: the workers import the package
        fleet.monte_carlo("slew", runs=2 * w, runs_per_task=1, client=c, duration=10.0)
    times = {(w, what): [] for w in (1, 2) for what in ("mc", "files")}
    for rep in range(repeats):
        for w, c in clients.items():
            t_mc, table = timed(lambda: fleet.monte_carlo("slew", runs=runs, runs_per_task=2, client=c))
            t_files, ft = timed(lambda: fleet.estimate_files(files, client=c))
            assert ft["error"].isna().all() and table["worker"].nunique() == w
            times[(w, "mc")].append(t_mc)
            times[(w, "files")].append(t_files)
            print(f"repeat {rep}, {w} worker(s): monte carlo {runs} runs {t_mc:.2f} s, "
                  f"{nfiles} files {t_files:.2f} s (load average {os.getloadavg()[0]:.1f})", flush=True)
    med = {k: statistics.median(v) for k, v in times.items()}
    for what, label in (("mc", f"monte carlo ({runs} runs)"), ("files", f"files ({nfiles})")):
        print(f"{label}: median {med[(1, what)]:.2f} s -> {med[(2, what)]:.2f} s, "
              f"speed-up {med[(1, what)] / med[(2, what)]:.2f}x")
    for c in clients.values():
        c.close()
    for c in clusters.values():
        c.close()


if __name__ == "__main__":
    main()
