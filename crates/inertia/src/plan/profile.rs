//! A wheel torque command profile: the body-axis rotor momentum rate `ρ̇` (N m) held
//! constant (zero-order hold) over each controller period, zero after the last.
//!
//! Command `k` holds on `[t0 + k P, t0 + (k+1) P)`, `P` the controller period. The body
//! feels `−ρ̇` (eq. 26); each wheel `i` is commanded its share `ḣ_i = (A⁺ρ̇)_i`
//! ([`super::limits`]), which is the motor torque on that wheel (Basilisk's
//! `ArrayMotorTorqueMsg.motorTorque`, whose sign is the torque on the wheel about its spin
//! axis).
//!
//! # CSV
//!
//! ```text
//! # inertia plan: wheel torque commands, zero-order hold from t_s to the next row; ...
//! t_s,rho_dot_x_nm,rho_dot_y_nm,rho_dot_z_nm,rw1_torque_nm,…,rw1_momentum_nms,…
//! ```
//!
//! `t_s` in s; `rho_dot_*_nm` the body-axis command, N m; per wheel its motor torque, N m,
//! and its momentum at `t_s` (the start of the row), N m s. The last row is at the end
//! of the profile with zero commands (its momentum is the final one). Reading needs only
//! `t_s` and `rho_dot_*_nm`, evenly spaced; lines starting with `#` are comments.

use nalgebra::{Matrix3, UnitQuaternion, Vector3};
use std::format;
use std::string::{String, ToString};
use std::vec::Vec;

/// A zero-order-hold wheel torque command profile.
#[derive(Debug, Clone, PartialEq)]
pub struct CommandProfile {
    /// Time of the first command, s.
    pub t0_s: f64,
    /// Controller period, s.
    pub period_s: f64,
    /// The commands `ρ̇`, N m, body axes.
    pub torque_nm: Vec<Vector3<f64>>,
}

/// A command CSV that cannot be read.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{file}:{}{message}", .line.map_or_else(String::new, |l| format!("{l}:")))]
pub struct ProfileError {
    /// The file.
    pub(crate) file: String,
    /// 1-based line, where there is one.
    pub(crate) line: Option<usize>,
    /// What is wrong.
    pub(crate) message: String,
}

/// Integration steps per command period of [`CommandProfile::max_angle_rad`].
pub(crate) const ANGLE_SUBSTEPS: usize = 20;

/// The body-axis command columns.
pub(crate) const COLUMNS: [&str; 3] = ["rho_dot_x_nm", "rho_dot_y_nm", "rho_dot_z_nm"];

impl CommandProfile {
    /// A profile of `torque_nm` from `t0_s` at period `period_s`.
    #[must_use]
    pub(crate) fn new(t0_s: f64, period_s: f64, torque_nm: Vec<Vector3<f64>>) -> Self {
        Self {
            t0_s,
            period_s,
            torque_nm,
        }
    }

    /// Its length, s.
    #[must_use]
    pub fn duration_s(&self) -> f64 {
        self.torque_nm.len() as f64 * self.period_s
    }

    /// The command held at `t_s` (zero outside the profile).
    #[must_use]
    pub(crate) fn at(&self, t_s: f64) -> Vector3<f64> {
        let k = ((t_s - self.t0_s) / self.period_s + 1e-9).floor();
        if k < 0.0 || !k.is_finite() {
            return Vector3::zeros();
        }
        self.torque_nm
            .get(k as usize)
            .copied()
            .unwrap_or_else(Vector3::zeros)
    }

    /// The rotor momentum at every tick from zero at the start (`n + 1` values): `ρ` is
    /// the running sum of `P ρ̇` (exact for the hold).
    #[must_use]
    pub(crate) fn momentum_at_ticks(&self) -> Vec<Vector3<f64>> {
        let mut rho = Vector3::zeros();
        let mut out = Vec::with_capacity(self.torque_nm.len() + 1);
        out.push(rho);
        for c in &self.torque_nm {
            rho += c * self.period_s;
            out.push(rho);
        }
        out
    }

    /// The largest rotation of the body from its attitude at the start, rad, over the
    /// profile flown from rest on the inertia whose inverse is `j_inv`
    /// (`ω = −J⁻¹ρ`, [`super::limits`]). Within a command period `ρ`, hence `ω`, is
    /// linear: the attitude is integrated in [`ANGLE_SUBSTEPS`] steps, each the rotation at
    /// its midpoint rate (second order; 1e-6 of the angle at the rates of a plan).
    #[must_use]
    pub(crate) fn max_angle_rad(&self, j_inv: &Matrix3<f64>) -> f64 {
        let dt = self.period_s / ANGLE_SUBSTEPS as f64;
        let mut q = UnitQuaternion::identity();
        let mut rho = Vector3::zeros();
        let mut worst: f64 = 0.0;
        for c in &self.torque_nm {
            for i in 0..ANGLE_SUBSTEPS {
                let mid = rho + c * (dt * (i as f64 + 0.5));
                q *= UnitQuaternion::from_scaled_axis(-(j_inv * mid) * dt);
                worst = worst.max(q.angle());
            }
            rho += c * self.period_s;
        }
        worst
    }

    /// Every command times `s`.
    #[must_use]
    pub(crate) fn scaled(&self, s: f64) -> Self {
        Self {
            torque_nm: self.torque_nm.iter().map(|c| c * s).collect(),
            ..self.clone()
        }
    }

    /// The first `n` commands.
    #[must_use]
    pub(crate) fn truncated(&self, n: usize) -> Self {
        Self {
            torque_nm: self.torque_nm[..n.min(self.torque_nm.len())].to_vec(),
            ..self.clone()
        }
    }

    /// Write the CSV (module docs) with each wheel's torque and momentum through the
    /// allocation `alloc` (m × 3, [`super::limits::Limits::allocation`]) and `names`.
    pub fn write_csv(
        &self,
        w: &mut dyn std::io::Write,
        names: &[String],
        alloc: &nalgebra::DMatrix<f64>,
    ) -> std::io::Result<()> {
        writeln!(
            w,
            "# inertia plan: wheel torque commands, zero-order hold from t_s to the next row; \
             rho_dot_* body axes, N m (the body feels -rho_dot); <wheel>_torque_nm motor \
             torque, N m; <wheel>_momentum_nms wheel momentum at t_s, N m s; zero after the last row"
        )?;
        let mut header: Vec<String> = std::vec!["t_s".into()];
        header.extend(COLUMNS.iter().map(|c| c.to_string()));
        header.extend(names.iter().map(|n| format!("{n}_torque_nm")));
        header.extend(names.iter().map(|n| format!("{n}_momentum_nms")));
        writeln!(w, "{}", header.join(","))?;
        let rho = self.momentum_at_ticks();
        let split = |v: &Vector3<f64>| alloc * nalgebra::DVector::from_column_slice(v.as_slice());
        let zero = Vector3::zeros();
        for (k, r) in rho.iter().enumerate() {
            let c = self.torque_nm.get(k).unwrap_or(&zero);
            let t = self.t0_s + k as f64 * self.period_s;
            let mut row: Vec<String> = std::vec![num(t)];
            row.extend(c.iter().map(|x| num(*x)));
            row.extend(split(c).iter().map(|x| num(*x)));
            row.extend(split(r).iter().map(|x| num(*x)));
            writeln!(w, "{}", row.join(","))?;
        }
        Ok(())
    }

    /// Read a command CSV (module docs); `file` names it in errors.
    pub fn parse_csv(text: &str, file: &str) -> Result<Self, ProfileError> {
        let err = |line: Option<usize>, message: String| ProfileError {
            file: file.to_string(),
            line,
            message: format!(" {message}"),
        };
        let mut lines = text
            .lines()
            .enumerate()
            .filter(|(_, l)| !l.trim_start().starts_with('#') && !l.trim().is_empty());
        let (hl, header) = lines
            .next()
            .ok_or_else(|| err(None, "no header line".into()))?;
        let names: Vec<&str> = header.split(',').map(str::trim).collect();
        let col = |n: &str| {
            names.iter().position(|c| *c == n).ok_or_else(|| {
                err(
                    Some(hl + 1),
                    format!("no column `{n}` (needs t_s, {})", COLUMNS.join(", ")),
                )
            })
        };
        let it = col("t_s")?;
        let ic = [col(COLUMNS[0])?, col(COLUMNS[1])?, col(COLUMNS[2])?];
        let mut t = Vec::new();
        let mut c = Vec::new();
        for (i, l) in lines {
            let f: Vec<&str> = l.split(',').map(str::trim).collect();
            let get = |k: usize, n: &str| -> Result<f64, ProfileError> {
                f.get(k)
                    .and_then(|s| s.parse::<f64>().ok())
                    .filter(|x| x.is_finite())
                    .ok_or_else(|| err(Some(i + 1), format!("`{n}`: not a finite number")))
            };
            t.push((i + 1, get(it, "t_s")?));
            c.push(Vector3::new(
                get(ic[0], COLUMNS[0])?,
                get(ic[1], COLUMNS[1])?,
                get(ic[2], COLUMNS[2])?,
            ));
        }
        if t.len() < 2 {
            return Err(err(None, "fewer than two rows".into()));
        }
        let period = t[1].1 - t[0].1;
        if !(period > 0.0) {
            return Err(err(Some(t[1].0), "t_s must increase".into()));
        }
        for k in 1..t.len() {
            let expect = t[0].1 + k as f64 * period;
            if (t[k].1 - expect).abs() > 1e-6 * period {
                return Err(err(
                    Some(t[k].0),
                    format!("t_s = {} breaks the even spacing {period} s", t[k].1),
                ));
            }
        }
        // The last row is the end of the profile when its command is zero.
        if c.last().is_some_and(|v| *v == Vector3::zeros()) {
            c.pop();
        }
        Ok(Self::new(t[0].1, period, c))
    }
}

/// Shortest round-trip decimal (`{}` of an f64 is exact), `-0` written `0`.
fn num(x: f64) -> String {
    if x == 0.0 {
        return "0".into();
    }
    format!("{x}")
}

#[cfg(feature = "sim")]
impl crate::sim::InputLaw for CommandProfile {
    fn eval(&self, t_s: f64, _x: &crate::dynamics::GyrostatState) -> Vector3<f64> {
        self.at(t_s)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn csv_round_trips_and_names_units() {
        let p = CommandProfile::new(
            0.0,
            0.5,
            std::vec![
                Vector3::new(1e-3, -2e-3, 0.0),
                Vector3::new(0.0, 3.5e-4, -1e-4),
                Vector3::new(-1e-3, 0.0, 0.0),
            ],
        );
        let alloc = nalgebra::DMatrix::<f64>::identity(3, 3);
        let names: Vec<String> = ["a", "b", "c"].iter().map(|s| s.to_string()).collect();
        let mut out = Vec::new();
        p.write_csv(&mut out, &names, &alloc).unwrap();
        let text = String::from_utf8(out).unwrap();
        assert!(text.contains("t_s,rho_dot_x_nm,rho_dot_y_nm,rho_dot_z_nm,a_torque_nm"));
        assert!(text.contains("c_momentum_nms"));
        let back = CommandProfile::parse_csv(&text, "p.csv").unwrap();
        assert_eq!(back, p);
        // The last row holds the final momentum: 0.5 (1e-3 + 0 − 1e-3) = 0 on x.
        let last = text.lines().last().unwrap();
        assert!(last.starts_with("1.5,0,0,0"), "{last}");
    }

    #[test]
    fn uneven_times_are_refused_with_the_line() {
        let text = "t_s,rho_dot_x_nm,rho_dot_y_nm,rho_dot_z_nm\n0,1,0,0\n1,1,0,0\n2.5,0,0,0\n";
        let e = CommandProfile::parse_csv(text, "p.csv").unwrap_err();
        assert_eq!(e.line, Some(4), "{e}");
        let e = CommandProfile::parse_csv("t_s,x\n0,1\n", "p.csv").unwrap_err();
        assert!(e.to_string().contains("rho_dot_x_nm"), "{e}");
    }

    #[test]
    fn hold_and_momentum() {
        let p = CommandProfile::new(1.0, 0.5, std::vec![Vector3::x(), -Vector3::x()]);
        assert_eq!(p.at(0.9), Vector3::zeros());
        assert_eq!(p.at(1.2), Vector3::x());
        assert_eq!(p.at(1.5), -Vector3::x());
        assert_eq!(p.at(2.0), Vector3::zeros());
        let m = p.momentum_at_ticks();
        assert_eq!(m[1], Vector3::new(0.5, 0.0, 0.0));
        assert_eq!(m[2], Vector3::zeros());
    }
}
