#!/usr/bin/env python3
"""Why no row form gets ahead on the small satellite (book/src/monte-carlo.md, "Why the RLS leads there"):
the wheel telemetry's 1e-5 N m s quantisation leaves an error floor that is shared by every
row form, is not removed by smoothing the wheel momentum, and does not come from the rows
where the wheels hold still.

    cargo build --release -p inertia-cli
    python3 scripts/quantisation_floor.py 8      # seeds 1..8
    INERTIA_BIN=/path/to/inertia python3 scripts/quantisation_floor.py 8

Needs numpy. Each seed simulates the small satellite twice with the true attitude and a
noise-free gyro (no bias), once with its quantised wheels and once with
`--wheel-quantization-nms 0`; everything else, the disturbance torque included, is the same,
so the two runs fly the same trajectory and differ only in the telemetered ρ. Printed:

* the default estimator (the CLI, defaults) on both files;
* the quantisation's effect on the answer, ĵ(quantised) − ĵ(exact) relative to ‖J‖, of two
  batch row forms of `scripts/rls_vs_rows.py` (the RLS's rows with matched ρ, and the
  discrete momentum rows averaged over two intervals): as telemetered, with ρ smoothed by a
  centred moving average of 3, 9 or 15 samples first, and without the rows where ρ did not
  change on any axis over the two intervals (the wheels holding still);
* the effect's mean over the seeds against its spread (a mean as large as the spread: it
  repeats from seed to seed on the same trajectory, a bias rather than noise).

The effect is linear in the quantisation error, so the forms' own discretisation errors
cancel in the difference.
"""
import json
import os
import subprocess
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from rls_vs_rows import BIN, NO_BIAS, g, plain_rows, rotation, solve  # noqa: E402

SIM = ["--preset", "small-sat", "--attitude", "truth", "--gyro-noise", "0", *NO_BIAS]


def smoothed(rho, width):
    if width == 1:
        return rho
    half = width // 2
    out = rho.copy()
    kernel = np.ones(width) / width
    for axis in range(3):
        out[half:-half, axis] = np.convolve(rho[:, axis], kernel, mode="valid")
    return out


def answers(path, width, drop_holds):
    d = np.genfromtxt(path, delimiter=",", names=True)
    q = np.stack([d["q_x"], d["q_y"], d["q_z"], d["q_w"]], 1)
    raw = np.stack([d["rho_x"], d["rho_y"], d["rho_z"]], 1)
    rho = smoothed(raw, width)
    w = np.stack([d["w_x"], d["w_y"], d["w_z"]], 1)
    h = d["t"][1] - d["t"][0]
    c = rotation(q)
    node = c[1:-1]
    # Row block k (k = 1 .. n−2) spans the intervals before and after node k.
    keep = np.ones(len(node), bool)
    if drop_holds:
        keep = ~np.all((raw[1:-1] == raw[:-2]) & (raw[1:-1] == raw[2:]), axis=1)
    a_rls = node @ g((w[:-2] + w[1:-1]) / 2)
    b_rls = -(node @ ((rho[:-2] + 2 * rho[1:-1] + rho[2:]) / 4)[..., None])[..., 0]
    _, a, b = plain_rows(c, w, rho, h)
    a2, b2 = (a[:-1] + a[1:]) / 2, (b[:-1] + b[1:]) / 2
    return {"RLS rows, ρ matched": solve(a_rls[keep], b_rls[keep]),
            "averaged rows": solve(a2[keep], b2[keep])}, keep.mean()


def default_error(path):
    out = subprocess.run([BIN, "estimate", path, "--truth",
                          path.replace(".csv", ".truth.json")],
                         check=True, capture_output=True, text=True).stdout
    line = next(x for x in out.splitlines() if "error vs truth" in x)
    return float(line.rsplit(":", 1)[1])


def main():
    seeds = int(sys.argv[1]) if len(sys.argv) > 1 else 8
    variants = [(1, False), (3, False), (9, False), (15, False), (1, True)]
    effects = {}
    defaults = []
    kept = []
    norm = None
    with tempfile.TemporaryDirectory() as tmp:
        for seed in range(1, seeds + 1):
            paths = []
            for lsb in ["1e-5", "0"]:
                path = os.path.join(tmp, f"s{seed}_{lsb}.csv")
                subprocess.run([BIN, "simulate", *SIM, "--wheel-quantization-nms", lsb,
                                "--seed", str(seed), "-o", path],
                               check=True, capture_output=True)
                paths.append(path)
            defaults.append([default_error(p) for p in paths])
            if norm is None:
                d = np.genfromtxt(paths[0], delimiter=",", names=True)
                steps = np.diff(np.stack([d["rho_x"], d["rho_y"], d["rho_z"]], 1), axis=0)
                still = (steps == 0).mean(axis=0)
                truth = json.load(open(paths[0].replace(".csv", ".truth.json")))
                norm = np.linalg.norm(np.array(truth["inertia_kg_m2"]))
            for width, drop in variants:
                quantised, share = answers(paths[0], width, drop)
                exact, _ = answers(paths[1], width, drop)
                if drop:
                    kept.append(share)
                for form in quantised:
                    effects.setdefault((form, width, drop), []).append(
                        quantised[form] - exact[form])
    defaults = np.array(defaults)
    print(f"small satellite, true attitude, noise-free gyro; {seeds} seeds")
    print("steps where the telemetered ρ did not change (x, y, z): "
          + ", ".join(f"{s:.2f}" for s in still))
    print(f"default estimator, median error: quantised {np.median(defaults[:, 0]):.2e}, "
          f"exact {np.median(defaults[:, 1]):.2e}")
    print(f"\n{'form':22s} {'ρ':28s} {'effect, median':>14s} {'mean':>9s} {'spread':>9s}")
    upper = np.triu_indices(3)
    for (form, width, drop), diffs in effects.items():
        diffs = np.array(diffs) / norm
        size = np.linalg.norm(diffs, axis=(1, 2))
        elems = diffs[:, upper[0], upper[1]]
        mean = np.linalg.norm(elems.mean(axis=0))
        spread = np.sqrt(elems.var(axis=0).sum())
        label = (f"without holds ({np.mean(kept):.0%} of rows kept)" if drop
                 else "as telemetered" if width == 1 else f"moving average of {width}")
        print(f"{form:22s} {label:28s} {np.median(size):14.2e} {mean:9.2e} {spread:9.2e}")


if __name__ == "__main__":
    main()
