"""Estimate a spacecraft's inertia tensor from attitude telemetry.

The Python interface of the ``inertia`` Rust library. Every computation is the
library's: the CSV reader, the estimation pipeline and its report, the simulator, run
as ``inertia estimate`` and ``inertia simulate`` run them, so results and messages are
the command line's. This module only converts arguments and results.

Units are SI throughout: time s, angles rad, rates rad/s, rotor momentum N m s, torque
N m, inertia kg m². Vectors are in body axes. Quaternions are ``[x, y, z, w]``, scalar
last, Hamilton, body → inertial, unless ``scalar_first=True`` (columns hold
``[w, x, y, z]``), ``jpl=True`` (JPL/Shuster: inertial → body, scalar last) or
``conjugate=True`` (Hamilton, inertial → body, scalar last) says otherwise, as the
command line's ``--scalar-first``, ``--jpl`` and ``--conjugate``; gyro rates are rad/s
unless ``gyro_unit="deg/s"`` (``--gyro-unit``).

Quick start::

    import inertia
    sim = inertia.simulate("slew", seed=1)             # telemetry and the true J
    est = inertia.estimate(sim.telemetry)               # the CLI's default estimator
    print(est.status, est.inertia, est.sigma)

``inertia.DataError`` (a ``ValueError``) is raised for bad data, with the command
line's message (file, line and column for a file; argument and row for arrays);
invalid arguments raise ``ValueError`` or ``TypeError`` naming the argument; a file that
cannot be read raises ``OSError``.
"""


from __future__ import annotations

from typing import List, Tuple

from . import _inertia
from ._inertia import DataError
from ._common import CSV_COLUMNS, DEFAULT_ESTIMATOR, HISTORY_COLUMNS, OUTSIDE_COLUMNS
from ._estimation import Estimator, estimate
from ._results import Estimate
from ._simulation import Simulation, plan, simulate
from ._telemetry import Telemetry, read_csv

# The Basilisk converter (`inertia.basilisk`, pure numpy) is written separately; once it
# is in the package it can be imported here (`from . import basilisk`).

__all__ = [
    "CSV_COLUMNS",
    "DEFAULT_ESTIMATOR",
    "HISTORY_COLUMNS",
    "OUTSIDE_COLUMNS",
    "DataError",
    "Estimate",
    "Estimator",
    "Simulation",
    "Telemetry",
    "estimate",
    "estimators",
    "plan",
    "read_csv",
    "simulate",
]

__version__ = "0.1.0"


def estimators() -> List[Tuple[str, str]]:
    """The estimators that can be named in ``estimator=``: ``(name, summary)`` pairs."""
    return list(_inertia.estimators())


# The public names say `inertia.Estimate`, not the private module that defines them (in
# `help()` and in pickles).
for _public in (Estimate, Estimator, Simulation, Telemetry, estimate, plan, read_csv, simulate):
    _public.__module__ = __name__
del _public
