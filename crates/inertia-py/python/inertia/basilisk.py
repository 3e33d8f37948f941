"""Basilisk recorded messages -> inertia's inputs (pure numpy; no other import).

Basilisk (PyPI ``bsk``) records a spacecraft's attitude as modified Rodrigues parameters
``sigma_BN``, its body rates ``omega_BN_B`` (``SCStatesMsgPayload`` or a navigation
message), the reaction-wheel speeds ``Omega`` (``RWSpeedMsgPayload.wheelSpeeds``) with each
wheel's spin inertia ``Js`` and spin axis ``gsHat_B`` (``RWArrayConfigMsgPayload`` or the
``rwFactory`` that built them), and external torques in body axes (for example
``ExtForceTorque.torqueRequestBody``; ``GravityGradientEffector``'s torque unless the orbit
is given, below). Recorder times are integer nanoseconds.

:func:`from_basilisk` turns them into what ``inertia.estimate`` (and the CLI's CSV,
:func:`to_csv`) take: ``t`` (s), ``q`` (N, 4), ``rho`` (N, 3), ``tau`` (N, 3) and ``w``
(N, 3)::

    from inertia import basilisk
    d = basilisk.from_basilisk(
        rec_sc.times(), rec_sc.sigma_BN, rec_sc.omega_BN_B,
        wheel_speeds=rec_rw.wheelSpeeds[:, :n_wheels], Js=Js, gs_B=gs_B)
    est = inertia.estimate(d["t"], d["q"], d["rho"], tau=d["tau"], w=d["w"])

For the spacecraft file's per-wheel telemetry (``--spacecraft``: each wheel's axis, spin
inertia and σ, so that ``--calibrate-rotors`` and ``inertia plan`` can use them), pass
``per_wheel=True`` and write the file with :func:`spacecraft_toml`; the outside torques'
measurements become the CSV's ``r_*`` (``r_BN_N``: gravity gradient), ``b_*`` (``B_B`` or
``B_N``: residual dipole), ``dipole_*`` (``mtb_dipoles``: torque rods, clipped at
``mtb_max_dipoles`` as ``MtbEffector`` clips them) and ``f_*``
(``thruster_forces_B``: centre of mass) columns::

    d = basilisk.from_basilisk(
        rec_sc.times(), rec_sc.sigma_BN, rec_sc.omega_BN_B, per_wheel=True,
        wheel_speeds=rec_rw.wheelSpeeds[:, :n_wheels], Js=Js, gs_B=gs_B,
        r_BN_N=rec_sc.r_BN_N)
    basilisk.to_csv("flight.csv", d)
    open("wheels.toml", "w").write(basilisk.spacecraft_toml(Js, gs_B))
    # inertia estimate flight.csv --spacecraft wheels.toml

The estimate is then the whole spacecraft's inertia about its centre of mass, wheels
included. With Basilisk's default wheel model, ``BalancedWheels``, that is the hub's
``IHubPntBc_B``: Basilisk counts the wheels' inertia in the hub's and adds none of its
own. Measured (``tests/test_basilisk.py``, bsk 2.12.1): Basilisk's
``totRotAngMomPntC_N`` equals ``C(q)(IHubPntBc_B ω + Σ Js Ω gs)`` with this module's ``q``
and ρ to 1e-15 relative, and a least-squares fit of the inertia in that identity returns
``IHubPntBc_B`` exactly, not ``IHubPntBc_B`` plus the wheels' ``Js``/``Jt``/``Jg``. (The
jitter wheel models add the wheels' mass properties to the spacecraft; they are not
tested here.) See "Wheel momentum" for the other choice of ρ.

Conventions, derived
====================

**Attitude.** inertia's quaternion is ``[x, y, z, w]``, scalar last, Hamilton product,
and maps body to inertial: ``x_N = q x_B q†`` (``docs/conventions.md`` §3, crate docs of
``inertia::attitude``). Basilisk's MRP ``sigma_BN = e tan(Φ/4)`` describes the rotation
of angle Φ about the principal axis ``e`` that carries the N axes into the B axes, and its
direction cosine matrix maps inertial components to body components::

    [BN] = I + (8 [σ×]² − 4 (1 − σ²) [σ×]) / (1 + σ²)²,      x_B = [BN] x_N

(``RigidBodyKinematics.MRP2C``). Its Euler parameters (scalar first) are
``β0 = cos(Φ/2) = (1 − σ²)/(1 + σ²)``, ``β_{1:3} = e sin(Φ/2) = 2σ/(1 + σ²)``, and
``[BN] = (β0² − β·β) I + 2ββᵀ − 2β0[β×]``: the *transpose* of the active rotation
``R(e, Φ) = cosΦ I + (1 − cosΦ) eeᵀ + sinΦ [e×]``. So ``x_N = [BN]ᵀ x_B = R(e, Φ) x_B``:
the same rotation, read actively, takes body components to inertial ones. The Hamilton
quaternion of the active rotation ``R(e, Φ)`` is ``[e sin(Φ/2), cos(Φ/2)]``, which is
``[β1, β2, β3, β0]``. Hence, **with no conjugation**::

    q = [2σ / (1 + σ²),  (1 − σ²) / (1 + σ²)]          (x, y, z, w)

Conjugating it (as "σ_BN maps N→B" might suggest) is wrong: the library would see every
rotation reversed and stop with its convention check (``--conjugate``). The tests check the
formula against ``MRP2C`` (``R(q) = [BN]ᵀ``), against the MRP kinematics
``σ̇ = ¼[(1 − σ²)I + 2[σ×] + 2σσᵀ]ω`` (``2 vec(q_k† q_{k+1})/h`` ≈ the body rate), and against
inertial momentum conservation.

**Shadow set.** Basilisk keeps ``|σ| ≤ 1`` by switching to the shadow set
``σˢ = −σ/|σ|²``, the same attitude. Its quaternion is ``−q`` (``1 − |σˢ|² < 0`` flips the
scalar, and ``2σˢ/(1 + |σˢ|²) = −2σ/(1 + σ²)``). inertia accepts either sign, but a
sequence with jumps between ``q`` and ``−q`` is harder to read, so
:func:`mrp_to_quaternion` makes the sequence sign-continuous (each quaternion in the
hemisphere of the one before; the first with ``w ≥ 0``).

**Wheel momentum ρ.** The library integrates the gyrostat equation
``J ω̇ + ω × (J ω + ρ) + ρ̇ = τ`` (paper eq. 26, ``crates/inertia/src/dynamics.rs``) with
the conserved inertial momentum ``C(q)(J ω + ρ)``. The paper's Lagrangian (eq. 27,
``L = ½ω·J_B ω + Σ ½(ω + ω_r)·J_r(ω + ω_r)``, ``ω_r`` the rotor's rate *relative to the
body*) gives ``H = (J_B + Σ J_r) ω + Σ J_r ω_r``, with ``J = J_B + Σ J_r`` (eq. 39): J is
the total inertia, rotors included, and ρ is the rotors' momentum **relative to the
body**. For an axisymmetric wheel spinning at ``Ω`` relative to the body (Basilisk's
``Omega``) about ``gs``: ``J_r ω_r = Js Ω gs``, so::

    ρ = Σ_i Js_i Ω_i gs_i                                  (wheel_momentum="relative")

Basilisk's own total momentum about the centre of mass is the same split,
``H = [I_sc] ω + Σ Js Ω gs`` (``[I_sc]`` = ``IHubPntBc_B`` for balanced wheels, above). The
wheel's absolute spin momentum ``h_s = Js (Ω + gsᵀω)``, which flight software often reports
(and ``mrpFeedback`` uses), satisfies ``Σ h_s gs = ρ + (Σ Js gs gsᵀ) ω``: with it
(``wheel_momentum="absolute"``) the same H is ``([I_sc] − Σ Js gs gsᵀ) ω + Σ h_s gs``, and
the estimate is ``[I_sc] − Σ Js gs gsᵀ``, not the spacecraft's inertia. The tests check
both against an independent simulation of Basilisk's hub-and-wheels equations.

**Rates.** inertia's ``w_k`` is the gyro rate averaged over ``[t_k, t_{k+1}]`` (a delta-angle
gyro). Basilisk's ``omega_BN_B`` is the instantaneous rate at ``t_k``. ``rates="interval"``
(default) gives ``w_k = (ω_k + ω_{k+1})/2`` (trapezoid: the interval mean to O(h²ω̈));
the last sample, which starts no interval, keeps its own ω. ``rates="instant"`` passes
ω as recorded; ``rates=None`` leaves ``w`` out (``None``). With an IMU's accumulated
delta angles (``IMUSensorMsgPayload.DRFramePlatform`` mapped to body axes, the turn over
the step that *ends* at each sample) pass ``delta_angle_B``: ``w_k = Δθ_{k+1}/(t_{k+1} − t_k)``.

**Torques.** ``tau_B`` is the known external torque, body axes, N m, at each sample
(zeros when ``None``). Wheel motor torques are internal: they enter through ρ, never τ.

**Time.** ``time_unit="ns"`` (default, Basilisk recorders' ``times()``) or ``"s"``. Times
must increase strictly.
"""

from __future__ import annotations

import csv as _csv
from typing import Optional

import numpy as np

__all__ = [
    "mrp_to_quaternion",
    "quaternion_to_mrp",
    "wheel_momentum",
    "interval_rates",
    "from_basilisk",
    "to_csv",
    "spacecraft_toml",
    "speed_column",
    "cell_means",
    "mtb_dipoles_applied",
]


def _array(name: str, value, shape_tail: tuple, n: Optional[int] = None) -> np.ndarray:
    """``value`` as a finite float array of shape ``(n,) + shape_tail``."""
    try:
        a = np.asarray(value, dtype=float)
    except (TypeError, ValueError) as e:
        raise TypeError(f"{name}: not an array of numbers ({e})") from None
    if a.ndim != 1 + len(shape_tail) or a.shape[1:] != shape_tail:
        want = "(N" + "".join(f", {d}" for d in shape_tail) + ")"
        raise ValueError(f"{name}: shape {a.shape}, expected {want}")
    if n is not None and a.shape[0] != n:
        raise ValueError(f"{name}: {a.shape[0]} rows, expected {n} (one per time)")
    if not np.all(np.isfinite(a)):
        bad = np.argwhere(~np.isfinite(a))[0]
        raise ValueError(f"{name}: non-finite value at index {tuple(int(i) for i in bad)}")
    return a


def mrp_to_quaternion(sigma_BN, *, continuous: bool = True) -> np.ndarray:
    """Basilisk MRPs ``sigma_BN`` (N, 3) -> inertia quaternions (N, 4), ``[x, y, z, w]``,
    Hamilton, body -> inertial: ``q = [2σ, 1 − σ²]/(1 + σ²)`` (module docs for the
    derivation). Either MRP set may be given at any sample; with ``continuous`` (default)
    the signs are made continuous (the first with ``w >= 0``, each next in the hemisphere
    of the one before), so that a switch to the shadow set leaves no jump."""
    s = _array("sigma_BN", sigma_BN, (3,))
    s2 = np.einsum("ij,ij->i", s, s)[:, None]
    q = np.concatenate([2.0 * s, 1.0 - s2], axis=1) / (1.0 + s2)
    if continuous and len(q):
        if q[0, 3] < 0:
            q[0] = -q[0]
        dots = np.einsum("ij,ij->i", q[1:], q[:-1])
        # Flip every sample after an odd number of sign changes.
        flips = np.concatenate([[False], dots < 0])
        parity = np.cumsum(flips) % 2 == 1
        q[parity] = -q[parity]
    return q


def quaternion_to_mrp(q) -> np.ndarray:
    """inertia quaternions (N, 4) ``[x, y, z, w]`` -> Basilisk's principal MRPs ``sigma_BN``
    (N, 3), ``|σ| <= 1``: ``σ = v/(1 + w)`` after choosing the sign with ``w >= 0``."""
    q = _array("q", q, (4,))
    q = q / np.linalg.norm(q, axis=1)[:, None]
    q = np.where(q[:, 3:4] < 0, -q, q)
    return q[:, :3] / (1.0 + q[:, 3:4])


def wheel_momentum(wheel_speeds, Js, gs_B, omega_BN_B=None, *, absolute: bool = False) -> np.ndarray:
    """Rotor momentum ρ (N, 3), N m s, body axes, from wheel speeds ``Ω`` (N, n) rad/s
    relative to the body, spin inertias ``Js`` (n,) kg m² and spin axes ``gs_B`` (n, 3).

    ``absolute=False`` (what inertia's ρ is, with J the spacecraft's total inertia):
    ``ρ = Σ Js Ω gs``. ``absolute=True``: ``Σ Js (Ω + gsᵀω) gs`` (needs ``omega_BN_B``;
    J is then the total less ``Σ Js gs gsᵀ``). Module docs: "Wheel momentum ρ"."""
    Js = np.atleast_1d(np.asarray(Js, dtype=float))
    n_wheels = Js.shape[0]
    if Js.ndim != 1 or not np.all(np.isfinite(Js)) or not np.all(Js > 0):
        raise ValueError(f"Js: spin inertias must be a 1-D array of finite values > 0, got {Js}")
    gs = _array("gs_B", gs_B, (3,), n_wheels)
    norms = np.linalg.norm(gs, axis=1)
    if np.any(np.abs(norms - 1.0) > 1e-3):
        raise ValueError(f"gs_B: spin axes must be unit vectors (norms {norms})")
    gs = gs / norms[:, None]
    omega_w = np.asarray(wheel_speeds, dtype=float)
    if omega_w.ndim == 1 and n_wheels == 1:
        omega_w = omega_w[:, None]
    omega_w = _array("wheel_speeds", omega_w, (n_wheels,))
    spin = omega_w * Js[None, :]
    if absolute:
        if omega_BN_B is None:
            raise ValueError("omega_BN_B: needed for absolute wheel momentum")
        w = _array("omega_BN_B", omega_BN_B, (3,), omega_w.shape[0])
        spin = spin + (w @ gs.T) * Js[None, :]
    return spin @ gs


def interval_rates(t_s, omega_BN_B) -> np.ndarray:
    """Instantaneous body rates at the samples -> inertia's ``w`` (the mean over each
    interval ``[t_k, t_{k+1}]``) by the trapezoid ``(ω_k + ω_{k+1})/2``; the last sample
    keeps its own ω."""
    t = _array("t", t_s, ())
    w = _array("omega_BN_B", omega_BN_B, (3,), t.shape[0])
    out = w.copy()
    out[:-1] = 0.5 * (w[:-1] + w[1:])
    return out


def _seconds(times, time_unit: str) -> np.ndarray:
    raw = np.asarray(times)
    if raw.ndim != 1:
        raise ValueError(f"times: shape {raw.shape}, expected (N,)")
    if time_unit == "ns":
        if raw.dtype.kind in "iu":
            ns = raw.astype(np.int64)
            # Differences first: whole ns stay exact however late the run starts.
            t = (ns - ns[0]).astype(float) / 1e9 + float(ns[0]) / 1e9 if len(ns) else ns.astype(float)
        else:
            f = _array("times", raw, ())
            if not np.all(f == np.round(f)):
                raise ValueError(
                    "times: not whole nanoseconds; Basilisk recorders give integer ns "
                    "(pass time_unit=\"s\" for times in seconds)"
                )
            t = f / 1e9
    elif time_unit == "s":
        t = _array("times", raw, ())
    else:
        raise ValueError(f"time_unit: {time_unit!r}, expected \"ns\" or \"s\"")
    if len(t) > 1 and not np.all(np.diff(t) > 0):
        k = int(np.argmax(~(np.diff(t) > 0)))
        raise ValueError(f"times: not increasing at index {k + 1} ({t[k + 1]} s after {t[k]} s)")
    return t


def from_basilisk(
    times,
    sigma_BN,
    omega_BN_B=None,
    *,
    wheel_speeds=None,
    Js=None,
    gs_B=None,
    tau_B=None,
    delta_angle_B=None,
    time_unit: str = "ns",
    rates: Optional[str] = "interval",
    wheel_momentum_kind: str = "relative",
    per_wheel: bool = False,
    wheel_names=None,
    r_BN_N=None,
    B_B=None,
    B_N=None,
    dipole_B=None,
    mtb_dipoles=None,
    mtb_axes_B=None,
    mtb_max_dipoles=None,
    thruster_forces_B=None,
    thruster_locations_B=None,
) -> dict:
    """Convert Basilisk recordings to inertia's inputs (module docs for every convention).

    Parameters
    ----------
    times : (N,) recorder times, integer ns (``time_unit="ns"``) or s (``"s"``).
    sigma_BN : (N, 3) MRPs of B relative to N (either set; shadow switches are handled).
    omega_BN_B : (N, 3) body rates, rad/s, body axes (for ``w``, and for absolute ρ).
    wheel_speeds : (N, n) wheel speeds Ω relative to the body, rad/s (``None``: no wheels,
        ρ = 0; then only a known torque can fix the scale of J).
    Js : (n,) wheel spin-axis inertias, kg m².
    gs_B : (n, 3) wheel spin axes, body axes (unit).
    tau_B : (N, 3) known external torque, N m, body axes (``None``: zeros).
    delta_angle_B : (N, 3) gyro delta angles, rad, body axes, each over the step ending at
        its sample (the first is ignored); gives ``w`` in place of ``omega_BN_B``.
    rates : ``"interval"`` (default), ``"instant"`` or ``None`` (no ``w``).
    wheel_momentum_kind : ``"relative"`` (default: J is the spacecraft's total inertia) or
        ``"absolute"`` (J is the total less ``Σ Js gs gsᵀ``).
    per_wheel : keep each wheel's speed (``wheel_speeds``, ``wheel_names``) in place of ρ,
        for a spacecraft file (:func:`spacecraft_toml`) that states each wheel's axis and
        spin inertia, so that ``--calibrate-rotors`` and ``inertia plan`` can use them.
    wheel_names : (n,) names for the per-wheel columns (default ``rw1``, ``rw2``, ...).
    r_BN_N : (N, 3) position, m, in N (``SCStatesMsgPayload.r_BN_N``, N centred on the
        central body): the orbit columns ``r_*``, from which the estimator models the
        gravity gradient (``GravityGradientEffector``'s torque; not also in ``tau_B``).
    B_B : (N, 3) magnetic field, T, body axes (a magnetometer's ``tam_S`` with
        ``dcm_SB`` the identity); or ``B_N`` (N, 3), inertial (``MagneticFieldMsgPayload
        .magField_N``), turned to body axes with the attitude: ``B_B = [BN] B_N``. The
        field columns ``b_*``: the estimator then estimates a residual dipole.
    dipole_B : (N, 3) commanded magnetorquer dipole, A m², body axes; or ``mtb_dipoles``
        (N, k) (``MTBCmdMsgPayload.mtbDipoleCmds[:k]``) with ``mtb_axes_B`` (k, 3), each
        rod's axis (the columns of ``MtbEffector``'s ``GtMatrix_B``): ``Σ m_i g_i``. Needs
        the field; ``MtbEffector``'s torque ``m × B`` is then known, not also in ``tau_B``.
    mtb_max_dipoles : (k,) each rod's limit, A m² (``MTBArrayConfigMsgPayload
        .maxMtbDipoles[:k]``): ``MtbEffector`` clips each rod's command to ± its limit
        before it acts, and so does this (:func:`mtb_dipoles_applied`). Clipping follows
        averaging here, exact where no command crosses a limit within a sample interval;
        for commands that switch between samples, clip the fine record with
        :func:`mtb_dipoles_applied` before :func:`cell_means` instead.
    thruster_forces_B : (N, k, 3) each thruster's force, N, body axes
        (``THROutputMsgPayload.thrustForce_B``), with ``thruster_locations_B`` (k, 3), m,
        from the body frame's origin B (``thrusterLocation``): the force columns ``f_*``
        get ``Σ F_i`` and ``tau`` gets ``Σ r_i × F_i``, the torque about B; the estimator
        then estimates the centre of mass (``hub.r_BcB_B``) with J. On/off thrusters
        switch between samples: record them at the dynamics rate and pass their
        :func:`cell_means` (so also for ``mtb_dipoles`` that change between samples).

    Returns
    -------
    dict with ``t`` (N,) s, ``q`` (N, 4), ``rho`` (N, 3) N m s (``None`` with
    ``per_wheel``), ``tau`` (N, 3) N m, ``w`` (N, 3) rad/s or ``None``: the arguments of
    ``inertia.estimate``; and ``wheel_speeds`` (N, n) rad/s with ``wheel_names``, ``r``,
    ``b``, ``dipole``, ``f`` (N, 3) where given (else ``None``): the further columns
    :func:`to_csv` writes.
    """
    t = _seconds(times, time_unit)
    n = t.shape[0]
    q = mrp_to_quaternion(_array("sigma_BN", sigma_BN, (3,), n))
    omega = None if omega_BN_B is None else _array("omega_BN_B", omega_BN_B, (3,), n)
    if wheel_momentum_kind not in ("relative", "absolute"):
        raise ValueError(
            f"wheel_momentum_kind: {wheel_momentum_kind!r}, expected \"relative\" or \"absolute\""
        )
    if wheel_speeds is None:
        if Js is not None or gs_B is not None:
            raise ValueError("Js, gs_B: given without wheel_speeds")
        rho = np.zeros((n, 3))
    else:
        if Js is None or gs_B is None:
            raise ValueError("wheel_speeds: needs Js and gs_B (each wheel's spin inertia and axis)")
        rho = wheel_momentum(
            wheel_speeds, Js, gs_B, omega, absolute=wheel_momentum_kind == "absolute"
        )
        if rho.shape[0] != n:
            raise ValueError(f"wheel_speeds: {rho.shape[0]} rows, expected {n} (one per time)")
    speeds, names = None, None
    if per_wheel:
        if wheel_speeds is None:
            raise ValueError("per_wheel: needs wheel_speeds, Js and gs_B")
        if wheel_momentum_kind != "relative":
            raise ValueError(
                "per_wheel: the spacecraft file's speeds are relative to the body "
                "(wheel_momentum_kind=\"relative\")"
            )
        n_wheels = np.atleast_1d(np.asarray(Js, dtype=float)).shape[0]
        speeds = np.asarray(wheel_speeds, dtype=float).reshape(n, n_wheels)
        names = _wheel_names(wheel_names, n_wheels)
        rho = None
    elif wheel_names is not None:
        raise ValueError("wheel_names: given without per_wheel=True")
    tau = np.zeros((n, 3)) if tau_B is None else _array("tau_B", tau_B, (3,), n)
    r = None if r_BN_N is None else _array("r_BN_N", r_BN_N, (3,), n)
    if B_B is not None and B_N is not None:
        raise ValueError("B_B, B_N: give the field in one frame")
    if B_N is not None:
        b_n = _array("B_N", B_N, (3,), n)
        # [BN] x_N = R(q)ᵀ x_N, with R(q) the body -> inertial rotation of `q`.
        b = np.einsum("kji,kj->ki", _rotations(q), b_n)
    else:
        b = None if B_B is None else _array("B_B", B_B, (3,), n)
    if dipole_B is not None and mtb_dipoles is not None:
        raise ValueError("dipole_B, mtb_dipoles: give the commanded dipole once")
    if mtb_dipoles is not None:
        if mtb_axes_B is None:
            raise ValueError("mtb_dipoles: needs mtb_axes_B (each rod's axis, body axes)")
        axes = np.atleast_2d(np.asarray(mtb_axes_B, dtype=float))
        axes = _array("mtb_axes_B", axes, (3,))
        m = np.asarray(mtb_dipoles, dtype=float)
        if m.ndim == 1 and axes.shape[0] == 1:
            m = m[:, None]
        m = _array("mtb_dipoles", m, (axes.shape[0],), n)
        if mtb_max_dipoles is not None:
            m = mtb_dipoles_applied(m, mtb_max_dipoles)
        dipole = m @ axes
    elif mtb_axes_B is not None or mtb_max_dipoles is not None:
        raise ValueError("mtb_axes_B, mtb_max_dipoles: given without mtb_dipoles")
    else:
        dipole = None if dipole_B is None else _array("dipole_B", dipole_B, (3,), n)
    if dipole is not None and b is None:
        raise ValueError("dipole_B: a commanded dipole's torque needs the field (B_B or B_N)")
    f = None
    if thruster_forces_B is not None:
        if thruster_locations_B is None:
            raise ValueError(
                "thruster_forces_B: needs thruster_locations_B (each thruster's position "
                "from the body frame's origin, m)"
            )
        loc = _array("thruster_locations_B", np.atleast_2d(thruster_locations_B), (3,))
        forces = np.asarray(thruster_forces_B, dtype=float)
        if forces.ndim == 2 and loc.shape[0] == 1:
            forces = forces[:, None, :]
        if forces.shape != (n, loc.shape[0], 3):
            raise ValueError(
                f"thruster_forces_B: shape {forces.shape}, expected ({n}, {loc.shape[0]}, 3)"
            )
        if not np.all(np.isfinite(forces)):
            raise ValueError("thruster_forces_B: non-finite value")
        f = forces.sum(axis=1)
        tau = tau + np.cross(loc[None, :, :], forces).sum(axis=1)
    elif thruster_locations_B is not None:
        raise ValueError("thruster_locations_B: given without thruster_forces_B")
    if delta_angle_B is not None:
        d = _array("delta_angle_B", delta_angle_B, (3,), n)
        w = np.empty((n, 3))
        w[:-1] = d[1:] / np.diff(t)[:, None]
        w[-1] = w[-2] if n > 1 else 0.0
    elif rates is None:
        w = None
    elif omega is None:
        raise ValueError("omega_BN_B: needed for rates (pass rates=None to leave w out)")
    elif rates == "interval":
        w = interval_rates(t, omega)
    elif rates == "instant":
        w = omega.copy()
    else:
        raise ValueError(f"rates: {rates!r}, expected \"interval\", \"instant\" or None")
    return {
        "t": t, "q": q, "rho": rho, "tau": tau, "w": w,
        "wheel_speeds": speeds, "wheel_names": names,
        "r": r, "b": b, "dipole": dipole, "f": f,
    }


def mtb_dipoles_applied(mtb_dipoles, mtb_max_dipoles) -> np.ndarray:
    """The dipoles torque rods apply for their commands: ``MtbEffector`` clips each rod's
    command (``MTBCmdMsgPayload.mtbDipoleCmds``, (N, k) A m²) to ± its limit
    (``MTBArrayConfigMsgPayload.maxMtbDipoles[:k]``, (k,) A m², each ≥ 0)."""
    m = np.asarray(mtb_dipoles, dtype=float)
    if m.ndim != 2:
        raise ValueError(f"mtb_dipoles: expected shape (N, k), got {m.shape}")
    limit = np.asarray(mtb_max_dipoles, dtype=float).reshape(-1)
    if limit.shape != (m.shape[1],):
        raise ValueError(
            f"mtb_max_dipoles: expected {m.shape[1]} limits (one per rod), got shape "
            f"{np.shape(mtb_max_dipoles)}"
        )
    if not np.all(np.isfinite(limit) & (limit >= 0.0)):
        raise ValueError(f"mtb_max_dipoles: each limit must be finite and >= 0, got {limit}")
    return np.clip(m, -limit, limit)


def cell_means(times, fine_times, fine_values, *, time_unit: str = "ns") -> np.ndarray:
    """Means of a finely recorded signal over each sample's cell, for the known torque,
    force and dipole columns of on/off actuators (thrusters, magnetorquers).

    The estimator credits the known torque at sample k with the impulse from the middle
    of the interval before it to the middle of the one after (``h̄_k τ_k``,
    ``crates/inertia/src/estimator/momentum_rows.rs``). A smooth torque read at the sample
    gives that impulse to O(h²); a thruster that switches between samples does not: read
    at the samples, each edge misplaces up to half a step of its impulse. So record such
    actuators at the dynamics rate (``fine_times`` (M,), ``fine_values`` (M, ...)) and
    pass their mean over ``[(t_{k−1} + t_k)/2, (t_k + t_{k+1})/2]`` (the first and last
    cells end at the first and last sample): the integral of the recording's linear
    interpolant, exact for a piecewise-linear recording. A recording of a signal held
    between its steps (Basilisk's messages) reads as ramping over one fine step at each
    edge: each edge's impulse is placed to half a fine step."""
    t = _seconds(times, time_unit)
    tf = _seconds(fine_times, time_unit)
    v = np.asarray(fine_values, dtype=float)
    if v.shape[:1] != tf.shape or not np.all(np.isfinite(v)):
        raise ValueError(
            f"fine_values: shape {v.shape} (finite values expected), one row per fine time "
            f"({tf.shape[0]})"
        )
    if len(t) < 2 or tf[0] > t[0] or tf[-1] < t[-1]:
        raise ValueError("fine_times: must span the samples' times (at least two samples)")
    flat = v.reshape(len(tf), -1)
    # Cumulative integral of the linear interpolant at the fine times ...
    steps = np.diff(tf)[:, None]
    cum = np.concatenate([np.zeros((1, flat.shape[1])),
                          np.cumsum(0.5 * steps * (flat[1:] + flat[:-1]), axis=0)])

    def integral(x):
        # ... and at any time within them (the interpolant's quadratic piece).
        i = np.clip(np.searchsorted(tf, x, side="right") - 1, 0, len(tf) - 2)
        d = (x - tf[i])[:, None]
        slope = (flat[i + 1] - flat[i]) / (tf[i + 1] - tf[i])[:, None]
        return cum[i] + d * flat[i] + 0.5 * d * d * slope

    edges = np.concatenate([[t[0]], 0.5 * (t[1:] + t[:-1]), [t[-1]]])
    area = integral(edges)
    means = (area[1:] - area[:-1]) / np.diff(edges)[:, None]
    return means.reshape((len(t),) + v.shape[1:])


def _wheel_names(names, n_wheels: int) -> list:
    if names is None:
        return [f"rw{i + 1}" for i in range(n_wheels)]
    names = [str(x) for x in names]
    if len(names) != n_wheels:
        raise ValueError(f"wheel_names: {len(names)} names for {n_wheels} wheels")
    for x in names:
        if not x or not all(c.isalnum() or c in "_-" for c in x):
            raise ValueError(f"wheel_names: {x!r}: use letters, digits, '_' and '-' only")
    if len(set(names)) != len(names):
        raise ValueError(f"wheel_names: not distinct: {names}")
    return names


def _rotations(q: np.ndarray) -> np.ndarray:
    """(N, 3, 3) rotation matrices of Hamilton quaternions ``[x, y, z, w]`` (body -> inertial)."""
    x, y, z, w = (q[:, i] for i in range(4))
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)], -1),
        np.stack([2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)], -1),
        np.stack([2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)], -1),
    ], axis=1)


def speed_column(name: str) -> str:
    """The CSV column of a wheel's speed in rad/s, as :func:`to_csv` and
    :func:`spacecraft_toml` name it."""
    return f"{name}_rad_s"


def spacecraft_toml(
    Js,
    gs_B,
    *,
    wheel_names=None,
    Js_sigma=None,
    axis_sigma_deg=None,
    time_tag_sigma_s=None,
    max_torque_nm=None,
    max_speed_rad_s=None,
) -> str:
    """The spacecraft file (TOML, ``--spacecraft``) of Basilisk's wheels: one ``[[rotor]]``
    per wheel with its spin axis ``gs_B`` (body axes) and spin inertia ``Js``, its speed
    read from :func:`to_csv`'s per-wheel column in rad/s (relative to the body: Basilisk's
    ``Omega``). Optional, each a scalar or one value per wheel: ``Js_sigma`` (kg m²),
    ``axis_sigma_deg`` and ``time_tag_sigma_s`` (each wheel's speed read at its own
    instant), the file's σ (what ``--calibrate-rotors`` estimates against, and the
    consider term without it); ``max_torque_nm`` and ``max_speed_rad_s`` (Basilisk's
    ``u_max`` and ``Omega_max``), the limits ``inertia plan`` keeps (the momentum limit is
    ``Js · Omega_max``)."""
    Js = np.atleast_1d(np.asarray(Js, dtype=float))
    n_wheels = Js.shape[0]
    if Js.ndim != 1 or not np.all(np.isfinite(Js)) or not np.all(Js > 0):
        raise ValueError(f"Js: spin inertias must be a 1-D array of finite values > 0, got {Js}")
    gs = _array("gs_B", np.atleast_2d(gs_B), (3,), n_wheels)
    norms = np.linalg.norm(gs, axis=1)
    if np.any(np.abs(norms - 1.0) > 1e-3):
        raise ValueError(f"gs_B: spin axes must be unit vectors (norms {norms})")
    gs = gs / norms[:, None]
    names = _wheel_names(wheel_names, n_wheels)

    def per_wheel(name, value):
        if value is None:
            return [None] * n_wheels
        v = np.broadcast_to(np.asarray(value, dtype=float), (n_wheels,))
        if not np.all(np.isfinite(v)) or np.any(v < 0):
            raise ValueError(f"{name}: finite values >= 0 expected, got {v}")
        return [float(x) for x in v]

    js_sigma = per_wheel("Js_sigma", Js_sigma)
    tilt = per_wheel("axis_sigma_deg", axis_sigma_deg)
    tag = per_wheel("time_tag_sigma_s", time_tag_sigma_s)
    torque = per_wheel("max_torque_nm", max_torque_nm)
    speed = per_wheel("max_speed_rad_s", max_speed_rad_s)
    lines = ["# Basilisk's reaction wheels (inertia.basilisk.spacecraft_toml)"]
    for i, name in enumerate(names):
        lines += [
            "",
            "[[rotor]]",
            f'name = "{name}"',
            "axis = [" + ", ".join(repr(float(x)) for x in gs[i]) + "]",
            f"spin_inertia_kg_m2 = {float(Js[i])!r}",
        ]
        if js_sigma[i] is not None:
            lines.append(f"spin_inertia_sigma_kg_m2 = {js_sigma[i]!r}")
        if tilt[i] is not None:
            lines.append(f"spin_axis_sigma_deg = {tilt[i]!r}")
        if tag[i] is not None:
            lines.append(f"time_tag_sigma_s = {tag[i]!r}")
        lines += [f'speed_column = "{speed_column(name)}"', 'speed_unit = "rad/s"']
        if torque[i] is not None:
            lines.append(f"max_torque_nm = {torque[i]!r}")
        if speed[i] is not None:
            lines.append(f"max_momentum_nms = {speed[i] * float(Js[i])!r}")
    return "\n".join(lines) + "\n"


def to_csv(path, data: dict) -> None:
    """Write :func:`from_basilisk`'s output as the CLI's CSV (``inertia estimate PATH``),
    with every number in its shortest round-trip form: ``t``, ``q_*``, ``rho_*`` (or one
    speed column per wheel, named by :func:`speed_column`, with ``per_wheel``), ``tau_*``,
    then ``w_*``, ``r_*``, ``b_*``, ``dipole_*`` and ``f_*`` where present."""
    n = data["t"].shape[0]
    cols = ["t", "q_x", "q_y", "q_z", "q_w"]
    blocks = [data["t"][:, None], data["q"]]
    if data.get("rho") is not None:
        cols += ["rho_x", "rho_y", "rho_z"]
        blocks.append(data["rho"])
    else:
        names = data.get("wheel_names") or []
        speeds = data.get("wheel_speeds")
        if speeds is None:
            raise ValueError("data: neither rho nor wheel_speeds")
        cols += [speed_column(x) for x in names]
        blocks.append(np.asarray(speeds, dtype=float).reshape(n, len(names)))
    cols += ["tau_x", "tau_y", "tau_z"]
    blocks.append(data["tau"])
    for key, prefix in (("w", "w"), ("r", "r"), ("b", "b"), ("dipole", "dipole"), ("f", "f")):
        if data.get(key) is not None:
            cols += [f"{prefix}_{a}" for a in "xyz"]
            blocks.append(data[key])
    table = np.concatenate([np.asarray(b, dtype=float).reshape(n, -1) for b in blocks], axis=1)
    with open(path, "w", newline="") as f:
        out = _csv.writer(f, lineterminator="\n")
        out.writerow(cols)
        for row in table:
            out.writerow([repr(float(v)) for v in row])
