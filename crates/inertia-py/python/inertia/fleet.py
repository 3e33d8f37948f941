"""Fleet-scale runs on Dask: many telemetry files, or Monte Carlo campaigns, as tasks.

Why Dask (``dask.distributed``) rather than Ray: it installs from PyPI as pure Python
(``pip install "dask[distributed]"``), its results are pandas tables, the same code runs
on a laptop (``LocalCluster``), an HPC batch system (dask-jobqueue) or Kubernetes
(dask-kubernetes) by pointing a ``Client`` at the scheduler, and it needs no daemon or
object store of its own. Each task here is independent (one file, or a block of
Monte Carlo runs) and returns a few numbers, which is Dask's simplest case.

Every task calls the package's own :func:`inertia.estimate` (the library's pipeline,
with the GIL released), so a table row is the report ``inertia estimate FILE --json``
would give for that file.

Usage::

    from dask.distributed import Client, LocalCluster
    import inertia.fleet

    client = Client(LocalCluster(n_workers=2, processes=True))   # or Client("tcp://scheduler:8786")
    table = inertia.fleet.estimate_files(["sat1.csv", "sat2.csv"], client=client)
    runs = inertia.fleet.monte_carlo("slew", runs=1000, client=client, gyro_noise=1e-4)

Without a client (``client=None`` and no default client), the tasks run one after
another in this process, so the same code runs without Dask installed.

Workers need the package: ``pip install crates/inertia-py`` in the workers' Python
environment (the same version as the client's). Files are read by the workers: give
paths that the workers see (a shared file system or object-store mounts).
"""

from __future__ import annotations

import os
import time
from typing import Any, Dict, Iterable, List, Optional, Sequence, Union

import numpy as np

from . import DataError, estimate, read_csv, simulate
from ._common import _pandas

__all__ = ["estimate_files", "monte_carlo", "summary", "ELEMENTS"]

#: The elements of J in table columns, in the library's order.
ELEMENTS = ("J11", "J22", "J33", "J12", "J13", "J23")


def _worker() -> Optional[str]:
    try:
        from distributed import get_worker

        return get_worker().address
    except (ImportError, ValueError):
        return None


def _row(est, **extra: Any) -> Dict[str, Any]:
    row: Dict[str, Any] = dict(extra)
    row.update(
        estimator=est.estimator,
        samples=est.samples,
        t=est.t,
        status=est.status,
        reason=est.reason,
    )
    for k, name in enumerate(ELEMENTS):
        row[name] = np.nan if est.j is None else float(est.j[k])
    for k, name in enumerate(ELEMENTS):
        row["s" + name] = np.nan if est.sigma is None else float(est.sigma[k])
    pm = est.principal_moments
    for k in range(3):
        row[f"moment{k + 1}"] = np.nan if pm is None else float(pm[k])
    return row


def _estimate_file(path: str, read: Dict[str, Any], settings: Dict[str, Any], errors: str) -> Dict[str, Any]:
    t0 = time.perf_counter()
    try:
        est = estimate(read_csv(path, **read), **settings)
    except (DataError, ValueError, OSError) as e:
        if errors == "raise":
            raise
        return dict(file=path, error=str(e), seconds=time.perf_counter() - t0, worker=_worker())
    return _row(est, file=path, error=None, seconds=time.perf_counter() - t0, worker=_worker())


def _monte_carlo_block(
    scenario: Optional[str],
    seeds: Sequence[int],
    first_run: int,
    estimators: Sequence[str],
    sim_options: Dict[str, Any],
    settings: Dict[str, Any],
) -> List[Dict[str, Any]]:
    rows = []
    for k, seed in enumerate(seeds):
        t0 = time.perf_counter()
        sim = simulate(scenario, seed=seed, **sim_options)
        for name in estimators:
            est = estimate(sim.telemetry, estimator=name, truth=sim.inertia, **settings)
            within = np.nan  # 1.0 or 0.0 when the estimator gives J and σ
            if est.j is not None and est.sigma is not None:
                j_true = sim.inertia[[0, 1, 2, 0, 0, 1], [0, 1, 2, 1, 2, 2]]
                within = float(np.all(np.abs(est.j - j_true) <= 3 * est.sigma))
            rows.append(
                _row(
                    est,
                    run=first_run + k,
                    seed=seed,
                    relative_error=est.relative_error,
                    within_3sigma=within,
                    seconds=time.perf_counter() - t0,
                    worker=_worker(),
                )
            )
    return rows


def _client(client: Any) -> Any:
    if client is not None:
        return client
    try:
        from distributed import default_client

        return default_client()
    except (ImportError, ValueError):
        return None


def estimate_files(
    paths: Iterable[Union[str, "os.PathLike[str]"]],
    *,
    client: Any = None,
    errors: str = "record",
    scalar_first: bool = False,
    jpl: bool = False,
    conjugate: bool = False,
    gyro_unit: Optional[str] = None,
    columns: Optional[Dict[str, str]] = None,
    unit_tolerance: Optional[float] = None,
    period_tolerance: Optional[float] = None,
    **settings: Any,
):
    """Estimate J from every file, one task per file; one pandas table back.

    Args:
        paths: telemetry CSV files (as :func:`inertia.read_csv` reads them).
        client: a ``dask.distributed.Client`` (default: the current default client;
            with none, the files are estimated here one after another).
        errors: ``"record"`` (default): a file that cannot be read or estimated gives a
            row with the message (the CLI's ``FILE:LINE: …``) in ``error``; ``"raise"``:
            the first such error is raised.
        scalar_first, jpl, conjugate, gyro_unit, columns, unit_tolerance,
        period_tolerance: how to read the
            files (:func:`inertia.read_csv`).
        **settings: estimation settings (:func:`inertia.estimate`; not ``history``).

    Returns:
        A DataFrame in the order of ``paths``: ``file``, ``error``, ``estimator``,
        ``samples``, ``t`` (s), ``status``, ``reason``, ``J11``…``J23`` and ``sJ11``…
        ``sJ23`` (kg m²), ``moment1..3`` (principal moments, kg m²), ``seconds`` (the
        task's time) and ``worker`` (the Dask worker's address).
    """
    if errors not in ("record", "raise"):
        raise ValueError(f'errors={errors!r}: expected "record" or "raise"')
    if settings.get("history"):
        raise ValueError("history: not available in fleet runs (one row per file)")
    read = dict(
        scalar_first=scalar_first,
        jpl=jpl,
        conjugate=conjugate,
        gyro_unit=gyro_unit,
        columns=columns,
        unit_tolerance=unit_tolerance,
        period_tolerance=period_tolerance,
    )
    files = [os.fspath(p) for p in paths]
    pd = _pandas("inertia.fleet")
    c = _client(client)
    if c is None:
        rows = [_estimate_file(f, read, settings, errors) for f in files]
    else:
        futures = c.map(
            _estimate_file, files, read=read, settings=settings, errors=errors, pure=False
        )
        rows = c.gather(futures)
    return pd.DataFrame(rows)


def monte_carlo(
    scenario: Optional[str] = "slew",
    *,
    runs: int = 100,
    seed: int = 1,
    estimators: Sequence[str] = ("discrete-momentum",),
    runs_per_task: int = 4,
    client: Any = None,
    settings: Optional[Dict[str, Any]] = None,
    **sim_options: Any,
):
    """A Monte Carlo campaign: run ``i`` simulates with seed ``seed + i`` (as
    ``inertia monte-carlo``) and estimates with each estimator, against the truth.

    Args:
        scenario: ``"slew"`` or ``"spin"`` (or ``None`` with ``preset=`` in
            ``sim_options``).
        runs: number of runs. seed: the first seed.
        estimators: estimator names (:func:`inertia.estimators`).
        runs_per_task: runs per Dask task (a task should take well over Dask's
            per-task overhead of about a millisecond).
        client: as for :func:`estimate_files`.
        settings: estimation settings (:func:`inertia.estimate`).
        **sim_options: simulation options (:func:`inertia.simulate`: ``duration``,
            ``gyro_noise``, ``disturbance``, ``preset``, …), the same for every run.

    Returns:
        A DataFrame, one row per run and estimator, sorted by run: ``run``, ``seed``,
        ``relative_error``, ``within_3sigma`` and the columns of
        :func:`estimate_files` (without ``file`` and ``error``).
    """
    if runs < 1:
        raise ValueError(f"runs={runs}: at least 1")
    if runs_per_task < 1:
        raise ValueError(f"runs_per_task={runs_per_task}: at least 1")
    settings = dict(settings or {})
    for k in ("estimator", "truth", "history"):
        if k in settings:
            raise ValueError(f"settings: {k} is set by the campaign")
    # Fail on bad options here, not in every task.
    simulate(scenario, seed=seed, **{**sim_options, "duration": 1.0})
    pd = _pandas("inertia.fleet")
    blocks = [
        (list(range(seed + i, seed + min(i + runs_per_task, runs))), i)
        for i in range(0, runs, runs_per_task)
    ]
    c = _client(client)
    if c is None:
        parts = [
            _monte_carlo_block(scenario, s, i, list(estimators), sim_options, settings)
            for s, i in blocks
        ]
    else:
        futures = [
            c.submit(
                _monte_carlo_block, scenario, s, i, list(estimators), sim_options, settings, pure=False
            )
            for s, i in blocks
        ]
        parts = c.gather(futures)
    return pd.DataFrame([row for part in parts for row in part]).sort_values(
        ["run", "estimator"], kind="stable", ignore_index=True
    )


def summary(table) -> Any:
    """Per estimator: runs, the 5/50/95 % percentiles of ``relative_error``, the fraction
    within 3σ and the fraction ``determined`` (a Monte Carlo table)."""
    g = table.groupby("estimator")
    out = g["relative_error"].quantile([0.05, 0.5, 0.95]).unstack()
    out.columns = ["error_p5", "error_p50", "error_p95"]
    out.insert(0, "runs", g.size())
    out["within_3sigma"] = g["within_3sigma"].mean()
    out["determined"] = g["status"].apply(lambda s: float(np.mean(s == "determined")))
    return out
