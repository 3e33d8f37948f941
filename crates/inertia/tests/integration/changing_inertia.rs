//! Inertia that changes during a run: exponential forgetting tracks it (issue: fuel use,
//! deployments, docking).

use inertia::constraints::ConstraintSet;
use inertia::estimator::recursive::{RecursiveEstimator, RecursiveSettings};
use inertia::estimator::rows::VariationalRows;
use inertia::sim::scenario::{Common, Scenario, SlewPlan};
use inertia::sim::{InertiaChange, SimOutput};
use inertia::solver::native::NativeSolver;
use inertia::tensor::relative_frobenius_error;

/// The paper's six slews, repeated every 300 s, for 600 s.
fn long_slew() -> Scenario {
    Scenario::Slew(SlewPlan::default().repeated(2))
}

fn simulate(change: Option<InertiaChange>) -> SimOutput {
    long_slew()
        .simulate(&Common {
            inertia_change: change,
            ..Common::paper()
        })
        .unwrap()
}

/// Error history (t, error against the true J at t) with forgetting time constant `tau_s`
/// (`None`: no forgetting).
fn errors(out: &SimOutput, tau_s: Option<f64>) -> Vec<(f64, f64)> {
    let settings = RecursiveSettings {
        memory_s: tau_s,
        ..RecursiveSettings::default()
    };
    let mut e = RecursiveEstimator::new(
        VariationalRows::default(),
        ConstraintSet::paper().validate().unwrap(),
        NativeSolver::default(),
        settings,
    )
    .unwrap();
    out.samples
        .iter()
        .filter_map(|s| e.push(s).unwrap())
        .map(|est| {
            let err = est.inertia().map_or(f64::INFINITY, |j| {
                relative_frobenius_error(&j, &out.inertia_at(est.t_s))
            });
            (est.t_s, err)
        })
        .collect()
}

fn at(errs: &[(f64, f64)], t: f64) -> f64 {
    errs.iter()
        .find(|(tt, _)| (tt - t).abs() < 1e-6)
        .map_or(f64::NAN, |e| e.1)
}

#[test]
fn forgetting_tracks_a_ten_percent_step_change() {
    let j0 = inertia::tensor::paper_j_true();
    let step = InertiaChange::Step {
        at_s: 300.0,
        to_kg_m2: j0 * 1.1,
    };
    let out = simulate(Some(step));
    // The simulator conserves angular momentum across the step and uses the new J after.
    assert_eq!(out.inertia_at(299.9), j0);
    assert_eq!(out.inertia_at(300.0), j0 * 1.1);
    let mut table = Vec::new();
    for tau in [Some(15.0), Some(30.0), Some(60.0), Some(120.0), None] {
        let e = errors(&out, tau);
        let converged = settle_time(&e, 300.0, 1e-2);
        eprintln!(
            "tau {tau:?}: error before the step (290 s) {:.2e}, after (600 s) {:.2e}, within 1e-2 from {converged:?} s after the step",
            at(&e, 290.0),
            at(&e, 600.0),
        );
        table.push((tau, at(&e, 290.0), at(&e, 600.0), converged));
    }
    // With a 30 s memory: within 1e-2 of the new J (and staying there) within 120 s of the
    // step, 1e-3 at the end; the price is a noisier steady state than without forgetting.
    let (_, before30, end30, settle30) = table[1];
    assert!(settle30.is_some_and(|t| t < 120.0), "{settle30:?}");
    assert!(end30 < 1e-3 && before30 < 1e-3, "{before30:e} {end30:e}");
    // Without forgetting the estimate stays a blend of old and new J.
    let (_, before_inf, end_inf, settle_inf) = table[4];
    assert!(settle_inf.is_none() && end_inf > 3e-2, "{end_inf:e}");
    // The trade-off: shorter memory, noisier steady state.
    assert!(table[0].1 > table[1].1 && table[1].1 > table[2].1 && before_inf < table[2].1);
}

/// Time after `t0` from which every error stays below `tol`.
fn settle_time(e: &[(f64, f64)], t0: f64, tol: f64) -> Option<f64> {
    let last_bad = e
        .iter()
        .rev()
        .find(|(t, x)| *t > t0 && !(*x < tol))
        .map(|(t, _)| *t);
    match last_bad {
        None => Some(0.0),
        Some(t) if t < e.last()?.0 => Some(t - t0),
        Some(_) => None,
    }
}

/// A 10 % ramp over 60 s (fuel use): the simulator's J follows it, and forgetting tracks.
#[test]
fn forgetting_tracks_a_ramp() {
    let j0 = inertia::tensor::paper_j_true();
    let ramp = InertiaChange::Ramp {
        start_s: 300.0,
        end_s: 360.0,
        to_kg_m2: j0 * 0.9,
    };
    let out = simulate(Some(ramp));
    assert!((out.inertia_at(330.0) - j0 * 0.95).norm() < 1e-12);
    let e = errors(&out, Some(30.0));
    let settle = settle_time(&e, 360.0, 1e-2);
    assert!(settle.is_some_and(|t| t < 120.0), "{settle:?}");
    let none = errors(&out, None);
    assert!(at(&none, 600.0) > 3e-2, "{:e}", at(&none, 600.0));
}
