//! Writing samples as CSV, in the reader's default format.

use crate::sample::Sample;

/// Write samples as CSV in the default format (scalar-last Hamilton quaternion; the gyro
/// columns `w_*` only when every sample has a rate). Used by the simulator's command-line
/// front end and by tests.
pub fn write_samples<W: std::io::Write>(out: W, samples: &[Sample]) -> std::io::Result<()> {
    write_samples_with(out, samples, [], |_| [])
}

/// [`write_samples`] with `N` extra columns named `names`, valued `extra(sample)`. Streams:
/// one row at a time.
pub fn write_samples_with<W: std::io::Write, const N: usize>(
    out: W,
    samples: &[Sample],
    names: [&str; N],
    extra: impl Fn(&Sample) -> [f64; N],
) -> std::io::Result<()> {
    write_columns(out, samples, true, &names, |k| extra(&samples[k]).to_vec())
}

/// Extra columns: their names, and their values for a sample.
pub type ExtraColumns<'a> = (&'a [&'a str], &'a dyn Fn(&Sample) -> Vec<f64>);

/// The outside measurements ([`crate::sample::External`]) that every sample of a record
/// has, as the reader's columns: `r_x,r_y,r_z` (position), `b_x,b_y,b_z` (magnetic
/// field), `f_x,f_y,f_z` (force), in that order.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ExternalColumns {
    position: bool,
    field: bool,
    force: bool,
}

impl ExternalColumns {
    /// The measurements every one of `samples` has (none for no samples).
    #[must_use]
    pub fn of(samples: &[Sample]) -> Self {
        let all = |f: fn(&Sample) -> bool| !samples.is_empty() && samples.iter().all(f);
        Self {
            position: all(|s| s.external.position_m.is_some()),
            field: all(|s| s.external.field_t.is_some()),
            force: all(|s| s.external.force_n.is_some()),
        }
    }

    /// The column names.
    #[must_use]
    pub fn names(&self) -> Vec<&'static str> {
        let mut v = Vec::new();
        for (on, names) in [
            (self.position, ["r_x", "r_y", "r_z"]),
            (self.field, ["b_x", "b_y", "b_z"]),
            (self.force, ["f_x", "f_y", "f_z"]),
        ] {
            if on {
                v.extend(names);
            }
        }
        v
    }

    /// The values of `s` in the columns' order (zeros where `s` lacks one).
    #[must_use]
    pub fn values(&self, s: &Sample) -> Vec<f64> {
        let e = &s.external;
        let mut v = Vec::new();
        for (on, x) in [
            (self.position, e.position_m),
            (self.field, e.field_t),
            (self.force, e.force_n),
        ] {
            if on {
                v.extend(x.unwrap_or_default().iter());
            }
        }
        v
    }
}

/// [`write_samples`] with the outside measurements every sample has as the extra columns
/// of [`ExternalColumns`], so that the reader reads back what was written.
pub fn write_samples_external<W: std::io::Write>(
    out: W,
    samples: &[Sample],
) -> std::io::Result<()> {
    let cols = ExternalColumns::of(samples);
    let names = cols.names();
    write_columns(out, samples, true, &names, |k| cols.values(&samples[k]))
}

/// [`write_samples_with`] for a spacecraft file's rotors: the rotors' speed columns
/// `names` (valued `speeds`, one row of `names.len()` per sample, flat) instead of the
/// `rho_*` columns, then the `extra` columns.
pub fn write_samples_with_speeds<W: std::io::Write>(
    out: W,
    samples: &[Sample],
    names: &[String],
    speeds: &[f64],
    extra: ExtraColumns<'_>,
) -> std::io::Result<()> {
    let m = names.len();
    let all: Vec<&str> = names
        .iter()
        .map(String::as_str)
        .chain(extra.0.iter().copied())
        .collect();
    write_columns(out, samples, false, &all, |k| {
        let mut v = speeds[k * m..(k + 1) * m].to_vec();
        v.extend((extra.1)(&samples[k]));
        v
    })
}

fn write_columns<W: std::io::Write>(
    out: W,
    samples: &[Sample],
    with_rho: bool,
    names: &[&str],
    extra: impl Fn(usize) -> Vec<f64>,
) -> std::io::Result<()> {
    let mut w = csv::Writer::from_writer(out);
    let with_rates = samples.iter().all(|s| s.omega_rad_s.is_some());
    let header = [
        "t", "q_x", "q_y", "q_z", "q_w", "rho_x", "rho_y", "rho_z", "tau_x", "tau_y", "tau_z",
        "w_x", "w_y", "w_z",
    ];
    let n = if with_rates { 14 } else { 11 };
    let keep = |i: &usize| with_rho || !(5..8).contains(i);
    w.write_record(
        header[..n]
            .iter()
            .enumerate()
            .filter(|(i, _)| keep(i))
            .map(|x| *x.1)
            .chain(names.iter().copied()),
    )?;
    for (k, s) in samples.iter().enumerate() {
        let rate = s.omega_rad_s.unwrap_or_default();
        let v = [
            s.t_s,
            s.q.v.x,
            s.q.v.y,
            s.q.v.z,
            s.q.s,
            s.rho_nms.x,
            s.rho_nms.y,
            s.rho_nms.z,
            s.tau_nm.x,
            s.tau_nm.y,
            s.tau_nm.z,
            rate.x,
            rate.y,
            rate.z,
        ];
        w.write_record(
            v[..n]
                .iter()
                .enumerate()
                .filter(|(i, _)| keep(i))
                .map(|x| x.1)
                .chain(&extra(k))
                .map(|x| format!("{x:?}")),
        )?;
    }
    w.flush()
}
