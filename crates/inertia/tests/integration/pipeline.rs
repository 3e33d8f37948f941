//! The library pipeline: memory in seconds (resampling, jitter, gaps), every registered
//! estimator through one API, and constructors that reject bad input with typed errors.

use inertia::constraints::ConstraintSet;
use inertia::discrete::RowError;
use inertia::estimator::momentum::{MomentumRls, MomentumSettings};
use inertia::estimator::resample::Resampler;
use inertia::estimator::{Estimate, EstimatorError};
use inertia::pipeline::registry::ESTIMATORS;
use inertia::pipeline::{self, Pipeline, PipelineError, PipelineSettings};
use inertia::sample::Sample;
use inertia::sim::scenario::{Common, Scenario};
use inertia::sim::{InertiaChange, SimOutput};
use inertia::solver::native::{NativeSettings, NativeSolver};
use inertia::tensor::{matrix_from_j, relative_frobenius_error, Component};
use nalgebra::{Matrix3, Vector3};

/// The paper's slew at step `dt_s` with J stepping by +10 % at 150 s.
fn stepped_slew(dt_s: f64) -> SimOutput {
    let j0 = Scenario::slew()
        .simulate(&Common::noise_free())
        .unwrap()
        .inertia_kg_m2;
    Scenario::slew()
        .simulate(&Common {
            dt_s,
            inertia_change: Some(InertiaChange::Step {
                at_s: 150.0,
                to_kg_m2: j0 * 1.1,
            }),
            ..Common::paper()
        })
        .unwrap()
}

fn run(samples: &[Sample], settings: &PipelineSettings) -> Vec<Estimate> {
    let mut p = Pipeline::new(settings).unwrap();
    let mut out = Vec::new();
    for s in samples {
        p.push_each(s, |e| out.push(*e)).unwrap();
    }
    out
}

/// Error of the estimate nearest `t_s` against the true J at that time.
fn error_at(history: &[Estimate], out: &SimOutput, t_s: f64) -> f64 {
    let e = history
        .iter()
        .min_by(|a, b| (a.t_s - t_s).abs().total_cmp(&(b.t_s - t_s).abs()))
        .unwrap();
    assert!((e.t_s - t_s).abs() < 0.2, "no estimate near {t_s}");
    relative_frobenius_error(&e.inertia().expect("an answer"), &out.inertia_at(t_s))
}

fn with_memory(memory_s: f64, resample_s: Option<f64>) -> PipelineSettings {
    PipelineSettings {
        memory_s: Some(memory_s),
        resample_s,
        uncertainty: false,
        ..PipelineSettings::default()
    }
}

/// Memory is a time constant in seconds: a 30 s memory tracks a +10 % step in J the same
/// way on the raw 10 Hz telemetry, resampled to 20 Hz, and on a ±20 % jittered grid.
#[test]
fn memory_in_seconds_is_independent_of_the_sampling() {
    let raw = stepped_slew(0.1);
    let base = error_at(&run(&raw.samples, &with_memory(30.0, None)), &raw, 220.0);
    let resampled = error_at(
        &run(&raw.samples, &with_memory(30.0, Some(0.05))),
        &raw,
        220.0,
    );
    // Jitter: the same run simulated at 0.02 s, kept at steps of 4, 5 or 6 fine steps.
    let fine = stepped_slew(0.02);
    let mut jittered = Vec::new();
    let (mut k, mut state) = (0usize, 12345u64);
    while k < fine.samples.len() {
        jittered.push(fine.samples[k]);
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        k += 4 + (state >> 33) as usize % 3;
    }
    let jitter = error_at(&run(&jittered, &with_memory(30.0, None)), &fine, 220.0);
    eprintln!("error at 220 s: raw {base:.3e}, resampled {resampled:.3e}, jittered {jitter:.3e}");
    for (what, e) in [("resampled", resampled), ("jittered", jitter)] {
        assert!(
            (e / base - 1.0).abs() < 0.2,
            "{what}: {e:e} against {base:e} on the raw grid"
        );
    }
    // And the memory does its job: once the slews after the step have excited every
    // axis it has forgotten the old J; without it the estimate is a blend of both.
    let late = error_at(&run(&raw.samples, &with_memory(30.0, None)), &raw, 290.0);
    let none = error_at(
        &run(
            &raw.samples,
            &PipelineSettings {
                uncertainty: false,
                ..PipelineSettings::default()
            },
        ),
        &raw,
        290.0,
    );
    assert!(
        late < 0.5 * none,
        "at 290 s: memory {late:e}, none {none:e}"
    );
}

/// Across a gap of an hour, a 30 s memory forgets everything before it: the estimate
/// after the gap equals the one from the data after the gap alone.
#[test]
fn memory_decays_across_a_gap() {
    let out = Scenario::slew().simulate(&Common::paper()).unwrap();
    let (before, after) = out.samples.split_at(1200);
    let mut gapped: Vec<Sample> = before.to_vec();
    gapped.extend(after.iter().map(|s| Sample {
        t_s: s.t_s + 3600.0,
        ..*s
    }));
    let settings = with_memory(30.0, None);
    let whole = run(&gapped, &settings);
    let alone = run(after, &settings);
    let (a, b) = (whole.last().unwrap(), alone.last().unwrap());
    let (ja, jb) = (a.j().unwrap(), b.j().unwrap());
    assert!(
        (ja - jb).norm() <= 1e-9 * jb.norm(),
        "with the old data {ja:?}, without {jb:?}"
    );
    let mut p = Pipeline::new(&settings).unwrap();
    for s in &gapped {
        p.push(s).unwrap();
    }
    assert_eq!(p.diagnostics().gaps, 1);
}

/// Every registered estimator runs through the same API and returns the same type, and
/// the batch form agrees with the recursive one where both exist.
#[test]
fn every_registered_estimator_runs_through_the_pipeline() {
    let out = Scenario::slew().simulate(&Common::paper()).unwrap();
    for entry in ESTIMATORS {
        let settings = PipelineSettings {
            estimator: entry.name.into(),
            ..PipelineSettings::default()
        };
        let history = run(&out.samples, &settings);
        let last = history.last().expect("estimates");
        let err = relative_frobenius_error(&last.inertia().unwrap(), &out.inertia_kg_m2);
        assert!(err < 2e-4, "{}: {err:e}", entry.name);
        assert_eq!(last.uncertainty.is_some(), entry.capabilities.uncertainty);
        if entry.has_batch() {
            let config = PipelineSettings {
                uncertainty: false,
                ..settings
            }
            .validate()
            .unwrap();
            let b = pipeline::batch(&out.samples, &config).unwrap();
            let jb = b.estimate.j().unwrap();
            let jr = last.j().unwrap();
            assert!((jb - jr).norm() < 1e-7 * jr.norm(), "{}", entry.name);
            assert!(b.diagnostics.excitation.is_some());
        }
    }
}

#[test]
fn settings_are_validated_with_typed_errors() {
    let v = |s: PipelineSettings| s.validate().map(drop).unwrap_err();
    let d = PipelineSettings::default;
    assert!(matches!(
        v(PipelineSettings {
            estimator: "kalman".into(),
            ..d()
        }),
        PipelineError::UnknownEstimator { .. }
    ));
    assert!(matches!(
        v(PipelineSettings {
            solver: "mosek".into(),
            ..d()
        }),
        PipelineError::UnknownSolver { .. }
    ));
    #[cfg(not(feature = "clarabel"))]
    assert!(matches!(
        v(PipelineSettings {
            solver: "clarabel".into(),
            ..d()
        }),
        PipelineError::SolverUnavailable { .. }
    ));
    for (field, s) in [
        (
            "solve_every",
            PipelineSettings {
                solve_every: 0,
                ..d()
            },
        ),
        (
            "memory_s",
            PipelineSettings {
                memory_s: Some(0.0),
                ..d()
            },
        ),
        (
            "memory_s",
            PipelineSettings {
                memory_s: Some(f64::NAN),
                ..d()
            },
        ),
        (
            "resample_s",
            PipelineSettings {
                resample_s: Some(-1.0),
                ..d()
            },
        ),
        (
            "gyro_noise_deg_s_rthz",
            PipelineSettings {
                gyro_noise_deg_s_rthz: Some(f64::INFINITY),
                ..d()
            },
        ),
    ] {
        match v(s) {
            PipelineError::InvalidSetting { field: f, .. } => assert_eq!(f, field),
            other => panic!("{field}: {other}"),
        }
    }
    // Options an estimator would ignore are refused, not ignored.
    let momentum = |s: PipelineSettings| PipelineSettings {
        estimator: "momentum".into(),
        ..s
    };
    assert!(matches!(
        v(momentum(PipelineSettings {
            gyro_noise_deg_s_rthz: Some(1e-5),
            ..d()
        })),
        PipelineError::NotApplicable {
            setting: "gyro_noise_deg_s_rthz",
            ..
        }
    ));
    assert!(matches!(
        v(momentum(PipelineSettings {
            constraints: ConstraintSet::paper(),
            ..d()
        })),
        PipelineError::NotApplicable {
            setting: "constraints",
            ..
        }
    ));
    assert!(matches!(
        v(PipelineSettings {
            constraints: ConstraintSet::physical().with_bounds(
                Component::J11,
                Some(2.0),
                Some(1.0)
            ),
            ..d()
        }),
        PipelineError::Constraints(_)
    ));
    // Batch refuses memory and resampling.
    let c = PipelineSettings {
        memory_s: Some(10.0),
        ..d()
    }
    .validate()
    .unwrap();
    assert!(matches!(
        pipeline::batch(&[], &c),
        Err(PipelineError::NotApplicable {
            setting: "memory_s",
            ..
        })
    ));
}

#[test]
fn constructors_reject_bad_input() {
    for h in [0.0, -0.1, f64::NAN, f64::INFINITY] {
        assert_eq!(Resampler::new(h).unwrap_err().name, "h_s");
    }
    for p0 in [0.0, -1.0, f64::NAN] {
        let e = MomentumRls::new(MomentumSettings {
            p0,
            ..MomentumSettings::default()
        });
        assert_eq!(e.unwrap_err().name, "p0");
    }
    let e = MomentumRls::new(MomentumSettings {
        memory_s: Some(0.0),
        ..MomentumSettings::default()
    });
    assert_eq!(e.unwrap_err().name, "memory_s");
    let mut bad = NativeSettings::default();
    bad.barrier.gap_tolerance = -1.0;
    assert!(NativeSolver::new(bad).is_err());
    use inertia::attitude::Quaternion;
    use inertia::sim::control::{Slew, SlewController};
    let slew = |start_s, duration_s, axis| Slew {
        axis,
        angle_rad: 1.0,
        start_s,
        duration_s,
    };
    let x = Vector3::x();
    for (what, slews, wn) in [
        ("frequency", vec![slew(0.0, 10.0, x)], 0.0),
        ("duration", vec![slew(0.0, 0.0, x)], 0.5),
        ("overlap", vec![slew(0.0, 10.0, x), slew(5.0, 10.0, x)], 0.5),
        ("axis", vec![slew(0.0, 10.0, Vector3::zeros())], 0.5),
    ] {
        assert!(
            SlewController::new(Matrix3::identity(), Quaternion::IDENTITY, slews, wn, 0.7).is_err(),
            "{what}"
        );
    }
    // The momentum RLS without gyro rates: a typed error, not NaN.
    let mut s = Scenario::slew().simulate(&Common::paper()).unwrap().samples[0];
    s.omega_rad_s = None;
    let err = MomentumRls::default().push(&s).unwrap_err();
    assert!(
        matches!(
            err,
            EstimatorError::Row {
                source: RowError::MissingGyroRate,
                ..
            }
        ),
        "{err}"
    );
}

/// `docs/conventions.md` §6: the products of inertia are tensor entries, `J12 = −Σ m x y`
/// (so that `H = J ω`), the opposite sign of a CAD tool's product of inertia.
#[test]
fn products_of_inertia_are_tensor_entries() {
    // Point masses: J = Σ m (|r|² I − r rᵀ).
    let masses = [
        (2.0, Vector3::new(1.0, 1.0, 0.0)),
        (1.0, Vector3::new(0.5, -0.2, 0.3)),
    ];
    let j: Matrix3<f64> = masses
        .iter()
        .map(|(m, r)| (Matrix3::identity() * r.norm_squared() - r * r.transpose()) * *m)
        .sum();
    let pxy: f64 = masses.iter().map(|(m, r)| m * r.x * r.y).sum();
    assert!((j[(0, 1)] + pxy).abs() < 1e-15);
    let jv = inertia::tensor::j_from_matrix(&j);
    assert_eq!(jv[Component::J12.index()], j[(0, 1)]);
    assert_eq!(matrix_from_j(&jv), j);
    // The angular momentum of a rigid body spinning about z: H = J ω, also from Σ m r × (ω × r).
    let w = Vector3::new(0.0, 0.0, 1.0);
    let h: Vector3<f64> = masses.iter().map(|(m, r)| r.cross(&w.cross(r)) * *m).sum();
    assert!((j * w - h).norm() < 1e-14);
}

mod status;

#[test]
fn batch_and_recursive_runs_report_the_same_torque_test() {
    // The discrete momentum estimator on the paper's slew, without a random disturbance (no
    // torque: held at zero) and with 1e-5 N m hidden from the telemetry (kept): the
    // recursive pipeline and the batch run make the same decision, with χ² within 1e-3,
    // and both reports carry it (JSON `torque_test`). The paper's estimator makes no test.
    for torque in [0.0, 1e-5] {
        let mut common = Common {
            disturbance_nm_rthz: 0.0,
            ..Common::paper()
        };
        common.realism.environment.constant_torque_nm = Vector3::new(torque, 0.0, 0.0);
        let out = Scenario::slew().simulate(&common).unwrap();
        let settings = PipelineSettings {
            estimator: "discrete-momentum".into(),
            ..PipelineSettings::default()
        };
        let mut p = Pipeline::new(&settings).unwrap();
        for s in &out.samples {
            p.push(s).unwrap();
        }
        let recursive = p.diagnostics().torque_test.expect("tested");
        let config = settings.validate().unwrap();
        let b = pipeline::batch(&out.samples, &config).unwrap();
        let batch = b.diagnostics.torque_test.expect("tested");
        assert_eq!(
            recursive.held_at_zero,
            torque == 0.0,
            "{torque}: {recursive:?}"
        );
        assert_eq!(batch.held_at_zero, recursive.held_at_zero, "{torque}");
        assert!(
            (batch.chi2 - recursive.chi2).abs() <= 1e-3 * recursive.chi2,
            "{torque}: {batch:?} against {recursive:?}"
        );
        #[cfg(feature = "serde")]
        {
            let report =
                inertia::pipeline::report::Report::of_batch(&b, &config, out.samples.len());
            assert_eq!(report.torque_test, Some(batch));
            let text = report.to_string();
            assert_eq!(text.contains("held at zero"), torque == 0.0, "{text}");
        }
    }
    let paper = PipelineSettings {
        estimator: "variational".into(),
        ..PipelineSettings::default()
    };
    let out = Scenario::slew().simulate(&Common::paper()).unwrap();
    let b = pipeline::batch(&out.samples, &paper.validate().unwrap()).unwrap();
    assert!(b.diagnostics.torque_test.is_none());
}
