#!/usr/bin/env python3
"""Why the momentum RLS leads the discrete momentum rows in a few cells of the matrix
(book/src/monte-carlo.md, "Why the RLS leads there"): every row form as one
batch least-squares problem in numpy, on the same simulated files, seed by seed.

    cargo build --release -p inertia-cli
    python3 scripts/rls_vs_rows.py mems 30        # the MEMS slew, seeds 1..30
    python3 scripts/rls_vs_rows.py small-sat 30   # the small satellite with a FOG
    python3 scripts/rls_vs_rows.py fog-midway 30  # the slew, FOG, commands mid-way
    INERTIA_BIN=/path/to/inertia python3 scripts/rls_vs_rows.py mems 30   # another binary

Needs numpy. Simulates into a temporary directory with target/release/inertia (or the
binary named by the environment variable INERTIA_BIN), then
prints, per row form, the median relative Frobenius error, its median ratio to the RLS's
and the mean error per element (relative to ‖J‖; the attenuation of errors-in-variables
shows there), plus each form's error on noise-free telemetry of the same case.

Cases: "mems" (the slew, MEMS-propagated attitude), "small-sat" (the small satellite,
FOG-propagated attitude, no gyro bias), "fog-midway" (the slew, FOG-propagated attitude,
10 Hz commands changing half-way between samples); all 10 Hz, commands held at 10 Hz.

Row forms (all with one initial momentum for the whole record, no torque unknown):
  rls            C_k G(ω_k) j − h = −C_k ρ_k, ω_k the mean of the two adjacent intervals'
                 rates (estimator::momentum, batch instead of recursive)
  rls, ρ matched the same with ρ averaged over the span its rate averages,
                 (ρ_{k−1} + 2ρ_k + ρ_{k+1})/4: exact on noise-free data
  plain          the discrete momentum rows of one interval, (2/h) C N(φ) G(φ) j − L = −C N(φ) ρ̄
  averaged       the plain rows of two neighbouring intervals averaged (the first-order
                 noise of the Richardson rows)
  averaged, comp the same, errors-in-variables compensated with the gyro's density
  averaged, GLS  the same weighted by its noise's covariance as the gyro's alone would
                 make it: each block by Ĵ⁻¹ (C N)ᵀ, Ĵ the averaged rows' answer (the gyro's
                 noise enters the momentum as C J δω); tried, not adopted
  averaged, GLS, comp  both
  plain|averaged, IV …  instrumental variables, no density needed: the instruments of
                 row block k are the same form's regressor blocks at k−L ("IV k-L"), the
                 mean of those at k−L and k+L ("IV (k±L)/2"; both just-identified,
                 (Zᵀ X)⁻¹ Zᵀ y), or the blocks side by side by two-stage least squares
                 ("2SLS k±2": k−2 and k+2; "2SLS k-2:4": k−2, k−3, k−4); the −I column of the
                 initial momentum is its own instrument. Their gyro noise (φ, white per
                 interval) is independent of block k's; the attitude's random walk (C_k of a
                 gyro-propagated attitude) is common to all and stays (second order, small).
  averaged, GLS-IV k-2  the same with the GLS weight, block k and its instruments
                 weighted by block k−2's Ĵ⁻¹ (C N)ᵀ (free of block k's gyro noise)
  avg κ, …       the averaged rows with the default stencil's κ column (ρ̄ of both
                 intervals moved by κ Δ²ρ at their common node, κ estimated with j; exact
                 to O(h²) when the commands change between samples): least squares,
                 compensated, IV, GLS and GLS-IV as above

Then two tests of whether the data can tell when the GLS weighting pays. The residuals'
shape: the unweighted rows' residuals rotated back to the body, (C N)ᵀ r, fitted by
maximum likelihood with covariance s Ĵ² (the gyro's noise) or s I (the wheels'); the
statistic tr(J̃⁻² S)/tr(S), J̃ = Ĵ/det(Ĵ)^⅓, is below 1 where Ĵ² fits better. And a
second table: the record
cut into 8 chains (each with its own initial momentum, as the estimator's chain groups),
the averaged rows unweighted and GLS-weighted, and per seed the one whose delete-a-chain
jackknife σ (Frobenius) is the smaller.

"spread" is the root of the summed variances of the six elements over the seeds, the
noise part of the error; the mean error per element is its bias part. (On the small
satellite most of that mean, about −5e-5 on J11, +4e-5 on J13 and −2e-5 on J23 in every
form, is the wheels' 1e-5 N m s quantisation, whose error nearly repeats from seed to seed
on the same trajectory: it goes with `--wheel-quantization-nms 0`, not with
`--disturbance 0`.)
"""
import json
import os
import subprocess
import sys
import tempfile

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BIN = os.environ.get("INERTIA_BIN", os.path.join(ROOT, "target", "release", "inertia"))

NO_BIAS = ["--gyro-bias-deg-h", "0:0:0", "--gyro-bias-instability-deg-h", "0"]
CLEAN = ["--attitude", "truth", "--gyro-noise", "0", "--disturbance", "0",
         "--wheel-quantization-nms", "0"]
CASES = {
    # name: (craft and commands, the sensors of the noisy runs, gyro density deg/s/√Hz)
    "mems": (["--scenario", "slew", "--controller-hz", "10"],
             ["--attitude", "gyro", "--gyro-noise", "0.0025"], 0.0025),
    "small-sat": (["--preset", "small-sat", "--controller-hz", "10", *NO_BIAS],
                  ["--attitude", "gyro", "--gyro-arw-deg-rthr", "0.02"], 0.02 / 60),
    # The paper slew with a FOG-propagated attitude, commands changing mid-way between
    # samples (the matrix's "slew | FOG-propagated | 10 Hz mid-way").
    "fog-midway": (["--scenario", "slew", "--controller-hz", "10", "--command-phase", "0.05"],
                   ["--attitude", "gyro", "--gyro-arw-deg-rthr", "0.02"], 0.02 / 60),
}


def rotation(q):
    x, y, z, w = q.T
    r = np.empty((len(q), 3, 3))
    r[:, 0] = np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)], 1)
    r[:, 1] = np.stack([2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)], 1)
    r[:, 2] = np.stack([2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)], 1)
    return r


def g(p):
    """G(p) with G(p) j = J p (j = J11 J22 J33 J12 J13 J23)."""
    a, b, c = p[..., 0], p[..., 1], p[..., 2]
    o = np.zeros_like(a)
    return np.stack([np.stack([a, o, o, b, c, o], -1),
                     np.stack([o, b, o, a, o, c], -1),
                     np.stack([o, o, c, o, a, b], -1)], -2)


def n_matrix(p):
    a, b, c = p[..., 0], p[..., 1], p[..., 2]
    o = np.zeros_like(a)
    skew = np.stack([np.stack([o, -c, b], -1), np.stack([c, o, -a], -1),
                     np.stack([-b, a, o], -1)], -2)
    s = np.sqrt(1 - (p * p).sum(-1))
    return s[..., None, None] * np.eye(3) + skew


G_AXES = [g(np.eye(3)[i]) for i in range(3)]


def solve(a, b, eiv=0.0, whiten=None, j_white=None, extra=None):
    """min Σ‖W_k (a_k j − L − b_k)‖² over j and one L (W_k = I unless `whiten`);
    `eiv` the rows' expected noise Gram per row block (σ² noise_s), removed from the
    normal equations: `σ² noise_s D` unweighted, `Σ_i G(e_i)ᵀ J⁻² G(e_i)` times it when
    whitened by `J⁻¹ (C N)ᵀ` (`j_white` that J). `extra` (n × 3 × p): more nuisance
    columns (the κ column)."""
    n = len(a)
    w = np.broadcast_to(np.eye(3), (n, 3, 3)) if whiten is None else whiten
    cols = [w @ a, -w] + ([] if extra is None else [w @ extra])
    m = np.concatenate(cols, axis=2).reshape(3 * n, -1)
    normal = m.T @ m
    j_inv = np.eye(3) if j_white is None else np.linalg.inv(j_white)
    normal[:6, :6] -= n * eiv * sum(x.T @ j_inv @ j_inv @ x for x in G_AXES)
    j = np.linalg.solve(normal, m.T @ (w @ b[..., None]).reshape(-1))[:6]
    return np.array([[j[0], j[3], j[4]], [j[3], j[1], j[5]], [j[4], j[5], j[2]]])


def solve_iv(a, b, offsets, stack=False, whiten=None, extra=None):
    """Instrumental variables for `a_k j − L = b_k` (one L): the instruments of row block k
    are the same form's regressor blocks at k + o, o in `offsets` (e.g. −2, or −2 and +2),
    whose gyro noise is independent of block k's when the noise is white per interval;
    the nuisance column −I is its own instrument. Averaged over the offsets and
    just-identified, Ĵ from (Zᵀ X) θ = Zᵀ y (`stack` False), or the blocks side by side
    and two-stage least squares (`stack` True). Blocks whose instruments fall outside the
    record are dropped. `whiten`, per block, weights row block k and its instruments by
    the weight of block k − 2 (Σ_k⁻¹ ≈ W_{k−2}ᵀ W_{k−2}, a weight free of block k's own
    gyro noise). `extra` (n × 3 × p): more nuisance columns, their own instruments (the
    κ column: wheel data and the attitude, no interval's gyro noise but through C N)."""
    n = len(a)
    back = max([-o for o in offsets if o < 0], default=0)
    ahead = max([o for o in offsets if o > 0], default=0)
    rows = np.arange(max(back, 2 if whiten is not None else 0), n - ahead)
    m = len(rows)
    w = (np.broadcast_to(np.eye(3), (m, 3, 3)) if whiten is None else whiten[rows - 2])
    nuisance = [-w] + ([] if extra is None else [w @ extra[rows]])
    x = np.concatenate([w @ a[rows], *nuisance], axis=2).reshape(3 * m, -1)
    y = (w @ b[rows][..., None]).reshape(-1)
    blocks = [w @ a[rows + o] for o in offsets]
    if stack:
        z = np.concatenate([*blocks, *nuisance], axis=2).reshape(3 * m, -1)
        # Two-stage least squares: X projected on the instruments, then least squares.
        x_hat = z @ np.linalg.lstsq(z, x, rcond=None)[0]
        j = np.linalg.solve(x_hat.T @ x, x_hat.T @ y)[:6]
    else:
        z = np.concatenate([sum(blocks) / len(blocks), *nuisance],
                           axis=2).reshape(3 * m, -1)
        j = np.linalg.solve(z.T @ x, z.T @ y)[:6]
    return to_matrix(j)


def solve_chains(a, b, w, chain):
    """min Σ‖W_k (a_k j − L_chain(k) − b_k)‖² over j and one L per chain: j."""
    n, chains = len(a), chain.max() + 1
    m = np.zeros((3 * n, 6 + 3 * chains))
    m[:, :6] = (w @ a).reshape(3 * n, 6)
    for i in range(chains):
        rows = np.where(chain == i)[0]
        for k in range(3):
            m[3 * rows + k, 6 + 3 * i:9 + 3 * i] = -w[rows][:, k, :]
    return np.linalg.lstsq(m, (w @ b[..., None]).reshape(-1), rcond=None)[0][:6]


def jackknife(a, b, w, chains=8):
    """j over `chains` chains and its delete-a-chain jackknife σ (Frobenius)."""
    n = len(a)
    chain = np.minimum(np.arange(n) * chains // n, chains - 1)
    full = solve_chains(a, b, w, chain)
    deleted = np.array([
        solve_chains(a[chain != i], b[chain != i], w[chain != i],
                     np.unique(chain[chain != i], return_inverse=True)[1])
        for i in range(chains)])
    var = (chains - 1) / chains * ((deleted - deleted.mean(0)) ** 2).sum(0)
    return full, np.sqrt(var[:3].sum() + 2 * var[3:].sum())


def to_matrix(j):
    return np.array([[j[0], j[3], j[4]], [j[3], j[1], j[5]], [j[4], j[5], j[2]]])


def plain_rows(c, w, rho, h):
    """The discrete momentum rows of one interval each, `a j − L = b`, and their `C N`
    (c: the attitude matrices at the nodes, w: the gyro's interval rates)."""
    theta = w[:-1] * h
    angle = np.linalg.norm(theta, axis=1, keepdims=True)
    phi = np.sin(angle / 2) * theta / np.where(angle > 0, angle, 1)
    cn = c[:-1] @ n_matrix(phi)
    a = cn @ g(phi) * (2 / h)
    b = -(cn @ ((rho[:-1] + rho[1:]) / 2)[..., None])[..., 0]
    return cn, a, b


def forms(path, density_deg):
    d = np.genfromtxt(path, delimiter=",", names=True)
    t = d["t"]
    q = np.stack([d["q_x"], d["q_y"], d["q_z"], d["q_w"]], 1)
    rho = np.stack([d["rho_x"], d["rho_y"], d["rho_z"]], 1)
    w = np.stack([d["w_x"], d["w_y"], d["w_z"]], 1)
    truth = np.array(json.load(open(path.replace(".csv", ".truth.json")))["inertia_kg_m2"])
    h = t[1] - t[0]
    c = rotation(q)
    node = c[1:-1]
    a_rls = node @ g((w[:-2] + w[1:-1]) / 2)
    out = {
        "rls": solve(a_rls, -(node @ rho[1:-1][..., None])[..., 0]),
        "rls, ρ matched": solve(
            a_rls, -(node @ ((rho[:-2] + 2 * rho[1:-1] + rho[2:]) / 4)[..., None])[..., 0]),
    }
    cn, a, b = plain_rows(c, w, rho, h)
    out["plain"] = solve(a, b)
    a2, b2 = (a[:-1] + a[1:]) / 2, (b[:-1] + b[1:]) / 2
    out["averaged"] = solve(a2, b2)
    eiv = np.radians(density_deg) ** 2 / (2 * h)
    out["averaged, comp"] = solve(a2, b2, eiv)
    first = out["averaged"]
    whiten = np.linalg.inv(first) @ np.transpose((cn[:-1] + cn[1:]) / 2, (0, 2, 1))
    out["averaged, GLS"] = solve(a2, b2, whiten=whiten)
    out["averaged, GLS, comp"] = solve(a2, b2, eiv, whiten, first)
    # Instrumental variables (the regressor blocks of the same form at other intervals):
    # no density needed. For the averaged rows the blocks at k ± 1 share an interval with
    # block k, so the offsets start at 2; the attitude's random walk (gyro-propagated C_k)
    # is common to all blocks and not removed (a second-order term, small).
    for name, rows_a, rows_b in [("plain", a, b), ("averaged", a2, b2)]:
        for label, offsets, stack in [("IV k-2", [-2], False), ("IV k-4", [-4], False),
                                      ("IV (k±2)/2", [-2, 2], False),
                                      ("IV (k±4)/2", [-4, 4], False),
                                      ("2SLS k±2", [-2, 2], True),
                                      ("2SLS k-2:4", [-2, -3, -4], True)]:
            out[f"{name}, {label}"] = solve_iv(rows_a, rows_b, offsets, stack)
    out["averaged, GLS-IV k-2"] = solve_iv(a2, b2, [-2], whiten=whiten)
    # The averaged rows with the κ column of the default stencil (ρ̄ of both intervals
    # moved by κ Δ²ρ at their common node; exact to O(h²) when the commands change
    # between samples, which the trapezoid is not).
    d2 = rho[2:] - 2 * rho[1:-1] + rho[:-2]
    kappa = ((cn[:-1] + cn[1:]) / 2 @ d2[..., None])
    out["avg κ"] = solve(a2, b2, extra=kappa)
    out["avg κ, comp"] = solve(a2, b2, eiv, extra=kappa)
    out["avg κ, IV k-2"] = solve_iv(a2, b2, [-2], extra=kappa)
    out["avg κ, IV (k±2)/2"] = solve_iv(a2, b2, [-2, 2], extra=kappa)
    out["avg κ, 2SLS k±2"] = solve_iv(a2, b2, [-2, 2], True, extra=kappa)
    out["avg κ, GLS"] = solve(a2, b2, whiten=whiten, extra=kappa)
    out["avg κ, GLS-IV k-2"] = solve_iv(a2, b2, [-2], whiten=whiten, extra=kappa)
    scale = np.linalg.norm(truth)
    # Chains, unweighted and GLS-weighted (by the unweighted chains' answer), and the
    # one with the smaller jackknife σ.
    eye = np.broadcast_to(np.eye(3), a2.shape[:1] + (3, 3))
    j_u, s_u = jackknife(a2, b2, eye)
    white = np.linalg.inv(to_matrix(j_u)) @ np.transpose((cn[:-1] + cn[1:]) / 2, (0, 2, 1))
    j_g, s_g = jackknife(a2, b2, white)
    # Which covariance shape the unweighted rows' residuals, rotated back to the body,
    # fit better by maximum likelihood (each with a free scale): Ĵ² (the gyro's noise,
    # C J δω) where this is below 1, I (the wheels') above.
    jv = np.array([first[0, 0], first[1, 1], first[2, 2], first[0, 1], first[0, 2],
                   first[1, 2]])
    fit = a2 @ jv - b2
    body = (np.transpose((cn[:-1] + cn[1:]) / 2, (0, 2, 1)) @ (fit - fit.mean(0))[..., None])
    spread = body[..., 0].T @ body[..., 0]
    shape = np.linalg.inv(first / np.cbrt(np.linalg.det(first)))
    likelihood = np.trace(shape @ shape @ spread) / np.trace(spread)
    chained = {"chains": to_matrix(j_u), "chains, GLS": to_matrix(j_g),
               "chains, by jackknife": to_matrix(j_g if s_g < s_u else j_u)}
    return ({k: (v - truth) / scale for k, v in out.items()},
            {k: (v - truth) / scale for k, v in chained.items()}, s_g < s_u, likelihood)


def main():
    case = sys.argv[1] if len(sys.argv) > 1 else "mems"
    seeds = int(sys.argv[2]) if len(sys.argv) > 2 else 30
    options, sensors, density = CASES[case]
    with tempfile.TemporaryDirectory() as tmp:
        def simulate(name, extra):
            path = os.path.join(tmp, name + ".csv")
            subprocess.run([BIN, "simulate", *options, *extra, "-o", path],
                           check=True, capture_output=True)
            return path

        both = [forms(simulate(f"s{s}", [*sensors, "--seed", str(s)]), density)
                for s in range(1, seeds + 1)]
        runs = [r[0] for r in both]
        # No gyro noise in it, so none to compensate.
        clean = forms(simulate("clean", CLEAN), 0.0)[0]
    rls = np.array([np.linalg.norm(r["rls"]) for r in runs])
    print(f"{case}, {seeds} seeds: error relative to ‖J‖ (Frobenius)")
    print(f"{'form':20s} {'median':>9s} {'/RLS':>6s} {'spread':>9s} {'noise-free':>10s}"
          "   mean error J11 J22 J33 J12 J13 J23")
    upper = np.triu_indices(3)
    for k in runs[0]:
        e = np.array([np.linalg.norm(r[k]) for r in runs])
        elems = np.array([r[k][upper] for r in runs])
        spread = np.sqrt(elems.var(axis=0).sum())
        mean = elems.mean(axis=0)[[0, 3, 5, 1, 2, 4]]
        print(f"{k:20s} {np.median(e):9.3e} {np.median(e / rls):6.3f} {spread:9.3e} "
              f"{np.linalg.norm(clean[k]):10.1e}   " + " ".join(f"{x:+.1e}" for x in mean))
    chained = [r[1] for r in both]
    gls = np.array([r[2] for r in both])
    shapes = np.array([r[3] for r in both])
    print(f"\nresiduals' shape, tr(J̃⁻² S)/tr(S) (below 1: the gyro's, GLS): "
          f"{shapes.min():.3f}–{shapes.max():.3f}")
    e_u = np.array([np.linalg.norm(r["chains"]) for r in chained])
    e_g = np.array([np.linalg.norm(r["chains, GLS"]) for r in chained])
    print(f"\n8 chains; the jackknife chose GLS in {gls.sum()} of {seeds} seeds, "
          f"the one with the smaller error in {(gls == (e_g < e_u)).sum()}")
    for k in chained[0]:
        e = np.array([np.linalg.norm(r[k]) for r in chained])
        print(f"{k:20s} {np.median(e):9.3e} {np.median(e / rls):6.3f}")


if __name__ == "__main__":
    main()
