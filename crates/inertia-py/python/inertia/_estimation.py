"""Estimation from telemetry: one run (:func:`estimate`) or sample by sample (:class:`Estimator`)."""

from __future__ import annotations

import os
from typing import Any, List, Mapping, Optional, Sequence, Tuple, Union


from . import _inertia
from ._common import DEFAULT_ESTIMATOR, _CONVENTIONS, _SETTINGS, _arrays, _float_array, _frame_arrays, _is_frame, _settings
from ._results import Estimate
from ._telemetry import Telemetry, read_csv


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
            σ, estimate each rotor's spin-inertia error, axis tilts and time tag with J, the
            file's σ their prior (``report["rotor_calibration"]``: values, σ, how many
            combinations the data fix); the wheels' common scale stays the file's σ. Unless
            every parameter is a time tag, the record needs a total angular momentum (else
            a warning, and the file's σ a consider term); with a known torque the
            calibration is not made (a warning).
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
