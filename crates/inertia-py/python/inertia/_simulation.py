"""The simulator and the manoeuvre planner (:func:`simulate`, :func:`plan`)."""

from __future__ import annotations

import dataclasses
import os
from typing import Any, Dict, Iterator, Optional, Union

import numpy as np

from . import _inertia
from ._telemetry import Telemetry


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
