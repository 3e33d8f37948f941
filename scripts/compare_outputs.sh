#!/usr/bin/env bash
# Bit-for-bit guard for refactors: run two builds of the CLI over the same simulated files
# and option sets and compare every printed byte (text reports, JSON, history files).
#
#   scripts/compare_outputs.sh OLD_INERTIA NEW_INERTIA [WORKDIR]
#
# NEW_SED: a sed script applied to the new build's printed output before the comparison,
# for a deliberate additive change (e.g. NEW_SED='s/"damping":false,//g' for a JSON key
# the old build did not print).
#
# Exit 0 and "IDENTICAL" when every output matches. Wall-clock lines are not printed by
# `estimate`, so nothing is filtered. Takes a few minutes with release builds.
set -euo pipefail
old=$1 new=$2 work=${3:-$(mktemp -d)}
mkdir -p "$work/data" "$work/old" "$work/new"
d=$work/data

# Data: the paper's scenarios, the flight-like presets, the lab throw, a gyro-only file and
# a spacecraft file with per-wheel speeds (written by the OLD build; both read the same).
"$old" simulate --scenario slew --duration 120 --output "$d/slew.csv" >/dev/null 2>&1
"$old" simulate --scenario spin --output "$d/spin.csv" >/dev/null 2>&1
"$old" simulate --preset small-sat --duration 200 --seed 3 --output "$d/sat.csv" >/dev/null 2>&1
"$old" simulate --preset microsat --duration 200 --seed 4 --output "$d/micro.csv" >/dev/null 2>&1
"$old" simulate --preset throw --seed 2 --output "$d/throw.csv" >/dev/null 2>&1
# Without its quaternion columns: the attitude is integrated from the gyro.
cut -d, -f1,6- "$d/slew.csv" >"$d/gyro_only.csv"
# Four wheels with spin inertia and tilt σ: the consider term re-runs the estimator.
cat >"$d/sc.toml" <<'EOF'
rotor_errors = "independent"
[[rotor]]
name = "w1"
axis = [0.8164965809277261, 0.0, 0.5773502691896258]
spin_inertia_kg_m2 = 0.01
spin_inertia_sigma_kg_m2 = 0.0001
spin_axis_sigma_deg = 0.2
speed_column = "w1"
[[rotor]]
name = "w2"
axis = [-0.8164965809277261, 0.0, 0.5773502691896258]
spin_inertia_kg_m2 = 0.01
spin_inertia_sigma_kg_m2 = 0.0001
speed_column = "w2"
[[rotor]]
name = "w3"
axis = [0.0, 0.8164965809277261, 0.5773502691896258]
spin_inertia_kg_m2 = 0.01
spin_inertia_sigma_kg_m2 = 0.0001
speed_column = "w3"
[[rotor]]
name = "w4"
axis = [0.0, -0.8164965809277261, 0.5773502691896258]
spin_inertia_kg_m2 = 0.01
speed_column = "w4"
EOF
"$old" simulate --scenario slew --duration 60 --spacecraft "$d/sc.toml" --output "$d/wheels.csv" >/dev/null 2>&1

opts=(
  ""
  "--json"
  "--batch"
  "--batch --json"
  "--estimator variational"
  "--estimator variational --batch --json"
  "--estimator finite-difference --json"
  "--estimator momentum --json"
  "--estimator equation-error --json"
  "--inertial-torque auto --json"
  "--no-torque-bias --rho-model held"
  "--rotation-source gyro --json"
  "--memory 60 --every 5"
  "--prior-sigma 10% --json"
  "--rotor-scale-sigma 2% --json"
  "--wheel-delay estimate --json"
  "--constraints physical --diagonal"
)
n=0 rc=0
for f in slew spin sat micro throw gyro_only wheels; do
  sc=""; [ $f = wheels ] && sc="--spacecraft $d/sc.toml"
  for o in "${opts[@]}"; do
    n=$((n + 1))
    for b in old new; do
      exe=$old; [ $b = new ] && exe=$new
      # shellcheck disable=SC2086
      "$exe" estimate "$d/$f.csv" $sc $o -o "$work/$b/$n.history.csv" >"$work/$b/$n.out" 2>"$work/$b/$n.err" || echo "exit $?" >>"$work/$b/$n.err"
    done
    echo "$f $o" >"$work/old/$n.case"
    cp "$work/old/$n.case" "$work/new/$n.case"
  done
done
# Stdout and stderr name the run's own files; both builds wrote under $work/{old,new}.
for b in old new; do sed -i "s#$work/$b#WORK#g" "$work/$b/"*.err "$work/$b/"*.out; done
if [ -n "${NEW_SED:-}" ]; then sed -i "$NEW_SED" "$work/new/"*.out; fi
diff -r "$work/old" "$work/new" >"$work/diff.txt" || rc=1
echo "cases: $n, files compared: $(find "$work/old" -type f | wc -l)"
if [ $rc = 0 ]; then echo IDENTICAL; else echo "DIFFERENT (see $work/diff.txt)"; head -40 "$work/diff.txt"; fi
exit $rc
