//! Samples from arrays (or a DataFrame's columns), checked as the CSV reader checks a
//! file's rows (`inertia::telemetry::csv`): finite values in the supported range, the
//! quaternion convention applied, quaternions within the unit tolerance renormalised
//! (and counted), sign flips counted, time increasing, and the period uniform in strict
//! mode. Messages have the reader's wording with the row (0-based) and the argument or
//! column in place of the file's line and column.

use crate::settings::Convention;
use inertia::attitude::Quaternion;
use inertia::sample::{check_value, Quantity, Sample};
use inertia::telemetry::csv::QuaternionFormat;
use inertia::text::Num;
use nalgebra::Vector3;

/// One row of raw values, in storage order.
#[derive(Debug, Clone, Copy)]
pub struct Row {
    pub t: f64,
    pub q: [f64; 4],
    pub rho: [f64; 3],
    pub tau: Option<[f64; 3]>,
    pub w: Option<[f64; 3]>,
}

/// How values are named in messages.
#[derive(Debug, Clone)]
pub enum Naming {
    /// Arguments `t`, `q`, `rho`, `tau`, `w`: `q[12, 3]`.
    Arrays,
    /// A table's columns, in the order t, q (4), rho, tau, w (3 each): `row 12: column `q_w``.
    Frame(Vec<String>),
}

/// Argument names and the offset of their first column in [`Naming::Frame`].
const GROUPS: [(&str, usize); 5] = [("t", 0), ("q", 1), ("rho", 5), ("tau", 8), ("w", 11)];

impl Naming {
    /// Where a value is: group `g` (index into [`GROUPS`]), component `k`, row `i`.
    pub fn value(&self, g: usize, k: Option<usize>, i: usize) -> String {
        let (arg, off) = GROUPS[g];
        match (self, k) {
            (Naming::Arrays, Some(k)) => format!("{arg}[{i}, {k}]"),
            (Naming::Arrays, None) => format!("{arg}[{i}]"),
            (Naming::Frame(c), k) => format!("row {i}: column `{}`", c[off + k.unwrap_or(0)]),
        }
    }

    /// Where the quaternion of row `i` is.
    pub fn quaternion(&self, i: usize) -> String {
        match self {
            Naming::Arrays => format!("q[{i}]"),
            Naming::Frame(c) => format!("row {i}: columns `{}`", c[1..5].join(",")),
        }
    }

    /// The quaternion columns, for the estimator's messages (as the CLI names them).
    pub fn quaternion_columns(&self) -> String {
        match self {
            Naming::Arrays => "q".into(),
            Naming::Frame(c) => c[1..5].join(","),
        }
    }

    /// Where sample `i` is, for the estimator's messages.
    pub fn sample(&self, i: usize) -> String {
        match self {
            Naming::Arrays => format!("sample {i}:"),
            Naming::Frame(_) => format!("row {i}:"),
        }
    }
}

/// What the reader counts: the CSV reader's counts, for arrays too.
pub type Stats = inertia::telemetry::csv::ReadStats;

/// The checks that span rows.
#[derive(Debug, Clone, Default)]
pub struct Checker {
    pub stats: Stats,
    prev: Option<Sample>,
    period: Option<f64>,
}

fn finite(naming: &Naming, g: usize, k: Option<usize>, i: usize, v: f64) -> Result<f64, String> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(format!(
            "{}: value {v} is not finite",
            naming.value(g, k, i)
        ))
    }
}

fn in_range(
    naming: &Naming,
    g: usize,
    k: Option<usize>,
    i: usize,
    quantity: Quantity,
    v: f64,
) -> Result<f64, String> {
    let v = finite(naming, g, k, i, v)?;
    check_value(quantity, v).map_err(|_| {
        let (limit, unit) = quantity.limit();
        format!(
            "{}: value {} is outside the supported range (magnitude at most {} {unit})",
            naming.value(g, k, i),
            Num(v),
            Num(limit)
        )
    })?;
    Ok(v)
}

fn vec3(
    naming: &Naming,
    g: usize,
    i: usize,
    v: [f64; 3],
    kind: fn(usize) -> Quantity,
) -> Result<Vector3<f64>, String> {
    let mut out = Vector3::zeros();
    for k in 0..3 {
        out[k] = in_range(naming, g, Some(k), i, kind(k), v[k])?;
    }
    Ok(out)
}

impl Checker {
    /// Row `i` as a sample, or the reader's message for it.
    pub fn sample(
        &mut self,
        row: &Row,
        i: usize,
        c: &Convention,
        naming: &Naming,
    ) -> Result<Sample, String> {
        let t = in_range(naming, 0, None, i, Quantity::Time, row.t)?;
        for k in 0..4 {
            finite(naming, 1, Some(k), i, row.q[k])?;
        }
        let raw = match c.format {
            QuaternionFormat::HamiltonScalarLast => Quaternion::from_xyzw(row.q),
            QuaternionFormat::HamiltonScalarFirst => Quaternion::from_wxyz(row.q),
            QuaternionFormat::Jpl => Quaternion::from_jpl_xyzw(row.q),
            QuaternionFormat::Conjugate => Quaternion::from_hamilton_inertial_to_body_xyzw(row.q),
        };
        let norm = raw.norm();
        if (norm - 1.0).abs() > c.unit_tolerance {
            return Err(format!(
                "{}: quaternion norm {norm:.6} differs from 1 by more than {:e}",
                naming.quaternion(i),
                c.unit_tolerance
            ));
        }
        let mut q = raw;
        if norm != 1.0 {
            if let Some(n) = raw.normalize() {
                if (norm - 1.0).abs() > 1e-12 {
                    self.stats.renormalised += 1;
                }
                q = n;
            }
        }
        let rho = vec3(naming, 2, i, row.rho, Quantity::Rho)?;
        let tau = match row.tau {
            Some(v) => vec3(naming, 3, i, v, Quantity::Tau)?,
            None => Vector3::zeros(),
        };
        let w = row
            .w
            .map(|v| vec3(naming, 4, i, v, Quantity::Rate))
            .transpose()?;
        if let Some(prev) = self.prev {
            let dt = t - prev.t_s;
            if !(dt > 0.0) {
                return Err(format!(
                    "{}: time {} s does not increase (previous row: {} s)",
                    naming.value(0, None, i),
                    Num(t),
                    Num(prev.t_s)
                ));
            }
            if let Some(tol) = c.period_tolerance {
                match self.period {
                    None => self.period = Some(dt),
                    Some(p) if (dt - p).abs() > tol * p => {
                        return Err(format!(
                            "{}: step {} s differs from the sample period {} s by more than {tol:e} (relative); resample or split the data",
                            naming.value(0, None, i),
                            Num(dt),
                            Num(p)
                        ));
                    }
                    Some(_) => {}
                }
            }
            self.stats.step(dt, &prev.q, &q);
        }
        let s = Sample {
            t_s: t,
            q,
            rho_nms: if c.negate_rho { -rho } else { rho },
            tau_nm: tau,
            omega_rad_s: w,
        };
        self.prev = Some(s);
        self.stats.rows += 1;
        Ok(s)
    }
}
