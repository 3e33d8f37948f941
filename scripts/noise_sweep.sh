#!/usr/bin/env bash
# The noise sweep (book/src/monte-carlo.md): final error percentiles of every estimator at 1x, 10x,
# 100x and 1000x the paper's gyro noise, both scenarios, 200 seeds each.
# Usage: scripts/noise_sweep.sh [OUT_DIR]   (about a minute on 2 cores)
set -euo pipefail
out="${1:-noise-sweep}"
cargo build --release -q -p inertia-cli
for scenario in slew spin; do
  for gyro in 1e-5 1e-4 1e-3 1e-2; do
    target/release/inertia monte-carlo --scenario "$scenario" --runs 200 \
      --gyro-noise "$gyro" --out "$out/$scenario-$gyro" > /dev/null
    echo "## $scenario, gyro $gyro deg/s/√Hz"
    grep '^|' "$out/$scenario-$gyro/${scenario}_summary.md"
    echo
  done
done
