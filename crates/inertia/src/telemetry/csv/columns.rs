//! The CSV reader's column names ([`ColumnNames`]): the defaults of the table in the
//! module docs of [`super`], renamable one by one.

use std::string::String;

/// Column names. Defaults are those of the table in the module docs.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ColumnNames {
    /// Time.
    pub t: String,
    /// Quaternion, in storage order.
    pub q: [String; 4],
    /// Rotor momentum.
    pub rho: [String; 3],
    /// Known torque.
    pub tau: [String; 3],
    /// Gyro rate.
    pub w: [String; 3],
    /// Inertial position.
    pub r: [String; 3],
    /// Magnetic field.
    pub b: [String; 3],
    /// External force.
    pub f: [String; 3],
    /// Commanded magnetic dipole.
    pub dipole: [String; 3],
}

impl Default for ColumnNames {
    fn default() -> Self {
        let v =
            |p: &str, s: &[&str]| -> Vec<String> { s.iter().map(|c| format!("{p}_{c}")).collect() };
        let arr3 = |v: Vec<String>| -> [String; 3] { [v[0].clone(), v[1].clone(), v[2].clone()] };
        let q = v("q", &["x", "y", "z", "w"]);
        Self {
            t: "t".into(),
            q: [q[0].clone(), q[1].clone(), q[2].clone(), q[3].clone()],
            rho: arr3(v("rho", &["x", "y", "z"])),
            tau: arr3(v("tau", &["x", "y", "z"])),
            w: arr3(v("w", &["x", "y", "z"])),
            r: arr3(v("r", &["x", "y", "z"])),
            b: arr3(v("b", &["x", "y", "z"])),
            f: arr3(v("f", &["x", "y", "z"])),
            dipole: arr3(v("dipole", &["x", "y", "z"])),
        }
    }
}

impl ColumnNames {
    /// Rename one column, e.g. `rename("t", "time")`. Returns `false` for an unknown key.
    pub(crate) fn rename(&mut self, key: &str, name: &str) -> bool {
        let d = Self::default();
        if key == d.t {
            self.t = name.into();
            return true;
        }
        for (dst, def) in self
            .q
            .iter_mut()
            .zip(&d.q)
            .chain(self.rho.iter_mut().zip(&d.rho))
            .chain(self.tau.iter_mut().zip(&d.tau))
            .chain(self.w.iter_mut().zip(&d.w))
            .chain(self.r.iter_mut().zip(&d.r))
            .chain(self.b.iter_mut().zip(&d.b))
            .chain(self.f.iter_mut().zip(&d.f))
            .chain(self.dipole.iter_mut().zip(&d.dipole))
        {
            if key == def {
                *dst = name.into();
                return true;
            }
        }
        false
    }
}
