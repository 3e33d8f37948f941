//! The Monte Carlo matrix's statistics: per-estimator error quantiles, 3σ coverage,
//! and the paired (seed by seed) comparison of two estimators.

use crate::Outcome;
use inertia::estimator::observability::{Observability, Unobservable};
use inertia::tensor::relative_frobenius_error;
use nalgebra::Matrix3;

#[derive(Default, Clone)]
pub(crate) struct Stats {
    pub(crate) errors: Vec<f64>,
    pub(crate) element_within: [usize; 6],
    pub(crate) with_sigma: usize,
    pub(crate) determined: usize,
    pub(crate) determined_outside: usize,
    pub(crate) failed: usize,
    /// `σ_F / ‖Ĵ − J‖_F` of every answer with a σ.
    pub(crate) sigma_ratios: Vec<f64>,
    /// The largest residual variance ratio of a segment to the rest, per run.
    pub(crate) residual_ratios: Vec<f64>,
    /// Runs whose answer was withdrawn for inconsistent residuals.
    pub(crate) inconsistent: usize,
    /// The residual variance over the part the stated gyro density implies, per run.
    pub(crate) density_ratios: Vec<f64>,
}

impl Stats {
    pub(crate) fn record(&mut self, run: Option<&Outcome>, truth: &Matrix3<f64>) {
        self.residual_ratios
            .extend(run.and_then(|r| r.residual_ratio));
        self.density_ratios
            .extend(run.and_then(|r| r.density_ratio));
        let e = run.and_then(|r| r.estimate.as_ref());
        if e.is_some_and(|e| {
            matches!(
                e.observability,
                Observability::NotObservable(
                    Unobservable::Inconsistent { .. } | Unobservable::DensityOverstated { .. }
                )
            )
        }) {
            self.inconsistent += 1;
        }
        let Some((e, j)) = e.and_then(|e| Some((e, e.inertia()?))) else {
            self.failed += 1;
            return;
        };
        self.errors.push(relative_frobenius_error(&j, truth));
        let (Some(sig), Some(jv), Some(u)) = (e.sigma_kg_m2(), e.j(), e.uncertainty) else {
            return;
        };
        self.with_sigma += 1;
        self.sigma_ratios
            .push(u.frobenius_sigma_kg_m2() / (j - truth).norm());
        let t = inertia::tensor::j_from_matrix(truth);
        for k in 0..6 {
            if (jv[k] - t[k]).abs() <= 3.0 * sig[k] {
                self.element_within[k] += 1;
            }
        }
        if matches!(e.observability, Observability::Determined { .. }) {
            self.determined += 1;
            if !((j - truth).norm() <= 3.0 * u.frobenius_sigma_kg_m2()) {
                self.determined_outside += 1;
            }
        }
    }

    pub(crate) fn errors(&self) -> String {
        let digits = if std::env::var("DIGITS").is_ok() {
            3
        } else {
            1
        };
        let mut out = format!(
            "{:.digits$e} / {:.1e}",
            quantile(&self.errors, 0.5),
            quantile(&self.errors, 0.95)
        );
        if self.failed > 0 {
            out += &format!(" ({} no answer)", self.failed);
        }
        out
    }

    pub(crate) fn coverage(&self) -> String {
        if self.with_sigma == 0 {
            return "no σ".into();
        }
        let worst = self.element_within.iter().copied().min().unwrap_or(0);
        format!("{:.2}", worst as f64 / self.with_sigma as f64)
    }

    pub(crate) fn sigma_ratio(&self) -> String {
        if self.sigma_ratios.is_empty() {
            return "no σ".into();
        }
        format!("{:.1}", quantile(&self.sigma_ratios, 0.5))
    }

    pub(crate) fn residual_ratio(&self) -> String {
        if self.residual_ratios.is_empty() {
            return "none".into();
        }
        let max = self.residual_ratios.iter().copied().fold(0.0, f64::max);
        format!(
            "{:.1} / {:.1} ({} withdrawn)",
            quantile(&self.residual_ratios, 0.5),
            max,
            self.inconsistent
        )
    }

    pub(crate) fn density_ratio(&self) -> String {
        if self.density_ratios.is_empty() {
            return "none".into();
        }
        let min = self
            .density_ratios
            .iter()
            .copied()
            .fold(f64::INFINITY, f64::min);
        format!("{:.2} / {:.2}", quantile(&self.density_ratios, 0.5), min)
    }

    pub(crate) fn determined_beyond(&self) -> String {
        if self.determined == 0 {
            return "none determined".into();
        }
        format!(
            "{:.2} of {}",
            self.determined_outside as f64 / self.determined as f64,
            self.determined
        )
    }
}

pub(crate) fn quantile(v: &[f64], q: f64) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    s[((s.len() - 1) as f64 * q).round() as usize]
}

/// The default against the momentum RLS seed by seed, over the seeds where both answer:
/// how often the default's error is the smaller, and the two-sided sign test's p-value
/// for "neither is better" (whether a ratio of medians near 1 says anything).
#[derive(Default)]
pub(crate) struct Paired {
    pub(crate) better: u64,
    pub(crate) both: u64,
}

impl Paired {
    pub(crate) fn record(&mut self, dm: Option<f64>, rls: Option<f64>) {
        if let (Some(a), Some(b)) = (dm, rls) {
            self.both += 1;
            self.better += u64::from(a < b);
        }
    }

    /// `P(|wins − n/2| ≥ |observed − n/2|)` for `n` fair coin flips.
    pub(crate) fn sign_test_p(&self) -> f64 {
        let n = self.both;
        let d = (2.0 * self.better as f64 - n as f64).abs();
        // ln C(n, k) by sums of logs: n is at most a few hundred seeds.
        let ln_choose = |k: u64| -> f64 {
            (1..=k)
                .map(|i| ((n - k + i) as f64).ln() - (i as f64).ln())
                .sum()
        };
        (0..=n)
            .filter(|&k| (2.0 * k as f64 - n as f64).abs() >= d)
            .map(|k| (ln_choose(k) - n as f64 * core::f64::consts::LN_2).exp())
            .sum::<f64>()
            .min(1.0)
    }
}

impl std::fmt::Display for Paired {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.both == 0 {
            return write!(f, "(no pairs)");
        }
        write!(
            f,
            "({}/{}, p {:.2})",
            self.better,
            self.both,
            self.sign_test_p()
        )
    }
}
