"""Telemetry in memory and the CSV reader (:class:`Telemetry`, :func:`read_csv`)."""

from __future__ import annotations

import os
import warnings
from typing import Any, Dict, Mapping, Optional, Union

import numpy as np

from . import _inertia
from ._common import _arrays, _pandas


class Telemetry:
    """Telemetry held in memory, checked, in this library's convention.

    Made by :func:`read_csv`, :func:`simulate` or :meth:`Telemetry.from_arrays`.
    Attributes (numpy arrays, SI units, body axes): ``t`` (N,) s; ``q`` (N, 4)
    ``[x, y, z, w]`` Hamilton body → inertial, unit norm; ``rho`` (N, 3) N m s; ``tau``
    (N, 3) N m (with commanded dipoles, their torque m × B included); ``w`` (N, 3) rad/s
    or ``None``; the outside measurements ``r`` (N, 3) m (inertial position), ``b``
    (N, 3) T (magnetic field) and ``f`` (N, 3) N (external force), each or ``None``;
    ``file`` and ``lines`` (each sample's line) for a file; ``stats``: what the reader
    counted.
    """

    __slots__ = ("_native",)

    def __init__(self, native: "_inertia.Telemetry") -> None:
        self._native = native

    @classmethod
    def from_arrays(
        cls,
        t: Any,
        q: Any,
        rho: Any,
        tau: Any = None,
        w: Any = None,
        r: Any = None,
        b: Any = None,
        f: Any = None,
        dipole: Any = None,
        *,
        scalar_first: bool = False,
        jpl: bool = False,
        conjugate: bool = False,
        gyro_unit: Optional[str] = None,
        negate_rho: bool = False,
        unit_tolerance: Optional[float] = None,
        period_tolerance: Optional[float] = None,
    ) -> "Telemetry":
        """Check arrays (shapes and meanings as for :func:`estimate`) into telemetry. A
        commanded ``dipole`` is not kept: its torque m × B is added to ``tau``."""
        a = _arrays(t, q, rho, tau, w, r, b, f, dipole)
        return cls(
            _inertia.samples_from_arrays(
                *a,
                kwargs=dict(
                    scalar_first=scalar_first,
                    jpl=jpl,
                    conjugate=conjugate,
                    gyro_unit=gyro_unit,
                    negate_rho=negate_rho,
                    unit_tolerance=unit_tolerance,
                    period_tolerance=period_tolerance,
                ),
            )
        )

    t = property(lambda self: self._native.t, doc="Time, s (N,).")
    q = property(lambda self: self._native.q, doc="Quaternions [x, y, z, w] (N, 4).")
    rho = property(lambda self: self._native.rho, doc="Rotor momentum, N m s (N, 3).")
    tau = property(lambda self: self._native.tau, doc="Known torque, N m (N, 3).")
    w = property(lambda self: self._native.w, doc="Gyro rates, rad/s (N, 3), or None.")
    r = property(lambda self: self._native.r, doc="Inertial position, m (N, 3), or None.")
    b = property(lambda self: self._native.b, doc="Magnetic field, T, body axes (N, 3), or None.")
    f = property(lambda self: self._native.f, doc="External force, N, body axes (N, 3), or None.")
    file = property(lambda self: self._native.file, doc="The file's name, or None.")
    lines = property(lambda self: self._native.lines, doc="Each sample's line, or None.")
    stats = property(lambda self: self._native.stats, doc="What the reader counted.")

    def __len__(self) -> int:
        return len(self._native)

    def __repr__(self) -> str:
        src = f" from {self.file!r}" if self.file else ""
        gyro = "with" if self.w is not None else "without"
        return f"<inertia.Telemetry: {len(self)} samples{src}, {gyro} gyro rates>"

    def to_dataframe(self):
        """A pandas DataFrame with the CSV column names (``w_*`` only with rates; ``r_*``,
        ``b_*``, ``f_*`` only with those measurements; commanded dipoles are in ``tau_*``).

        ``rho`` is the rotor momentum as read; where a spacecraft file gave it from the
        wheel speeds, their σ do not travel with the frame (a warning says so: estimate
        the Telemetry itself to keep them). Where the attitude was integrated from the
        gyro, ``q_*`` are those integrated quaternions."""
        pd = _pandas("Telemetry.to_dataframe")
        if self._native.rotors_state() is not None:
            warnings.warn(
                "to_dataframe: rho holds the momentum from the wheel speeds, but the "
                "spacecraft file's σ do not travel with the frame; estimate the Telemetry "
                "itself to keep them",
                stacklevel=2,
            )
        cols: Dict[str, np.ndarray] = {"t": self.t}
        blocks = (("q", self.q), ("rho", self.rho), ("tau", self.tau), ("w", self.w),
                  ("r", self.r), ("b", self.b), ("f", self.f))
        for name, block in blocks:
            if block is None:
                continue
            axes = "xyzw" if name == "q" else "xyz"
            for k, a in enumerate(axes):
                cols[f"{name}_{a}"] = block[:, k]
        return pd.DataFrame(cols)

    def __reduce__(self):
        st = self.stats
        state = (st["rows"], st["renormalised"], st["sign_flips"], st["min_step_s"], st["max_step_s"],
                 st["attitude_from_gyro"])
        lines = None if self.lines is None else [int(x) for x in self.lines]
        return (
            _restore_telemetry,
            (self.t, self.q, self.rho, self.tau, self.w, self.file, lines, state,
             self._native.q_columns, self._native.label, self._native.rotors_state(),
             self.r, self.b, self.f),
        )


def _restore_telemetry(*state) -> Telemetry:
    return Telemetry(_inertia.restore(*state))


def read_csv(
    path: Union[str, "os.PathLike[str]"],
    *,
    scalar_first: bool = False,
    jpl: bool = False,
    conjugate: bool = False,
    gyro_unit: Optional[str] = None,
    negate_rho: bool = False,
    columns: Optional[Mapping[str, str]] = None,
    unit_tolerance: Optional[float] = None,
    period_tolerance: Optional[float] = None,
    spacecraft: Union[None, str, "os.PathLike[str]"] = None,
) -> Telemetry:
    """Read a telemetry CSV file as ``inertia estimate`` reads it.

    Columns (matched by name, extra ones ignored): ``t`` (s, or ISO-8601 UTC time
    stamps), ``q_x,q_y,q_z,q_w``, ``rho_x,rho_y,rho_z`` (N m s), optional
    ``tau_x,tau_y,tau_z`` (N m) and ``w_x,w_y,w_z`` (rad/s), and the optional outside
    measurements (:data:`OUTSIDE_COLUMNS`): ``r_x,r_y,r_z`` (inertial position, m),
    ``b_x,b_y,b_z`` (magnetic field, T), ``f_x,f_y,f_z`` (force, N) and
    ``dipole_x,dipole_y,dipole_z`` (commanded dipole, A m², needs ``b_*``).

    Args:
        path: the file.
        scalar_first: the quaternion columns hold ``[w, x, y, z]`` (``--scalar-first``).
        jpl: JPL/Shuster quaternions, inertial → body (``--jpl``; the same numbers as
            this library's Hamilton body → inertial ones).
        conjugate: Hamilton quaternions mapping inertial → body, scalar last: read
            conjugated (``--conjugate``).
        gyro_unit: the unit of the ``w_*`` columns, ``"rad/s"`` (default, ``None``) or
            ``"deg/s"`` (``--gyro-unit``).
        negate_rho: the rho columns hold the rotor momentum with the opposite sign
            (e.g. the wheels' reaction on the body): negate them (``--negate-rho``).
        columns: renamed columns, ``{"t": "time", "rho_x": "hw_x"}`` (``--column``).
        unit_tolerance: largest ``| |q| − 1 |`` renormalised (default 1e-3).
        period_tolerance: strict mode: a step differing from the first by more than
            this (relative) is an error.
        spacecraft: a spacecraft file (TOML, ``--spacecraft``): the rotors' axes, spin
            inertias ± σ and speed columns. ``rho`` is computed from the wheel speeds
            (the file then has no ``rho_*`` columns), and the spin inertias' σ widen
            the estimate's σ.

    Raises:
        DataError: the CLI's message, ``FILE:LINE: column …``; ``.line`` is the line.
        OSError: the file cannot be read.
    """
    return Telemetry(
        _inertia.read_csv(
            os.fspath(path),
            kwargs=dict(
                scalar_first=scalar_first,
                jpl=jpl,
                conjugate=conjugate,
                gyro_unit=gyro_unit,
                negate_rho=negate_rho,
                columns=None if columns is None else dict(columns),
                unit_tolerance=unit_tolerance,
                period_tolerance=period_tolerance,
                spacecraft=None if spacecraft is None else os.fspath(spacecraft),
            ),
        )
    )
