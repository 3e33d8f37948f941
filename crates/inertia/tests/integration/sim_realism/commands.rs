//! Commands held between controller ticks, the integrator's order with held commands,
//! and decimation of the telemetry.

use super::*;

/// Wheel commands held at 10 Hz with phase 0.05 s: on a 100 Hz node grid ρ is exactly
/// piecewise linear; its slope changes only at the ticks 0.05 + 0.1 j s.
#[test]
fn commands_are_held_between_ticks_at_the_phase_given() {
    for (phase, first) in [(0.05, 5usize), (0.0, 0), (0.03, 3)] {
        let out = Scenario::slew()
            .simulate(&Common {
                dt_s: 0.01,
                substeps: 2,
                duration_s: Some(12.0),
                realism: Realism {
                    commands: Some(CommandHold {
                        rate_hz: 10.0,
                        phase_s: phase,
                    }),
                    ..Realism::default()
                },
                ..Common::noise_free()
            })
            .unwrap();
        let rho: Vec<Vector3<f64>> = out.truth.iter().map(|t| t.state.rho_nms).collect();
        let mut kinks = 0;
        let mut max_off_tick = 0.0f64;
        let mut max_on_tick = 0.0f64;
        for k in 1..rho.len() - 1 {
            // Second difference at node k: zero unless the slope changes at t_k.
            let d2 = (rho[k + 1] - 2.0 * rho[k] + rho[k - 1]).norm();
            if k % 10 == first {
                max_on_tick = max_on_tick.max(d2);
                kinks += usize::from(d2 > 1e-12);
            } else {
                max_off_tick = max_off_tick.max(d2);
            }
        }
        assert!(
            max_off_tick < 1e-15,
            "phase {phase}: slope change off a tick {max_off_tick:e}"
        );
        assert!(kinks > 50, "phase {phase}: only {kinks} command changes");
        assert!(max_on_tick > 1e-9);
    }
}

fn final_state(substeps: usize, law: &dyn InputLaw, hold: Option<CommandHold>) -> GyrostatState {
    let cfg = SimConfig {
        inertia_kg_m2: paper_j_true(),
        initial: GyrostatState {
            q: Quaternion::exp(&Vector3::new(0.3, -0.2, 0.5)),
            omega_rad_s: Vector3::new(0.3, -0.2, 0.4),
            rho_nms: Vector3::new(0.05, -0.1, 0.1),
        },
        t0_s: 0.0,
        dt_s: 0.1,
        samples: 201,
        substeps,
        disturbance_nm_rthz: 0.0,
        gyro_noise_deg_s_rthz: 0.0,
        seed: 0,
        inertia_change: None,
        realism: Realism {
            commands: hold,
            ..Realism::default()
        },
    };
    simulate(&cfg, law, &Zero).unwrap().truth[200].state
}

fn state_error(a: &GyrostatState, b: &GyrostatState) -> f64 {
    (a.omega_rad_s - b.omega_rad_s).norm()
        + (a.rho_nms - b.rho_nms).norm()
        + a.q.conjugate().mul(&b.q).angle()
}

/// The longest substep the simulator uses for `substeps` with ticks at 0.03 + 0.1 j s
/// (pieces of 0.03 s and 0.07 s per 0.1 s interval, each cut into equal substeps).
fn longest_substep(substeps: usize) -> f64 {
    let dt = 0.1 / substeps as f64;
    [0.03f64, 0.07]
        .iter()
        .map(|len| len / (len / dt - 1e-9).ceil())
        .fold(0.0, f64::max)
}

/// Least-squares slope of log e against log h.
fn fitted_order(h: &[f64], e: &[f64]) -> f64 {
    let x: Vec<f64> = h.iter().map(|v| v.ln()).collect();
    let y: Vec<f64> = e.iter().map(|v| v.ln()).collect();
    let n = x.len() as f64;
    let (mx, my) = (x.iter().sum::<f64>() / n, y.iter().sum::<f64>() / n);
    let sxy: f64 = x.iter().zip(&y).map(|(a, b)| (a - mx) * (b - my)).sum();
    let sxx: f64 = x.iter().map(|a| (a - mx) * (a - mx)).sum();
    sxy / sxx
}

/// RK4 with held commands keeps fourth order because the substeps land on the ticks
/// (phase 0.03 s, so every 0.1 s interval is split into 0.03 s and 0.07 s pieces): the
/// fitted order against the longest substep over substeps 1→8 is within 3.5–4.5. The
/// same held law evaluated inside RK4 steps that straddle its jumps converges at first
/// order (checked below 1.5): that is what the split prevents.
#[test]
fn rk4_is_fourth_order_with_held_commands() {
    let hold = Some(CommandHold {
        rate_hz: 10.0,
        phase_s: 0.03,
    });
    let reference = final_state(64, &Smooth, hold);
    let subs = [1usize, 2, 4, 8];
    let h: Vec<f64> = subs.iter().map(|&s| longest_substep(s)).collect();
    let errs: Vec<f64> = subs
        .iter()
        .map(|&s| state_error(&final_state(s, &Smooth, hold), &reference))
        .collect();
    let order = fitted_order(&h, &errs);
    eprintln!("held commands: longest substeps {h:?}, errors {errs:?}, order {order:.2}");
    assert!(
        (3.5..4.5).contains(&order),
        "held: errors {errs:?}, order {order}"
    );
    // Contrast: the staircase inside the law, no hold (same trajectory in the limit).
    let h: Vec<f64> = subs.iter().map(|&s| 0.1 / s as f64).collect();
    let straddle: Vec<f64> = subs
        .iter()
        .map(|&s| state_error(&final_state(s, &Staircase, None), &reference))
        .collect();
    let order = fitted_order(&h, &straddle);
    eprintln!("straddled steps: errors {straddle:?}, order {order:.2}");
    assert!(order < 1.5, "straddled: errors {straddle:?}, order {order}");
}

/// Decimation: every 10th node of the undecimated run, bit for bit for the truth and the
/// gyro-propagated attitude, with disturbance and gyro noise on; the decimated rate is the
/// mean of the ten rates it covers.
#[test]
fn decimation_keeps_every_nth_node() {
    let common = |every: usize, phase: f64| Common {
        duration_s: Some(30.0),
        realism: Realism {
            telemetry_every: every,
            commands: Some(CommandHold {
                rate_hz: 10.0,
                phase_s: phase,
            }),
            ..Realism::default()
        },
        seed: 9,
        ..Common::paper()
    };
    // 1 Hz and 0.2 Hz telemetry from 10 Hz nodes.
    for (phase, n) in [(0.0, 10), (0.05, 10), (0.0, 50), (0.05, 50)] {
        let fine = Scenario::slew().simulate(&common(1, phase)).unwrap();
        let coarse = Scenario::slew().simulate(&common(n, phase)).unwrap();
        assert_eq!(fine.samples.len(), 301);
        assert_eq!(coarse.samples.len(), 300 / n + 1);
        for (i, c) in coarse.samples.iter().enumerate() {
            let f = &fine.samples[n * i];
            assert_eq!(coarse.truth[i], fine.truth[n * i]);
            assert_eq!(c.t_s, f.t_s);
            assert_eq!(c.q, f.q);
            assert_eq!(c.rho_nms, f.rho_nms);
            if n * i + n <= fine.samples.len() {
                let mean: Vector3<f64> = fine.samples[n * i..n * i + n]
                    .iter()
                    .filter_map(|s| s.omega_rad_s)
                    .sum::<Vector3<f64>>()
                    / n as f64;
                let w = c.omega_rad_s.unwrap();
                assert!(
                    (w - mean).norm() < 1e-15 * (1.0 + mean.norm()),
                    "{w} vs {mean}"
                );
            }
        }
    }
}
