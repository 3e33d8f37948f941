//! Issue 11, numeric side: the supported range of telemetry values, and numerical
//! soundness inside it (no panic, no hang, no NaN), with the fuzzer's findings as
//! regressions.

use inertia::estimator::excitation::diagnose;
use inertia::estimator::observability::ObservabilitySettings;
use inertia::estimator::qr::RecursiveQr;
use inertia::pipeline::registry::ESTIMATORS;
use inertia::pipeline::{self, Pipeline, PipelineError, PipelineSettings, MAX_RESAMPLE_FACTOR};
use inertia::sample::{check_range, range, Quantity, Sample};
use inertia::sim::scenario::{Common, Scenario};
use nalgebra::{Vector3, Vector6};

/// Sets one value of a sample.
type Edit = fn(&mut Sample, f64);

fn slew(duration_s: f64) -> Vec<Sample> {
    Scenario::slew()
        .simulate(&Common {
            duration_s: Some(duration_s),
            ..Common::paper()
        })
        .unwrap()
        .samples
}

fn settings(estimator: &str) -> PipelineSettings {
    PipelineSettings {
        estimator: estimator.into(),
        ..PipelineSettings::default()
    }
}

/// Every value just outside its limit is refused, naming the quantity; at the limit it
/// is accepted. NaN is never in range.
#[test]
fn range_check_names_the_quantity() {
    let s = slew(1.0)[3];
    assert!(check_range(&s).is_ok());
    let cases: [(Quantity, Edit); 4] = [
        (Quantity::Time, |s, v| s.t_s = v),
        (Quantity::Rho(2), |s, v| s.rho_nms.z = v),
        (Quantity::Tau(0), |s, v| s.tau_nm.x = v),
        (Quantity::Rate(1), |s, v| {
            s.omega_rad_s = Some(Vector3::new(0.0, v, 0.0))
        }),
    ];
    for (q, set) in cases {
        let limit = q.limit().0;
        for (v, ok) in [
            (limit, true),
            (-limit, true),
            (limit * 1.000_001, false),
            (f64::NAN, false),
        ] {
            let mut x = s;
            set(&mut x, v);
            match check_range(&x) {
                Ok(()) => assert!(ok, "{q:?} = {v} accepted"),
                Err(e) => {
                    assert!(!ok, "{q:?} = {v} refused: {e}");
                    assert_eq!(e.quantity, q);
                    assert!(e.to_string().contains(q.column()), "{e}");
                }
            }
        }
    }
    assert_eq!(range::RHO_NMS, 1e6);
}

/// The pipeline refuses a sample outside the range, recursive and batch, naming it
/// (library users bypass the CSV reader's check).
#[test]
fn pipeline_refuses_out_of_range_samples() {
    let mut samples = slew(3.0);
    samples[7].rho_nms.z = 1e15;
    let config = settings("variational").validate().unwrap();
    let mut p = Pipeline::from_config(config).unwrap();
    let err = samples.iter().find_map(|s| p.push(s).err()).unwrap();
    assert!(
        matches!(err, PipelineError::OutOfRange { sample: 7, .. }),
        "{err}"
    );
    let err = pipeline::batch(&samples, &config).unwrap_err();
    assert!(
        matches!(err, PipelineError::OutOfRange { sample: 7, .. }),
        "{err}"
    );
}

/// Values at the limits on a few rows: every estimator, recursive and batch, returns
/// finite answers and σ, or no answer; never NaN.
#[test]
fn values_at_the_limits_give_finite_answers() {
    let clean = slew(20.0);
    let edits: [fn(&mut Sample); 4] = [
        |s| s.rho_nms.x = range::RHO_NMS,
        |s| s.rho_nms.z = -range::RHO_NMS,
        |s| s.tau_nm.x = range::TAU_NM,
        |s| s.omega_rad_s = Some(Vector3::repeat(range::RATE_RAD_S)),
    ];
    for edit in edits {
        let mut samples = clean.clone();
        for s in &mut samples[49..52] {
            edit(s);
        }
        for entry in ESTIMATORS {
            let config = settings(entry.name).validate().unwrap();
            let mut estimates = Vec::new();
            let mut p = Pipeline::from_config(config).unwrap();
            for s in &samples {
                if let Ok(Some(e)) = p.push(s) {
                    estimates.push(e);
                }
            }
            // Estimators without a batch form refuse it (typed).
            if let Ok(out) = pipeline::batch(&samples, &config) {
                estimates.push(out.estimate);
            }
            for e in estimates {
                let j = e.j().map(|j| j.as_slice().to_vec()).unwrap_or_default();
                let sigma = e.sigma_kg_m2().unwrap_or_default();
                assert!(
                    j.iter().chain(&sigma).all(|v| v.is_finite()),
                    "{}: J {j:?}, σ {sigma:?}",
                    entry.name
                );
            }
        }
    }
}

/// Fuzz finding: a step of 1e-9 s then a gap leaves fewer than six rows for the batch
/// QR, which indexed past them (panic). Now: no answer, no panic.
#[test]
fn batch_with_fewer_than_six_rows() {
    let mut samples = slew(1.0)[..4].to_vec();
    samples[1].t_s = 1e-9;
    for name in ["variational", "finite-difference"] {
        let config = settings(name).validate().unwrap();
        if let Ok(out) = pipeline::batch(&samples, &config) {
            assert!(out
                .estimate
                .j()
                .is_none_or(|j| j.iter().all(|v| v.is_finite())));
        }
    }
}

/// Fuzz finding (hang): a step of 1e9 s with `resample_s` made 2e10 samples. A step
/// that is not a gap and would make more than `MAX_RESAMPLE_FACTOR` samples is refused.
#[test]
fn resampling_a_huge_step_is_refused() {
    let mut samples = slew(2.0);
    for s in &mut samples[5..] {
        s.t_s += 1e9;
    }
    // Not a gap only as the first step; make every step as long.
    let mut first = samples[..3].to_vec();
    first[1].t_s = 1e9;
    first[2].t_s = 2e9;
    let p = PipelineSettings {
        resample_s: Some(0.1),
        ..settings("variational")
    };
    let mut pipe = Pipeline::new(&p).unwrap();
    let err = first.iter().find_map(|s| pipe.push(s).err()).unwrap();
    assert!(
        matches!(err, PipelineError::ResampleTooFine { sample: 1, .. }),
        "{err}"
    );
    assert!(
        err.to_string()
            .contains(&format!("at most {MAX_RESAMPLE_FACTOR}")),
        "{err}"
    );
    // After a gap, the grid restarts: accepted.
    let mut pipe = Pipeline::new(&p).unwrap();
    for s in &samples {
        pipe.push(s).unwrap();
    }
    // Fuzz finding (hang): a gap, then a huge step. The resampler restarted at the gap
    // has no previous step to call the next one a gap against: refused.
    let mut after_gap = slew(2.0);
    for s in &mut after_gap[5..] {
        s.t_s += 3.0;
    }
    for s in &mut after_gap[6..] {
        s.t_s += 1e9;
    }
    let mut pipe = Pipeline::new(&p).unwrap();
    let err = after_gap.iter().find_map(|s| pipe.push(s).err()).unwrap();
    assert!(
        matches!(err, PipelineError::ResampleTooFine { sample: 6, .. }),
        "{err}"
    );
}

/// The excitation diagnosis decomposes R with a bounded SVD: non-finite or wildly scaled
/// rows return (an unbounded SVD looped forever on them).
#[test]
fn excitation_diagnosis_returns_on_non_finite_rows() {
    for bad in [f64::NAN, f64::INFINITY, 1e308] {
        let mut qr = RecursiveQr::new();
        for i in 0..12 {
            let h = Vector6::from_fn(|k, _| ((i * 7 + k * 3) % 5) as f64 - 2.0);
            qr.add_row(&h, 1.0);
        }
        qr.add_row(&Vector6::repeat(bad), bad);
        let x = diagnose(&qr, &ObservabilitySettings::default());
        assert_eq!(x.singular_values.len(), 6);
    }
}
