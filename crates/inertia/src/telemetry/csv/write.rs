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
    let mut w = csv::Writer::from_writer(out);
    let with_rates = samples.iter().all(|s| s.omega_rad_s.is_some());
    let header = [
        "t", "q_x", "q_y", "q_z", "q_w", "rho_x", "rho_y", "rho_z", "tau_x", "tau_y", "tau_z",
        "w_x", "w_y", "w_z",
    ];
    let n = if with_rates { 14 } else { 11 };
    w.write_record(header[..n].iter().chain(&names))?;
    for s in samples {
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
        w.write_record(v[..n].iter().chain(&extra(s)).map(|x| format!("{x:?}")))?;
    }
    w.flush()
}
