"""The Basilisk converter (``inertia/basilisk.py``) against physics it does not share code
with: an independent simulation of Basilisk's hub-and-reaction-wheels equations in MRPs
(with Basilisk's shadow-set switching), Basilisk's own MRP -> DCM formula, inertial
momentum conservation, and, where available, the ``inertia`` CLI and Basilisk itself.

Runs with plain pytest + numpy: the module is imported by path, so the package need not
be built. The CLI test needs the ``inertia`` binary (``INERTIA_BIN``, or
``target/release/inertia`` / ``target/debug/inertia`` in the repository); the Basilisk test
needs ``pip install bsk``. Each is skipped, saying why, without them.
"""

import functools
import json
import os
import pathlib
import subprocess

import numpy as np
import pytest

from conftest import basilisk_wheels, load_basilisk_converter

HERE = pathlib.Path(__file__).resolve().parent
REPO = HERE.parents[2]
bsk = load_basilisk_converter()


# ---------------------------------------------------------------- reference formulas


def skew(v):
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


def mrp2c(s):
    """Basilisk's ``RigidBodyKinematics.MRP2C``: [BN] with x_B = [BN] x_N."""
    s = np.asarray(s, dtype=float)
    s2 = s @ s
    S = skew(s)
    return np.eye(3) + (8.0 * S @ S - 4.0 * (1.0 - s2) * S) / (1.0 + s2) ** 2


def rot(q):
    """Hamilton [x, y, z, w], x_N = q x_B q†: the active rotation matrix."""
    v, w = np.asarray(q[:3]), q[3]
    V = skew(v)
    return np.eye(3) + 2.0 * w * V + 2.0 * V @ V


def qmul(a, b):
    """Hamilton product of [x, y, z, w] quaternions."""
    av, aw, bv, bw = a[:3], a[3], b[:3], b[3]
    return np.concatenate([aw * bv + bw * av + np.cross(av, bv), [aw * bw - av @ bv]])


def conj(q):
    return np.array([-q[0], -q[1], -q[2], q[3]])


# ------------------------------------------- Basilisk's equations, simulated independently

# The spacecraft's total inertia, wheels included (Basilisk's IHubPntBc_B with balanced
# wheels, which Basilisk takes to include them: see test_basilisk_end_to_end).
I_SC = np.array([[4.0, 0.15, -0.1], [0.15, 5.0, 0.2], [-0.1, 0.2, 6.0]])
JS = np.array([0.08, 0.1, 0.12])
GS = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.6, 0.0, 0.8]])


def motor_torque(t):
    """Smooth, different on each wheel: excites every direction of J."""
    return np.array(
        [0.02 * np.sin(0.31 * t), 0.015 * np.cos(0.17 * t + 0.4), 0.018 * np.sin(0.23 * t + 1.0)]
    )


@functools.lru_cache(maxsize=None)
def simulate(duration=120.0, dt=0.01, every=10, torque=(0.0, 0.0, 0.0)):
    """Hub + balanced wheels at the centre of mass, Basilisk's form (Schaub & Junkins):
    (I_sc − Σ Js gs gsᵀ) ω̇ = τ − Σ u gs − ω × (I_sc ω + Σ Js Ω gs);  Js (Ω̇ + gsᵀω̇) = u;
    σ̇ = ¼[(1 − σ²)I + 2[σ×] + 2σσᵀ] ω; RK4, then the shadow set when |σ| > 1 (as
    Basilisk's hub does). Records (t_ns, σ_BN, ω_BN_B, Ω) every `every` steps."""
    tau = np.asarray(torque, dtype=float)
    m_inv = np.linalg.inv(I_SC - sum(j * np.outer(g, g) for j, g in zip(JS, GS)))

    def f(t, x):
        s, w, Om = x[:3], x[3:6], x[6:]
        u = motor_torque(t)
        h = I_SC @ w + GS.T @ (JS * Om)
        wdot = m_inv @ (tau - GS.T @ u - np.cross(w, h))
        Omdot = u / JS - GS @ wdot
        s2 = s @ s
        sdot = 0.25 * ((1.0 - s2) * np.eye(3) + 2.0 * skew(s) + 2.0 * np.outer(s, s)) @ w
        return np.concatenate([sdot, wdot, Omdot])

    x = np.concatenate([[0.3, -0.2, 0.5], [0.05, -0.03, 0.08], [10.0, -5.0, 3.0]])
    n_steps = int(round(duration / dt))
    rec = []
    switches = 0
    for k in range(n_steps + 1):
        if k % every == 0:
            rec.append((round(k * dt * 1e9), *x))
        if k == n_steps:
            break
        t = k * dt
        k1 = f(t, x)
        k2 = f(t + dt / 2, x + dt / 2 * k1)
        k3 = f(t + dt / 2, x + dt / 2 * k2)
        k4 = f(t + dt, x + dt * k3)
        x = x + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        s2 = x[:3] @ x[:3]
        if s2 > 1.0:
            x[:3] = -x[:3] / s2
            switches += 1
    r = np.array(rec)
    return {
        "t_ns": r[:, 0].astype(np.int64),
        "sigma": r[:, 1:4],
        "omega": r[:, 4:7],
        "Omega": r[:, 7:],
        "switches": switches,
    }


def converted(sim, **kw):
    return bsk.from_basilisk(
        sim["t_ns"], sim["sigma"], sim["omega"],
        wheel_speeds=sim["Omega"], Js=JS, gs_B=GS, **kw,
    )


# ---------------------------------------------------------------------------- attitude


def test_quaternion_is_basilisks_dcm_read_body_to_inertial():
    rng = np.random.default_rng(1)
    sigmas = rng.normal(size=(200, 3)) * rng.uniform(0.05, 3.0, size=(200, 1))
    q = bsk.mrp_to_quaternion(sigmas, continuous=False)
    assert np.allclose(np.linalg.norm(q, axis=1), 1.0, atol=1e-14)
    worst = max(np.abs(rot(qk) - mrp2c(s).T).max() for qk, s in zip(q, sigmas))
    assert worst < 1e-13, worst
    # The conjugate is the N -> B reading: it gives [BN], not [BN]ᵀ.
    off = min(np.abs(rot(conj(qk)) - mrp2c(s).T).max() for qk, s in zip(q, sigmas))
    assert off > 1e-3, off


def test_shadow_set_is_the_same_attitude_and_minus_q():
    rng = np.random.default_rng(2)
    s = rng.normal(size=(100, 3))
    shadow = -s / np.einsum("ij,ij->i", s, s)[:, None]
    a = bsk.mrp_to_quaternion(s, continuous=False)
    b = bsk.mrp_to_quaternion(shadow, continuous=False)
    assert np.allclose(a, -b, atol=1e-14)
    # A sequence that alternates between the sets comes out sign-continuous.
    mixed = np.where((np.arange(100) % 2 == 0)[:, None], s, shadow)
    c = bsk.mrp_to_quaternion(np.repeat(mixed[:1], 5, axis=0))
    assert np.all(c[:, 3] >= 0)
    steady = np.repeat(s[:1], 6, axis=0)
    steady[1::2] = -steady[1::2] / (steady[1::2] ** 2).sum(axis=1)[:, None]
    d = bsk.mrp_to_quaternion(steady)
    assert np.allclose(d, d[0], atol=1e-14), "shadow switches left jumps in q"


def test_round_trip_with_inertias_conventions():
    rng = np.random.default_rng(3)
    q = rng.normal(size=(300, 4))
    q /= np.linalg.norm(q, axis=1)[:, None]
    s = bsk.quaternion_to_mrp(q)
    assert np.all(np.linalg.norm(s, axis=1) <= 1.0 + 1e-12)
    back = bsk.mrp_to_quaternion(s, continuous=False)
    same = np.minimum(np.abs(back - q).max(axis=1), np.abs(back + q).max(axis=1))
    assert same.max() < 1e-13
    # Composition: the turn between two samples, Hamilton order q_k† q_{k+1}, is the body
    # rotation: rot(q_{k+1}) = rot(q_k) rot(q_k† q_{k+1}).
    for a, b in zip(back[:-1], back[1:]):
        assert np.allclose(rot(b), rot(a) @ rot(qmul(conj(a), b)), atol=1e-13)


def test_attitude_increments_are_the_body_rates():
    sim = simulate()
    assert sim["switches"] >= 1, "the run must cross a shadow-set switch"
    d = converted(sim)
    h = np.diff(d["t"])
    assert np.allclose(h, 0.1, atol=1e-15)
    rate_q = np.array(
        [2.0 * qmul(conj(a), b)[:3] / hk for a, b, hk in zip(d["q"][:-1], d["q"][1:], h)]
    )
    scale = np.abs(sim["omega"]).max()
    err = np.abs(rate_q - d["w"][:-1]).max() / scale
    assert err < 1e-3, err
    # Control: the conjugated quaternions give the wrong rates.
    qc = d["q"] * np.array([-1.0, -1.0, -1.0, 1.0])
    rate_c = np.array(
        [2.0 * qmul(conj(a), b)[:3] / hk for a, b, hk in zip(qc[:-1], qc[1:], h)]
    )
    assert np.abs(rate_c - d["w"][:-1]).max() / scale > 0.3
    # The trapezoid is the interval mean to O(h²): better than the instantaneous rate.
    inst = np.abs(rate_q - sim["omega"][:-1]).max() / scale
    assert err < inst / 10, (err, inst)


# -------------------------------------------------------------------------- wheel momentum


def inertial_momentum(d, J):
    return np.array([rot(q) @ (J @ w + r) for q, w, r in zip(d["q"], d["omega"], d["rho"])])


def test_rho_is_the_relative_wheel_momentum_of_the_total_inertia():
    sim = simulate()
    rel = dict(converted(sim), omega=sim["omega"])
    ab = dict(converted(sim, wheel_momentum_kind="absolute"), omega=sim["omega"])
    spin = sum(j * np.outer(g, g) for j, g in zip(JS, GS))
    drift = lambda H: np.abs(H - H[0]).max() / np.linalg.norm(H[0])  # noqa: E731
    # inertia's gyrostat: C(q)(J ω + ρ) is conserved without external torque.
    assert drift(inertial_momentum(rel, I_SC)) < 1e-9
    assert drift(inertial_momentum(ab, I_SC - spin)) < 1e-9
    # The mismatched pairs are not conserved.
    assert drift(inertial_momentum(ab, I_SC)) > 1e-3
    assert drift(inertial_momentum(rel, I_SC - spin)) > 1e-3
    # And the explicit sums.
    k = 37
    assert np.allclose(rel["rho"][k], sum(j * o * g for j, o, g in zip(JS, sim["Omega"][k], GS)))
    w = sim["omega"][k]
    assert np.allclose(
        ab["rho"][k], sum(j * (o + g @ w) * g for j, o, g in zip(JS, sim["Omega"][k], GS))
    )


def test_gyrostat_equation_holds_with_the_converted_inputs():
    """Eq. 26, J ω̇ + ω × (J ω + ρ) + ρ̇ = τ, by central differences (O(h²)) on 10 ms data."""
    sim = simulate(duration=20.0, every=1)
    d = converted(sim, rates="instant")
    h = 0.01
    w, rho = d["w"], d["rho"]
    wd = (w[2:] - w[:-2]) / (2 * h)
    rd = (rho[2:] - rho[:-2]) / (2 * h)
    m = w[1:-1]
    res = wd @ I_SC.T + np.cross(m, m @ I_SC.T + rho[1:-1]) + rd
    size = np.abs(wd @ I_SC.T).max()
    assert np.abs(res).max() / size < 1e-3, np.abs(res).max() / size
    d_abs = converted(sim, rates="instant", wheel_momentum_kind="absolute")
    rho_a = d_abs["rho"]
    res_a = wd @ I_SC.T + np.cross(m, m @ I_SC.T + rho_a[1:-1]) + (rho_a[2:] - rho_a[:-2]) / (2 * h)
    assert np.abs(res_a).max() / size > 1e-2


def test_external_torque_is_body_axes():
    tau = (2e-3, -1e-3, 1.5e-3)
    sim = simulate(duration=20.0, every=1, torque=tau)
    d = converted(sim, tau_B=np.tile(tau, (len(sim["t_ns"]), 1)))
    d["omega"] = sim["omega"]
    H = inertial_momentum(d, I_SC)
    applied = np.array([rot(q) @ t for q, t in zip(d["q"], d["tau"])])
    integral = np.concatenate([[np.zeros(3)], np.cumsum(0.5 * (applied[1:] + applied[:-1]) * 0.01, axis=0)])
    change = H - H[0]
    assert np.abs(change - integral).max() / np.abs(change).max() < 1e-4
    # Control: the torque read in inertial axes does not account for the change.
    wrong = np.cumsum(np.tile(tau, (len(H) - 1, 1)) * 0.01, axis=0)
    assert np.abs(change[1:] - wrong).max() / np.abs(change).max() > 1e-2


# ------------------------------------------------------------------------------ inputs


def test_delta_angles_give_the_interval_mean():
    sim = simulate(duration=20.0, every=1)
    # Exact delta angles over 0.1 s steps from the 10 ms record (Simpson on each step).
    om, t = sim["omega"], sim["t_ns"] / 1e9
    idx = np.arange(0, len(t), 10)
    dth = np.zeros((len(idx), 3))
    for j in range(1, len(idx)):
        seg = om[idx[j - 1]: idx[j] + 1]
        dth[j] = 0.01 / 3 * (seg[0] + seg[-1] + 4 * seg[1:-1:2].sum(0) + 2 * seg[2:-1:2].sum(0))
    d = bsk.from_basilisk(sim["t_ns"][idx], sim["sigma"][idx], delta_angle_B=dth)
    # The delta angle that ends at sample k+1 is the rate over [t_k, t_{k+1}].
    assert np.allclose(d["w"][:-1], dth[1:] / 0.1, rtol=1e-12, atol=0)
    rate_q = np.array(
        [2.0 * qmul(conj(a), b)[:3] / 0.1 for a, b in zip(d["q"][:-1], d["q"][1:])]
    )
    assert np.abs(rate_q - d["w"][:-1]).max() / np.abs(om).max() < 1e-3
    # Control: without the shift (Δθ_k over [t_k, t_{k+1}]) it is a step late.
    assert np.abs(rate_q[1:] - dth[1:-1] / 0.1).max() / np.abs(om).max() > 1e-2
    assert np.array_equal(d["w"][-1], d["w"][-2])
    assert np.allclose(d["rho"], 0.0) and np.allclose(d["tau"], 0.0)


def test_time_units_and_validation():
    sim = simulate()
    a = converted(sim)
    b = bsk.from_basilisk(
        sim["t_ns"] / 1e9, sim["sigma"], sim["omega"], time_unit="s",
        wheel_speeds=sim["Omega"], Js=JS, gs_B=GS,
    )
    assert np.allclose(a["t"], b["t"], rtol=0, atol=1e-12)
    assert a["t"][0] == 0.0 and a["t"][-1] == 120.0
    with pytest.raises(ValueError, match="whole nanoseconds"):
        bsk.from_basilisk(sim["t_ns"] / 1e9, sim["sigma"], sim["omega"])
    with pytest.raises(ValueError, match="not increasing at index 3"):
        t = sim["t_ns"].copy()
        t[3] = t[2]
        bsk.from_basilisk(t, sim["sigma"], sim["omega"])
    with pytest.raises(ValueError, match="sigma_BN: non-finite value at index \\(5, 1\\)"):
        s = sim["sigma"].copy()
        s[5, 1] = np.nan
        bsk.from_basilisk(sim["t_ns"], s, sim["omega"])
    with pytest.raises(ValueError, match="gs_B: spin axes must be unit"):
        converted_bad = dict(wheel_speeds=sim["Omega"], Js=JS, gs_B=2 * GS)
        bsk.from_basilisk(sim["t_ns"], sim["sigma"], sim["omega"], **converted_bad)
    with pytest.raises(ValueError, match="needs Js and gs_B"):
        bsk.from_basilisk(sim["t_ns"], sim["sigma"], sim["omega"], wheel_speeds=sim["Omega"])
    with pytest.raises(ValueError, match="omega_BN_B: shape"):
        bsk.from_basilisk(sim["t_ns"], sim["sigma"], sim["omega"][:, :2])
    with pytest.raises(ValueError, match="wheel_speeds: 10 rows, expected 1201"):
        bsk.from_basilisk(
            sim["t_ns"], sim["sigma"], sim["omega"],
            wheel_speeds=sim["Omega"][:10], Js=JS, gs_B=GS,
        )
    assert bsk.from_basilisk(sim["t_ns"], sim["sigma"], rates=None)["w"] is None


# ----------------------------------------------------------------- end to end, the CLI


def inertia_bin():
    env = os.environ.get("INERTIA_CLI") or os.environ.get("INERTIA_BIN")
    if env:
        assert pathlib.Path(env).exists(), f"INERTIA_CLI/INERTIA_BIN={env} does not exist"
        return pathlib.Path(env)
    for p in (REPO / "target" / "release" / "inertia", REPO / "target" / "debug" / "inertia"):
        if p.exists():
            return p
    return None


def estimate_with_cli(d, tmp_path, *args):
    exe = inertia_bin()
    if exe is None:
        pytest.skip("no inertia binary (set INERTIA_BIN or cargo build --release -p inertia-cli)")
    path = tmp_path / "basilisk.csv"
    bsk.to_csv(path, d)
    out = subprocess.run(
        [str(exe), "estimate", str(path), "--json", *args],
        capture_output=True, text=True, check=False,
    )
    assert out.returncode == 0, out.stderr
    r = json.loads(out.stdout)
    return np.array(r["inertia"]), r


def rel_err(a, b):
    return np.linalg.norm(a - b) / np.linalg.norm(b)


def test_cli_estimates_the_total_inertia_from_converted_data(tmp_path):
    sim = simulate()
    J, report = estimate_with_cli(converted(sim), tmp_path)
    assert rel_err(J, I_SC) < 1e-4, (rel_err(J, I_SC), report["status"])
    spin = sum(j * np.outer(g, g) for j, g in zip(JS, GS))
    J_abs, _ = estimate_with_cli(converted(sim, wheel_momentum_kind="absolute"), tmp_path)
    assert rel_err(J_abs, I_SC - spin) < 1e-4
    assert rel_err(J_abs, I_SC) > 1e-2


def test_cli_refuses_the_conjugated_reading(tmp_path):
    """The module docs' claim: reading σ_BN's quaternion as N -> B (conjugated) is caught by
    the library's convention check, which names --conjugate (a JPL quaternion has this
    tool's numbers, so --jpl would not read it)."""
    exe = inertia_bin()
    if exe is None:
        pytest.skip("no inertia binary (set INERTIA_BIN or cargo build --release -p inertia-cli)")
    d = converted(simulate())
    d["q"] = d["q"] * np.array([-1.0, -1.0, -1.0, 1.0])
    path = tmp_path / "conjugated.csv"
    bsk.to_csv(path, d)
    out = subprocess.run([str(exe), "estimate", str(path)], capture_output=True, text=True)
    assert out.returncode == 2 and "--conjugate" in out.stderr, out.stderr
    assert "--jpl" not in out.stderr, out.stderr


# --------------------------------------------------------- end to end, Basilisk itself


def basilisk_run(duration=120.0):
    """A tumbling spacecraft with three custom balanced reaction wheels whose motor
    torques change every 4 s; recorded at 10 Hz, with Basilisk's own total angular
    momentum."""
    from Basilisk.simulation import spacecraft
    from Basilisk.utilities import SimulationBaseClass, macros

    sim = SimulationBaseClass.SimBaseClass()
    proc = sim.CreateNewProcess("dyn")
    proc.addTask(sim.CreateNewTask("task", macros.sec2nano(0.01)))
    sc = spacecraft.Spacecraft()
    sc.ModelTag = "sc"
    sc.hub.mHub = 50.0
    sc.hub.r_BcB_B = [[0.0], [0.0], [0.0]]
    sc.hub.IHubPntBc_B = I_SC.tolist()
    sc.hub.sigma_BNInit = [[0.3], [-0.2], [0.5]]
    sc.hub.omega_BN_BInit = [[0.05], [-0.03], [0.08]]
    rw, cmd, cmd_msg = basilisk_wheels(sim, sc, GS, JS)
    rec_sc = sc.scStateOutMsg.recorder(macros.sec2nano(0.1))
    rec_rw = rw.rwSpeedOutMsg.recorder(macros.sec2nano(0.1))
    log = sc.logger(["totRotAngMomPntC_N"], macros.sec2nano(0.1))
    for r in (rec_sc, rec_rw, log):
        sim.AddModelToTask("task", r)
    sim.InitializeSimulation()
    rng = np.random.default_rng(7)
    t = 0.0
    while t < duration - 1e-9:
        cmd.motorTorque = list(rng.uniform(-0.02, 0.02, size=3)) + [0.0] * 33
        cmd_msg.write(cmd, sim.TotalSim.CurrentNanos)
        t += 4.0
        sim.ConfigureStopTime(macros.sec2nano(t))
        sim.ExecuteSimulation()
    return {
        "t_ns": np.asarray(rec_sc.times()),
        "sigma": np.asarray(rec_sc.sigma_BN),
        "omega": np.asarray(rec_sc.omega_BN_B),
        "Omega": np.asarray(rec_rw.wheelSpeeds)[:, :3],
        "H_N": np.asarray(log.totRotAngMomPntC_N),
    }


def test_basilisk_end_to_end(tmp_path):
    pytest.importorskip("Basilisk", reason="Basilisk not installed (pip install bsk)")
    run = basilisk_run()
    d = converted(run)
    assert np.abs(run["sigma"]).max() > 0.5 and np.ptp(run["Omega"]) > 1.0
    # The attitude increments against Basilisk's own rates.
    h = np.diff(d["t"])
    rate_q = np.array(
        [2.0 * qmul(conj(a), b)[:3] / hk for a, b, hk in zip(d["q"][:-1], d["q"][1:], h)]
    )
    scale = np.abs(run["omega"]).max()
    assert np.abs(rate_q - d["w"][:-1]).max() / scale < 1e-3
    # Basilisk's own total momentum is inertia's C(q)(J ω + ρ) with the converted q and ρ
    # and J = IHubPntBc_B ...
    H_N = run["H_N"]
    mine = inertial_momentum(dict(d, omega=run["omega"]), I_SC)
    size = np.linalg.norm(H_N[0])
    assert np.abs(mine - H_N).max() / size < 1e-12
    # ... and not with the wheels' inertia added to the hub's (Jt = Jg = Js/2 across).
    wheels = sum(j * np.outer(g, g) + 0.5 * j * (np.eye(3) - np.outer(g, g)) for j, g in zip(JS, GS))
    other = inertial_momentum(dict(d, omega=run["omega"]), I_SC + wheels)
    assert np.abs(other - H_N).max() / size > 1e-3
    J, report = estimate_with_cli(d, tmp_path)
    err = rel_err(J, I_SC)
    print(f"Basilisk end to end: relative error {err:.3e}, status {report['status']}")
    assert err < 1e-3, (err, report["status"])
