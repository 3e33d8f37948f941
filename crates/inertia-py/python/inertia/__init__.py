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

import dataclasses
import json
import os
import re
import warnings
from typing import Any, Dict, Iterator, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np

from . import _inertia
from ._inertia import DataError

# The Basilisk converter (`inertia.basilisk`, pure numpy) is written separately; once it
# is in the package it can be imported here (`from . import basilisk`).

__all__ = [
    "DEFAULT_ESTIMATOR",
    "HISTORY_COLUMNS",
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

#: The estimator ``inertia estimate`` runs by default (the discrete momentum estimator).
DEFAULT_ESTIMATOR: str = _inertia.DEFAULT_ESTIMATOR

#: Columns of an estimate history (the CLI's ``-o`` CSV, schema version 1).
HISTORY_COLUMNS: Tuple[str, ...] = (
    "t", "J11", "J22", "J33", "J12", "J13", "J23", "status", "condition", "iterations",
    "sJ11", "sJ22", "sJ33", "sJ12", "sJ13", "sJ23", "reason",
)

#: The CSV column names, in the order t, q (4), rho (3), tau (3), w (3).
CSV_COLUMNS: Tuple[str, ...] = (
    "t", "q_x", "q_y", "q_z", "q_w", "rho_x", "rho_y", "rho_z",
    "tau_x", "tau_y", "tau_z", "w_x", "w_y", "w_z",
)

#: The optional columns of outside measurements, in the order r (inertial position, m),
#: b (magnetic field, T, body axes), f (external force, N, body axes), dipole (commanded
#: magnetic dipole, A m², body axes): the arguments ``r``, ``b``, ``f``, ``dipole``.
OUTSIDE_COLUMNS: Tuple[str, ...] = (
    "r_x", "r_y", "r_z", "b_x", "b_y", "b_z", "f_x", "f_y", "f_z",
    "dipole_x", "dipole_y", "dipole_z",
)


def _pandas(what: str):
    try:
        import pandas
    except ImportError as e:  # pragma: no cover - exercised without pandas only
        raise ImportError(
            f"{what} needs pandas, which is not installed: pip install pandas"
        ) from e
    return pandas


def estimators() -> List[Tuple[str, str]]:
    """The estimators that can be named in ``estimator=``: ``(name, summary)`` pairs."""
    return list(_inertia.estimators())


# --------------------------------------------------------------------------- results


def _array(v: Any) -> Optional[np.ndarray]:
    return None if v is None else np.array(v, dtype=np.float64)


@dataclasses.dataclass(frozen=True, eq=False)
class Estimate:
    """The result of an estimation run: the command line's report.

    Attributes:
        inertia: J, kg m², 3×3 (``None`` when the data cannot determine J).
        j: ``[J11, J22, J33, J12, J13, J23]``, kg m² (products are tensor entries,
            ``J12 = −Σ m x y``).
        sigma: one standard deviation of each element of ``j``, kg m² (noise,
            discretisation bias and, when ``rotor_scale_sigma`` or ``torque_scale_sigma``
            was given, the wheels' or the known torque's scale:
            ``report["rotor_scale_sigma_kg_m2"]``, ``report["torque_scale_sigma_kg_m2"]``),
            or ``None`` for estimators without an uncertainty model.
        status: ``"determined"``, ``"from_prior"``, ``"not_observable"``,
            ``"unchecked"`` (no observability test, or no σ) or ``"model_check_failed"``
            (an answer with its σ that breaks J1 > 0 or J1 + J2 ≥ J3 beyond 3σ).
        reason: why the data fall short, when they do (else ``None``).
        condition: σ₁/σ₆ of the information factor R when determined.
        principal_moments: ascending, kg m² (3,).
        principal_moments_sigma: their standard deviations, kg m² (3,).
        principal_axes: the principal axes as columns, body axes (3×3).
        t: time of the estimate, s.
        samples: samples the estimator saw (after resampling).
        estimator: the estimator's name.
        relative_error: ‖J − J_true‖_F/‖J_true‖_F when ``truth=`` was given.
        torque_bias_nm: estimated constant body-frame disturbance torque, N m (3,);
            ``None`` where it is not estimated or the data gave no evidence of one and it
            was held at zero (``report["torque_test"]``: ``chi2``, ``held_at_zero``).
            The torques of outside measurements (``r``, ``b``, ``f``) are reported in
            ``report["outside"]``: ``gravity_gradient`` (whether modelled),
            ``residual_dipole_am2`` (A m²) and ``centre_of_mass_m`` (m), each
            ``{"value": [3], "sigma": [3] or None}`` or ``None``; the report has no
            ``outside`` key where none of them is modelled.
        warnings: every ``warning:`` line of the text report (the JSON's ``warnings``
            messages), none of which contradicts ``status``.
        report: the whole report as a dict (the ``inertia estimate --json`` schema).
        text: the readable report (``inertia estimate`` without ``--json``).

    With ``history=True`` the estimate history is ``.history`` (a pandas DataFrame with
    :data:`HISTORY_COLUMNS`; pandas is needed only then). Estimates pickle.
    """

    inertia: Optional[np.ndarray]
    j: Optional[np.ndarray]
    sigma: Optional[np.ndarray]
    status: str
    reason: Optional[str]
    condition: Optional[float]
    principal_moments: Optional[np.ndarray]
    principal_moments_sigma: Optional[np.ndarray]
    principal_axes: Optional[np.ndarray]
    t: float
    samples: int
    estimator: str
    relative_error: Optional[float]
    torque_bias_nm: Optional[np.ndarray]
    warnings: List[str]
    report: Dict[str, Any] = dataclasses.field(repr=False)
    text: str = dataclasses.field(repr=False)
    history_columns: Optional[Dict[str, Any]] = dataclasses.field(default=None, repr=False)

    @classmethod
    def _from_native(cls, native: Tuple[str, str, Optional[Dict[str, Any]]]) -> "Estimate":
        report_json, text, history = native
        r = json.loads(report_json)
        return cls(
            inertia=_array(r["inertia"]),
            j=_array(r["j"]),
            sigma=_array(r["sigma"]),
            status=r["status"],
            reason=r["reason"],
            condition=r["condition"],
            principal_moments=_array(r["principal_moments"]),
            principal_moments_sigma=_array(r["principal_moments_sigma"]),
            principal_axes=_array(r["principal_axes"]),
            t=r["t"],
            samples=r["samples"],
            estimator=r["estimator"],
            relative_error=r["relative_error"],
            torque_bias_nm=_array(r["torque_bias_nm"]),
            warnings=[w["message"] for w in r["warnings"]],
            report=r,
            text=text,
            history_columns=history,
        )

    @property
    def determined(self) -> bool:
        """``True`` when the data determine J (status ``"determined"``)."""
        return self.status == "determined"

    @property
    def history(self):
        """The estimate history as a pandas DataFrame (``history=True`` runs only).

        Columns :data:`HISTORY_COLUMNS`: ``t`` s; ``J..`` and ``sJ..`` kg m² (NaN where
        not available); ``status``; ``condition``; ``iterations``; ``reason``.
        """
        if self.history_columns is None:
            raise ValueError("no history: estimate with history=True")
        pd = _pandas("Estimate.history")
        return pd.DataFrame({c: self.history_columns[c] for c in HISTORY_COLUMNS})

    def to_dict(self) -> Dict[str, Any]:
        """The report as a JSON-compatible dict: the ``inertia estimate --json`` object."""
        return json.loads(json.dumps(self.report))

    def __str__(self) -> str:
        return self.text


# ------------------------------------------------------------------------- telemetry


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


# ------------------------------------------------------------------------ estimation


def _float_array(name: str, x: Any, shape: str) -> np.ndarray:
    try:
        a = np.asarray(x)
    except Exception as e:  # noqa: BLE001 - anything numpy cannot take
        raise TypeError(f"{name}: expected an array of numbers {shape}, got {type(x).__name__}") from e
    if a.dtype.kind not in "iuf":
        raise TypeError(
            f"{name}: expected an array of numbers {shape}, got an array of dtype {a.dtype}"
        )
    return np.ascontiguousarray(a, dtype=np.float64)


def _arrays(t, q, rho, tau, w, r=None, b=None, f=None, dipole=None):
    def optional(name: str, x: Any) -> Optional[np.ndarray]:
        return None if x is None else _float_array(name, x, "(N, 3)")

    return (
        _float_array("t", t, "(N,)"),
        None if q is None else _float_array("q", q, "(N, 4)"),
        _float_array("rho", rho, "(N, 3)"),
        optional("tau", tau),
        optional("w", w),
        optional("r", r),
        optional("b", b),
        optional("f", f),
        optional("dipole", dipole),
    )


def _is_frame(x: Any) -> bool:
    return hasattr(x, "columns") and hasattr(x, "iloc")


def _frame_arrays(df: Any, columns: Optional[Mapping[str, str]]):
    known = CSV_COLUMNS + OUTSIDE_COLUMNS
    names = list(known)
    for k, v in (columns or {}).items():
        if k not in known:
            raise ValueError(
                f"columns: unknown column {k!r} (known: t, q_x, q_y, q_z, q_w, rho_*, tau_*, "
                "w_*, r_*, b_*, f_*, dipole_*)"
            )
        names[known.index(k)] = v
    present = [str(c) for c in df.columns]
    if len(set(present)) != len(present):
        dup = next(c for c in present if present.count(c) > 1)
        raise DataError(f"<DataFrame>: column `{dup}` appears twice")

    def need(n: str) -> np.ndarray:
        if n not in present:
            raise DataError(f"<DataFrame>: missing column `{n}` (columns present: {','.join(present)})")
        return df[n].to_numpy()

    def optional(block: List[str]) -> Optional[np.ndarray]:
        if not any(n in present for n in block):
            return None
        return np.column_stack([_float_array(n, need(n), "(N,)") for n in block])

    need(names[0])
    t = df[names[0]]
    if str(t.dtype).startswith("datetime64"):
        # Elapsed seconds since the first row (pandas' datetimes have no leap seconds).
        t = (t - t.iloc[0]).dt.total_seconds()
    t = _float_array(names[0], t.to_numpy(), "(N,)")
    # No quaternion column at all (none renamed, none that looks like one) and every gyro
    # column: the attitude is integrated from the gyro rates, as for such a CSV file.
    looks_like_q = any(re.fullmatch(r"(q|quat|quaternion)[_ ]?([0-3]|[xyzws]|scalar)", c.lower()) for c in present)
    gyro_only = (
        not any(n in present for n in names[1:5])
        and names[1:5] == list(CSV_COLUMNS[1:5])
        and all(n in present for n in names[11:14])
        and not looks_like_q
    )
    q = None if gyro_only else np.column_stack([_float_array(n, need(n), "(N,)") for n in names[1:5]])
    rho = np.column_stack([_float_array(n, need(n), "(N,)") for n in names[5:8]])
    blocks = [optional(names[k:k + 3]) for k in range(8, len(names), 3)]
    return names, (t, q, rho, *blocks)


#: The estimation settings and the input conventions, as :func:`estimate` and
#: :class:`Estimator` name them: the library's run description's keys (the command line's
#: options, in snake case; ``inertia estimate --settings`` reads the same keys from a
#: file). The native side maps them onto the description generically.
_SETTINGS = tuple(_inertia.SETTINGS_KEYS)
#: How the data are read (``columns`` and ``spacecraft`` go to :func:`read_csv` apart).
_CONVENTIONS = tuple(k for k in _inertia.INPUT_KEYS if k not in ("columns", "spacecraft"))


def _settings(arguments: Mapping[str, Any], names: Sequence[str] = _SETTINGS) -> Dict[str, Any]:
    """The named arguments a function has, with matrices as nested lists for the native
    side."""
    kw = {k: arguments[k] for k in names if k in arguments}
    for key in ("nominal", "truth", "prior"):
        if kw.get(key) is not None:
            kw[key] = _float_array(key, kw[key], "(3, 3)").tolist()
    sigma = kw.get("prior_sigma")
    if sigma is not None and not isinstance(sigma, (str, int, float)):
        kw["prior_sigma"] = _float_array("prior_sigma", sigma, "(3, 3)").tolist()
    return kw


def estimate(
    t: Any,
    q: Any = None,
    rho: Any = None,
    *,
    tau: Any = None,
    w: Any = None,
    r: Any = None,
    b: Any = None,
    f: Any = None,
    dipole: Any = None,
    estimator: str = DEFAULT_ESTIMATOR,
    constraints: str = "physical",
    bounds: Union[None, str, Sequence[str], Mapping[str, Tuple[Optional[float], Optional[float]]]] = None,
    nominal: Any = None,
    tolerance: Union[None, float, str] = None,
    diagonal: bool = False,
    prior: Any = None,
    prior_sigma: Any = None,
    products: str = "tensor",
    gyro_noise: Optional[float] = None,
    attitude_drift: Optional[float] = None,
    memory: Optional[float] = None,
    resample: Optional[float] = None,
    every: int = 1,
    rotation_source: Optional[str] = None,
    rho_model: str = "auto",
    torque_bias: bool = True,
    inertial_torque: str = "short",
    damping: bool = False,
    calibrate_rotors: bool = False,
    outside: Optional[Mapping[str, Any]] = None,
    rotor_scale_sigma: Optional[float] = None,
    torque_scale_sigma: Optional[float] = None,
    filter_cutoff_hz: Optional[float] = None,
    chain: float = 30.0,
    wheel_delay: Union[None, str, float] = None,
    glitches: str = "stop",
    solver: str = "native",
    uncertainty: bool = True,
    batch: bool = False,
    history: bool = False,
    truth: Any = None,
    scalar_first: bool = False,
    jpl: bool = False,
    conjugate: bool = False,
    gyro_unit: Optional[str] = None,
    negate_rho: bool = False,
    columns: Optional[Mapping[str, str]] = None,
    unit_tolerance: Optional[float] = None,
    period_tolerance: Optional[float] = None,
    spacecraft: Union[None, str, "os.PathLike[str]"] = None,
) -> Estimate:
    """Estimate the inertia tensor, as ``inertia estimate`` does.

    The data are one of:

    * arrays ``t`` (N,) s, ``q`` (N, 4), ``rho`` (N, 3) N m s, and optionally
      ``tau=`` (N, 3) N m (known external torque) and ``w=`` (N, 3) rad/s (gyro rate
      averaged over [t_k, t_{k+1}]); ``q=None`` with ``w=``: the attitude is integrated
      from the gyro rates (as for a file without quaternion columns). Optional outside
      measurements, each (N, 3), for every sample: ``r=`` the position of the centre of
      mass in the attitude's inertial frame, m (the gravity-gradient torque is modelled;
      needs ``q``), ``b=`` the magnetic field, T, body axes (a residual magnetic dipole
      is estimated), ``f=`` the external force, N, body axes (the centre of mass is
      estimated, ``tau`` then taken about the body frame's origin), ``dipole=`` the
      commanded magnetic dipole, A m², body axes (needs ``b``; its torque m × B is
      added to ``tau``);
    * a pandas DataFrame with the CSV column names (``t``, ``q_x`` …, the outside
      measurements' ``r_x`` … ``dipole_z`` of :data:`OUTSIDE_COLUMNS`, renamed by
      ``columns=``), as the only positional argument;
    * a :class:`Telemetry` (from :func:`read_csv` or :func:`simulate`);
    * a path: the file is read with :func:`read_csv` first. Unlike the CLI, which
      streams, the whole file is read before the estimator runs (about 0.1 kB of
      memory per sample), so when a file holds both a bad row and, earlier, a step the
      estimator stops on, the bad row is reported.
    * a list of paths or :class:`Telemetry`: several records of one spacecraft (passes,
      throws), estimated together with ``batch=True``: one J, each record its own
      initial momenta and torques, its own time axis (``report["records"]``).

    Settings (the command line's options, same names and defaults):
        estimator: ``"discrete-momentum"`` (default), ``"variational"`` (the paper's),
            ``"finite-difference"``, ``"momentum"`` (:func:`estimators`).
        constraints: ``"physical"`` (J ⪰ εI and Σ = ½tr(J)I − J ⪰ 0), ``"paper"``,
            ``"positive-definite"``.
        bounds: element bounds, kg m²: ``{"J33": (2.7, 3.3), "J12": (None, 0.05)}`` or
            ``["J33=2.7:3.3"]`` (``--bound``).
        nominal, tolerance: a nominal 3×3 J (kg m²) bounding every element within a
            fraction (``0.1`` or ``"10%"``).
        diagonal: fix every product of inertia at zero (an equality the solver
            eliminates; ``bounds={"J12": (0, 0)}`` fixes one).
        prior, prior_sigma: a Gaussian prior (e.g. from CAD): a 3×3 J, kg m², and its
            standard deviation: ``"5%"`` (moments ±5 %·|J_ii|, products
            ±5 %·√(J_ii J_jj)), a number (kg m², every element) or a 3×3 matrix.
            ``Estimate.to_dict()["prior"]`` gives the prior-data χ² and the fraction of
            each element's information from the data (``--prior``).
        products: how products of inertia are written in ``nominal``, ``prior`` and
            product ``bounds``: ``"tensor"`` (J12 = −Σ m x y, default) or ``"cad"``
            (+Σ m x y).
        gyro_noise: the gyro's rate-noise density, deg/s/√Hz (errors-in-variables
            compensation). ``None`` (default): the discrete momentum estimator estimates
            it from the rates where their differences are noise
            (``report["gyro_noise_estimated_deg_s_rthz"]``); ``0``: no compensation.
        attitude_drift: the attitude's angle random walk, deg/√h, with ``gyro_noise``
            (``--attitude-drift``): for an attitude propagated from a gyro, its ARW; the
            momentum rows are weighted for the drift (``report["drift_weighted"]`` says
            whether the answer came from them). Not for a star tracker or an MEKF.
        memory: forgetting time constant, s. resample: resampling period, s.
        every: solve every N samples. rotation_source: ``"attitude"`` or ``"gyro"``
            (default: chosen from the data). rho_model: ``"auto"``, ``"smooth"``,
            ``"held"``, ``"plain"``. torque_bias: estimate an unknown constant torque.
            inertial_torque: a torque constant in the inertial frame, per chain: ``"short"``
            (default: ``"auto"`` on a record shorter than 30 s, ``"off"`` on a longer one),
            ``"off"``, ``"on"`` or ``"auto"`` (a nested χ² test decides;
            ``report["row_model"]``).
            damping: estimate a linear damping torque −D ω (air drag; ``report["damping_nms"]``).
            calibrate_rotors: with ``batch=True`` and a ``spacecraft`` file whose rotors have a
            σ, estimate each rotor's spin-inertia error and axis tilts with J, the file's σ
            their prior (``report["rotor_calibration"]``: values, σ, how many combinations
            the data fix); the wheels' common scale stays the file's σ, and the record needs
            a total angular momentum (else a warning, and the file's σ a consider term).
            outside: which torques of the outside measurements are modelled, a dict
            (``--no-gravity-gradient``, ``--gravity-mu``, ``--no-residual-dipole``,
            ``--no-centre-of-mass``): ``gravity_gradient`` (default ``True``),
            ``gravity_mu_m3_s2`` (default Earth's, 3.986004418e14), ``residual_dipole``
            (``True``), ``centre_of_mass`` (``True``), e.g.
            ``outside={"centre_of_mass": False}``. The estimates are in
            ``report["outside"]`` (see :class:`Estimate`).
            rotor_scale_sigma: relative σ of the wheel momentum's scale (the wheels' spin
            inertia known to ±this, e.g. 0.02): widens σ by it times |Ĵ|.
            torque_scale_sigma: relative σ of the known torque's scale (a thrust or a
            dipole known to ±this, e.g. 0.02): widens the final answer's σ by it times
            the part of Ĵ the known torque sets (``report["torque_scale_sigma_kg_m2"]``).
            filter_cutoff_hz: the equation-error baseline's low-pass cutoff, Hz.
            wheel_delay: the wheel speeds' time tag: ``None`` (off), the delay in s
            (the speeds are read that much later), or ``"estimate"`` (with σ, which widens
            each element's; ``report["wheel_delay"]``). chain: momentum chain, s (0:
            chains end only at gaps). glitches: ``"stop"``
            or ``"keep"``. solver: ``"native"``. uncertainty: compute σ.
        batch: one batch solve instead of the recursive estimator (``--batch``).
        history: keep every estimate (``Estimate.history``, the CLI's ``-o``).
        truth: the true J (3×3, kg m²), for ``Estimate.relative_error``.

    Input conventions (arrays, DataFrame, path): ``scalar_first``, ``jpl``,
    ``conjugate``, ``gyro_unit``, ``negate_rho``, ``unit_tolerance``,
    ``period_tolerance``; ``columns`` for a DataFrame or a path; ``spacecraft`` (a
    spacecraft file, :func:`read_csv`) for a path.

    The GIL is released while the data are checked and the estimator runs.

    Raises:
        DataError: bad data, with the CLI's message.
        ValueError, TypeError: an invalid argument, named.
    """
    arguments = locals()
    settings = _settings(arguments, (*_SETTINGS, "history", "truth"))
    conventions = _settings(arguments, _CONVENTIONS)
    single = all(x is None for x in (q, rho, tau, w, r, b, f, dipole))
    if isinstance(t, Telemetry) or isinstance(t, (str, os.PathLike)) or _is_frame(t):
        if not single:
            raise TypeError(
                "estimate(data): q, rho, tau, w, r, b, f and dipole are given only with arrays "
                "(t, q, rho)"
            )
    # A list of records: paths or Telemetry (a list of numbers is an array of times).
    records_given = isinstance(t, (list, tuple)) and (
        len(t) == 0 or any(isinstance(x, (str, os.PathLike, Telemetry)) for x in t)
    )
    if spacecraft is not None and not (isinstance(t, (str, os.PathLike)) or records_given):
        raise TypeError(
            "spacecraft: give it with a path, or to read_csv (the wheel speeds are read from the file)"
        )
    if records_given:
        if not single:
            raise TypeError(
                "estimate(records): q, rho, tau, w, r, b, f and dipole are given only with arrays "
                "(t, q, rho)"
            )
        if not t:
            raise ValueError("estimate(records): the list of records is empty")
        records = []
        for k, x in enumerate(t):
            if isinstance(x, (str, os.PathLike)):
                records.append(read_csv(x, columns=columns, spacecraft=spacecraft, **conventions))
            elif isinstance(x, Telemetry):
                if columns is not None or spacecraft is not None:
                    raise ValueError(
                        f"records[{k}]: already read; give columns and spacecraft to read_csv"
                    )
                records.append(x)
            else:
                raise TypeError(
                    f"records[{k}]: expected a path or a Telemetry, got {type(x).__name__}"
                )
        # Conventions belong to reading: with a record already read, the native side names
        # one given here (as for one Telemetry, below).
        read_here = all(isinstance(x, (str, os.PathLike)) for x in t)
        given = {} if read_here else {k: v for k, v in conventions.items() if v not in (None, False)}
        return Estimate._from_native(
            _inertia.estimate_records([r._native for r in records], kwargs={**settings, **given})
        )
    if isinstance(t, (str, os.PathLike)):
        telemetry = read_csv(t, columns=columns, spacecraft=spacecraft, **conventions)
        return Estimate._from_native(telemetry._native.estimate(kwargs=settings))
    if isinstance(t, Telemetry):
        if columns is not None:
            raise ValueError("columns: these samples were already read; give it to read_csv")
        # Conventions belong to reading: the native side names one given here.
        given = {k: v for k, v in conventions.items() if v not in (None, False)}
        return Estimate._from_native(t._native.estimate(kwargs={**settings, **given}))
    if columns is not None and not _is_frame(t):
        raise ValueError("columns: applies to a DataFrame or a file")
    if _is_frame(t):
        names, arrays = _frame_arrays(t, columns)
        return Estimate._from_native(
            _inertia.estimate_arrays(
                *arrays, kwargs={**settings, **conventions}, frame_columns=names, label="<DataFrame>"
            )
        )
    if rho is None or (q is None and w is None):
        raise TypeError(
            "estimate(t, q, rho): rho is required with an array t, and q unless w is given "
            "(q=None: the attitude is integrated from the gyro rates)"
        )
    return Estimate._from_native(
        _inertia.estimate_arrays(
            *_arrays(t, q, rho, tau, w, r, b, f, dipole), kwargs={**settings, **conventions}
        )
    )


# ------------------------------------------------------------------------- streaming


def _vector(name: str, x: Any, n: int) -> Optional[List[float]]:
    if x is None:
        return None
    a = _float_array(name, x, f"({n},)")
    if a.shape != (n,):
        raise ValueError(f"{name}: expected {n} numbers, got shape {a.shape}")
    return a.tolist()


class Estimator:
    """A streaming estimator: push samples one at a time (or in blocks).

    Takes the settings of :func:`estimate` (not ``batch``, ``history``, ``truth``) and
    the input conventions (``scalar_first``, ``jpl``, ``conjugate``, ``gyro_unit``,
    ``negate_rho``, ``unit_tolerance``,
    ``period_tolerance``). Each sample is checked as a file's row is. Pushing the
    samples of a file one by one, then :meth:`finish`, gives the same estimate as
    :func:`estimate` on it.
    The GIL is released while a sample is processed.
    """

    def __init__(
        self,
        *,
        estimator: str = DEFAULT_ESTIMATOR,
        constraints: str = "physical",
        bounds: Any = None,
        nominal: Any = None,
        tolerance: Union[None, float, str] = None,
        diagonal: bool = False,
        prior: Any = None,
        prior_sigma: Any = None,
        products: str = "tensor",
        gyro_noise: Optional[float] = None,
        attitude_drift: Optional[float] = None,
        memory: Optional[float] = None,
        resample: Optional[float] = None,
        every: int = 1,
        rotation_source: Optional[str] = None,
        rho_model: str = "auto",
        torque_bias: bool = True,
        inertial_torque: str = "short",
        damping: bool = False,
        outside: Optional[Mapping[str, Any]] = None,
        rotor_scale_sigma: Optional[float] = None,
        torque_scale_sigma: Optional[float] = None,
        filter_cutoff_hz: Optional[float] = None,
        chain: float = 30.0,
        glitches: str = "stop",
        solver: str = "native",
        uncertainty: bool = True,
        scalar_first: bool = False,
        jpl: bool = False,
        conjugate: bool = False,
        gyro_unit: Optional[str] = None,
        negate_rho: bool = False,
        unit_tolerance: Optional[float] = None,
        period_tolerance: Optional[float] = None,
    ) -> None:
        self._native = _inertia.Stream(kwargs=_settings(locals(), (*_SETTINGS, *_CONVENTIONS)))

    def push(
        self, t: float, q: Any, rho: Any, tau: Any = None, w: Any = None,
        r: Any = None, b: Any = None, f: Any = None, dipole: Any = None,
    ) -> Optional[Estimate]:
        """Push one sample: ``t`` s, ``q`` (4,), ``rho`` (3,) N m s, ``tau`` (3,) N m,
        ``w`` (3,) rad/s, and the outside measurements ``r`` (3,) m, ``b`` (3,) T, ``f``
        (3,) N, ``dipole`` (3,) A m² (as for :func:`estimate`; each for every sample or
        none). Returns the estimate it produced, or ``None``."""
        try:
            t = float(t)
        except (TypeError, ValueError) as e:
            raise TypeError(f"t: expected a number (s), got {type(t).__name__}") from e
        produced = self._native.push(
            t, _vector("q", q, 4), _vector("rho", rho, 3), _vector("tau", tau, 3), _vector("w", w, 3),
            _vector("r", r, 3), _vector("b", b, 3), _vector("f", f, 3), _vector("dipole", dipole, 3),
        )
        return self.estimate if produced else None

    def push_many(
        self, t: Any, q: Any, rho: Any, tau: Any = None, w: Any = None,
        r: Any = None, b: Any = None, f: Any = None, dipole: Any = None,
    ) -> Optional[Estimate]:
        """Push a block of samples (arrays as for :func:`estimate`). Returns the newest
        estimate after the block, or ``None`` when the block produced none."""
        n = self._native.push_many(*_arrays(t, q, rho, tau, w, r, b, f, dipole))
        return self.estimate if n else None

    def finish(self) -> Optional[Estimate]:
        """End of input: returns the final estimate, as :func:`estimate` gives it on the
        same samples (where the wheel speeds are held between updates, its σ carries the
        move of J for their mean lag, which only the whole input gives), or ``None``
        before any estimate. Raises :class:`DataError` when the input was too short."""
        self._native.finish()
        return self.estimate

    @property
    def estimate(self) -> Optional[Estimate]:
        """The newest estimate, or ``None`` before one."""
        r = self._native.report()
        return None if r is None else Estimate._from_native((r[0], r[1], None))

    @property
    def samples(self) -> int:
        """Samples accepted so far."""
        return self._native.samples


# ------------------------------------------------------------------------ simulation


@dataclasses.dataclass(frozen=True, eq=False)
class Simulation:
    """Simulated telemetry and the truth. Unpacks as ``telemetry, inertia``.

    Attributes:
        telemetry: the telemetry, as :func:`read_csv` would read the file that
            ``inertia simulate`` writes with the same settings.
        inertia: the true J at the end of the run, kg m² (3×3; the CLI's truth file).
        inertia_initial: the true J at the start, kg m².
        scenario: the scenario's or preset's name.
        positions: the inertial orbit position at each sample, m (N, 3), with gravity
            gradient (the CLI's ``r_x,r_y,r_z`` columns, also ``telemetry.r``), else
            ``None``.
    """

    telemetry: Telemetry
    inertia: np.ndarray
    inertia_initial: np.ndarray
    scenario: str
    positions: Optional[np.ndarray] = None

    def __iter__(self) -> Iterator[Any]:
        return iter((self.telemetry, self.inertia))


def simulate(scenario: Optional[str] = None, **options: Any) -> Simulation:
    """Simulate telemetry as ``inertia simulate`` does.

    ``scenario`` is ``"slew"`` (300 s of rest-to-rest slews on reaction wheels) or
    ``"spin"`` (180 s major-axis spin with one wheel pulse), or give
    ``preset="small-sat"`` or ``"microsat"``. Every option of ``inertia simulate`` is a
    keyword argument with ``-`` written ``_`` and ``X:Y:Z`` values as three numbers:
    ``duration`` (s), ``dt`` (s, default 0.1), ``telemetry_dt`` (s), ``seed`` (default 1),
    ``gyro_noise`` (deg/s/√Hz) or ``gyro_arw_deg_rthr`` (deg/√h), ``gyro_bias_deg_h``,
    ``gyro_bias_instability_deg_h``, ``gyro_bias_correlation_s``, ``disturbance``
    (N m/√Hz), ``attitude`` (``"truth"``, ``"gyro"``, ``"star-tracker"``, ``"mekf"``),
    ``star_tracker_arcsec``, ``star_tracker_boresight``, ``star_tracker_hz``,
    ``mekf_raw_rates``, ``controller_hz``, ``command_phase`` (s),
    ``wheel_quantization_nms``, ``wheel_noise_nms``, ``wheel_skew_s``,
    ``wheel_scale_error``, ``wheel_misalignment_deg`` (deg),
    ``gravity_gradient_altitude_km``, ``orbit_inclination_deg``,
    ``magnetic_field_t`` (T), ``residual_dipole_am2``, ``magnetorquer_am2``,
    ``magnetometer_noise_t``, ``magnetometer_bias_t``, ``thrusters`` (N),
    ``thruster_arm_m``, ``centre_of_mass_m``, ``force_noise_n``,
    ``constant_torque_nm`` (N m), ``inertia_step`` ``(T, SCALE)``, ``inertia_ramp``
    ``(T0, T1, SCALE)``, ``paper_inertia`` (the paper's J exactly, which breaks
    J1 + J2 ≥ J3 by 4.9e-5 kg m²; by default the scenarios' truth is the paper's J +
    1e-4 I).

    The same settings and seed give the same samples as the CLI's file, bit for bit,
    with the outside measurements of its ``r_*``, ``b_*``, ``f_*`` columns in
    ``telemetry.r``, ``.b``, ``.f`` (a magnetorquer's torque is in ``tau``).
    """
    kwargs = dict(options)
    if scenario is not None:
        kwargs["scenario"] = scenario
    tel, end, start, name, positions = _inertia.simulate(kwargs=kwargs)
    return Simulation(Telemetry(tel), end, start, name, positions)


def plan(
    spacecraft: Union[str, "os.PathLike[str]"],
    target: float = 0.01,
    duration: Optional[float] = None,
    max_duration: float = 1800.0,
    chain: Union[float, str, None] = "auto",
    rehearsals: int = 8,
    disturbance: float = 1e-8,
) -> Dict[str, Any]:
    """Plan the calibration manoeuvre as ``inertia plan`` does (book, "Planning the
    calibration manoeuvre").

    ``spacecraft`` is a spacecraft file whose rotors carry ``max_torque_nm`` and
    ``max_momentum_nms``, with ``[prior]``, ``[sensors]`` and optionally ``[limits]``.
    ``target`` is the relative Frobenius error at 3σ; ``duration`` (s) flies that long
    instead; ``chain`` is the estimator's short momentum chain (s, ``None``: none), or
    ``0`` as ``None``, or ``"auto"`` (default): the plans for chains of 30, 60 and 120 s are rehearsed and the
    chain whose rehearsal reports the target soonest is kept (returned as ``chain_s``:
    give it to ``estimate(..., chain=...)`` for the flight, 0 for None);
    ``rehearsals`` flights of the estimator on the prior J decide, with the information
    matrix, where the plan stops (0: the information matrix alone).

    Returns a dict: ``t`` (N,) command times, s; ``period_s``; ``rho_dot_nm`` (N, 3) the
    body-axis wheel torque commands, N m, each held for ``period_s``; ``wheels`` (names)
    and ``wheel_torque_nm`` (N lists, one torque per wheel, N m); ``prediction_t`` (K,),
    ``sigma_kg_m2`` (K, 6) the predicted σ per element (J11, J22, J33, J12, J13, J23) and
    ``relative_sigma`` (K,) the relative Frobenius σ; ``target_met_s`` (information
    matrix) and ``reported_target_met_s`` (rehearsal), s or None; ``rehearsal_t`` and
    ``rehearsal_relative_sigma`` (the median σ the estimator reported); ``margin``,
    ``limit_use`` (``torque``, ``momentum``, ``rate``, ``angle``: the largest fraction of
    each limit used), ``gap`` (the A-optimality gap of the design), ``chain_s`` (the chain the plan
    assumes, s, or None) and ``chain_trials`` (with ``"auto"``: each chain tried and when
    its rehearsal reported the target, s or None). Raises ``ValueError`` naming the file
    and key for a file that lacks what a plan needs.
    """
    choose = isinstance(chain, str)
    if choose and chain != "auto":
        raise ValueError(f"chain: {chain!r}, expected a length in s, None or \"auto\"")
    return _inertia.plan(
        os.fspath(spacecraft), float(target),
        None if duration is None else float(duration), float(max_duration),
        None if (choose or chain is None or float(chain) == 0.0) else float(chain), choose,
        int(rehearsals),
        float(disturbance),
    )
