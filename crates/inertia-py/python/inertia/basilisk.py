"""Basilisk recorded messages -> inertia's inputs (pure numpy; no other import).

Basilisk (PyPI ``bsk``) records a spacecraft's attitude as modified Rodrigues parameters
``sigma_BN``, its body rates ``omega_BN_B`` (``SCStatesMsgPayload`` or a navigation
message), the reaction-wheel speeds ``Omega`` (``RWSpeedMsgPayload.wheelSpeeds``) with each
wheel's spin inertia ``Js`` and spin axis ``gsHat_B`` (``RWArrayConfigMsgPayload`` or the
``rwFactory`` that built them), and external torques in body axes (for example
``ExtForceTorque.torqueRequestBody``, ``GravityGradientEffector``'s torque). Recorder times
are integer nanoseconds.

:func:`from_basilisk` turns them into what ``inertia.estimate`` (and the CLI's CSV,
:func:`to_csv`) take: ``t`` (s), ``q`` (N, 4), ``rho`` (N, 3), ``tau`` (N, 3) and ``w``
(N, 3)::

    from inertia import basilisk
    d = basilisk.from_basilisk(
        rec_sc.times(), rec_sc.sigma_BN, rec_sc.omega_BN_B,
        wheel_speeds=rec_rw.wheelSpeeds[:, :n_wheels], Js=Js, gs_B=gs_B)
    est = inertia.estimate(d["t"], d["q"], d["rho"], tau=d["tau"], w=d["w"])

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
]

#: Columns of the CLI's CSV, in the order :func:`to_csv` writes them.
CSV_COLUMNS = (
    "t", "q_x", "q_y", "q_z", "q_w",
    "rho_x", "rho_y", "rho_z",
    "tau_x", "tau_y", "tau_z",
    "w_x", "w_y", "w_z",
)


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

    Returns
    -------
    dict with ``t`` (N,) s, ``q`` (N, 4), ``rho`` (N, 3) N m s, ``tau`` (N, 3) N m and ``w``
    (N, 3) rad/s or ``None``: the arguments of ``inertia.estimate``.
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
    tau = np.zeros((n, 3)) if tau_B is None else _array("tau_B", tau_B, (3,), n)
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
    return {"t": t, "q": q, "rho": rho, "tau": tau, "w": w}


def to_csv(path, data: dict) -> None:
    """Write :func:`from_basilisk`'s output as the CLI's CSV (``inertia estimate PATH``),
    with every number in its shortest round-trip form."""
    n = data["t"].shape[0]
    has_w = data.get("w") is not None
    cols = CSV_COLUMNS if has_w else CSV_COLUMNS[:11]
    with open(path, "w", newline="") as f:
        out = _csv.writer(f, lineterminator="\n")
        out.writerow(cols)
        for k in range(n):
            row = [data["t"][k], *data["q"][k], *data["rho"][k], *data["tau"][k]]
            if has_w:
                row += list(data["w"][k])
            out.writerow([repr(float(v)) for v in row])
