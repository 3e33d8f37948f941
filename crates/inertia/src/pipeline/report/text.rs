//! The text report ([`ReportText`]): what `inertia estimate` prints, the fixes named in
//! one front end's words.

use super::*;

/// A report as text, with its fixes in one front end's names ([`Report::text`]).
pub struct ReportText<'a> {
    report: &'a Report,
    names: FixNames,
    label: &'static str,
}

impl Report {
    /// The text, naming the fixes of its status with `names` as `label`s (`option`,
    /// `keyword`); `Display` names them with the library's settings.
    #[must_use]
    pub fn text(&self, names: FixNames, label: &'static str) -> ReportText<'_> {
        ReportText {
            report: self,
            names,
            label,
        }
    }
}

impl fmt::Display for Report {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.text(crate::fix::library_names, "setting").fmt(f)
    }
}

impl fmt::Display for ReportText<'_> {
    fn fmt(&self, s: &mut fmt::Formatter<'_>) -> fmt::Result {
        let fixes = Fixes {
            fixes: &self.report.fixes,
            names: self.names,
            label: self.label,
        };
        let r = self.report;
        if let Some(i) = &r.input {
            let steps = if (i.max_step_s - i.min_step_s) <= 1e-9 * i.max_step_s {
                std::format!("h = {} s", Num(i.sample_period_s))
            } else {
                std::format!("steps {}–{} s", Num(i.min_step_s), Num(i.max_step_s))
            };
            writeln!(
                s,
                "{}: {}, {steps} ({} renormalised, {}, {})",
                i.file,
                Counted(r.samples, "sample"),
                i.renormalised,
                Counted(i.sign_flips, "sign flip"),
                Counted(r.gaps, "gap")
            )?;
            if i.records > 1 {
                writeln!(
                    s,
                    "records: {}, estimated together (one J; each its own initial momenta and torques)",
                    i.records
                )?;
            }
            if i.attitude_from_gyro {
                writeln!(
                    s,
                    "attitude: integrated from the gyro rates (no quaternion columns); it drifts with the gyro's noise, and the gyro's unit cannot be checked against it"
                )?;
            }
        }
        writeln!(
            s,
            "estimator: {} ({}), solver: {}, constraints: {}, t = {} s",
            r.estimator,
            if r.batch { "batch" } else { "recursive" },
            r.solver,
            r.constraints,
            Num(r.t)
        )?;
        if let Some(m) = &r.row_model {
            writeln!(s, "rows: {m}")?;
        }
        if r.attitude_is_gyro_integral == Some(true) {
            writeln!(
                s,
                "rotation: the attitude is the gyro's own integral (their answers agree within {} σ), so its rows are the gyro's and are folded once",
                crate::estimators::discrete_momentum::twins::TWIN_Z
            )?;
        }
        writeln!(s, "status: {}{fixes}", r.observability)?;
        let (Some(m), Some(j)) = (r.inertia, r.j) else {
            return writeln!(s, "no estimate: the data cannot determine J");
        };
        writeln!(s, "J [kg m²] =")?;
        for r in m {
            writeln!(s, "  [ {:>12.6} {:>12.6} {:>12.6} ]", r[0], r[1], r[2])?;
        }
        if let Some(sig) = r.sigma {
            let mut parts = std::vec!["noise", "discretisation bias"];
            if r.wheel_delay.is_some_and(|d| d.estimated) {
                parts.push("the wheel speeds' time tag");
            }
            if r.rotor_inertia.is_some() {
                parts.push("the rotors' stated uncertainty");
            }
            if r.rotor_calibration.is_some() {
                parts.push("the rotors' calibration");
            }
            if r.rotor_scale_sigma_kg_m2.is_some() {
                parts.push("the wheels' stated scale");
            }
            if r.torque_scale_sigma_kg_m2.is_some() {
                parts.push("the known torque's stated scale");
            }
            let last = parts.pop().unwrap_or_default();
            let parts = format!("{} and {last}", parts.join(", "));
            writeln!(s, "elements, ± one standard deviation ({parts}) [kg m²]:")?;
            for (k, name) in COMPONENT_NAMES.iter().enumerate() {
                match r.rotor_scale_sigma_kg_m2 {
                    Some(p) => writeln!(
                        s,
                        "  {name} = {:>12.6} ± {:.2e} (scale {:.2e})",
                        j[k], sig[k], p[k]
                    )?,
                    None => writeln!(s, "  {name} = {:>12.6} ± {:.2e}", j[k], sig[k])?,
                }
            }
        }
        if let Some(pm) = r.principal_moments {
            match r.principal_moments_sigma {
                Some(ps) => writeln!(
                    s,
                    "principal moments [kg m²]: {:.6} ± {:.1e}  {:.6} ± {:.1e}  {:.6} ± {:.1e}",
                    pm[0], ps[0], pm[1], ps[1], pm[2], ps[2]
                )?,
                None => writeln!(
                    s,
                    "principal moments [kg m²]: {:.6}  {:.6}  {:.6}",
                    pm[0], pm[1], pm[2]
                )?,
            }
        }
        if let Some(ax) = r.principal_axes {
            writeln!(s, "principal axes (columns, body axes):")?;
            for r in ax {
                writeln!(s, "  [ {:>9.5} {:>9.5} {:>9.5} ]", r[0], r[1], r[2])?;
            }
        }
        if let Some(g) = &r.glitches {
            writeln!(
                s,
                "attitude glitches kept: {} step{} where the attitude jumped against the gyro",
                g.count,
                if g.count == 1 { "" } else { "s" }
            )?;
            for x in &g.listed {
                writeln!(s, "  {x}")?;
            }
        }
        if !r.active_bounds.is_empty() {
            let list: std::vec::Vec<String> =
                r.active_bounds.iter().map(ToString::to_string).collect();
            writeln!(
                s,
                "active bounds (they, not the data, hold the answer there): {}",
                list.join(", ")
            )?;
        }
        if let Some(p) = &r.prior {
            let shares: std::vec::Vec<String> = COMPONENT_NAMES
                .iter()
                .zip(&p.data_share)
                .map(|(name, d)| match d {
                    Some(d) => format!("{name} {:.0} %", 100.0 * d),
                    None => format!("{name} fixed"),
                })
                .collect();
            writeln!(
                s,
                "information from the data (the rest from the prior): {}",
                shares.join(", ")
            )?;
            writeln!(
                s,
                "prior-data disagreement: χ² = {:.2} on {} elements (conflict above {:.1})",
                p.chi2,
                p.rows,
                p.threshold()
            )?;
        }
        if let Some(d) = r.wheel_delay {
            let how = if d.estimated {
                format!(
                    "estimated: {:.3e} ± {:.1e} s, its σ in each element's σ up to {:.1e} kg m²",
                    d.delay_s,
                    d.sigma_s,
                    d.sigma_kg_m2.iter().fold(0.0f64, |a, &b| a.max(b))
                )
            } else {
                format!("given: {:.3e} s", d.delay_s)
            };
            writeln!(s, "wheel speeds read later than time-tagged by δ ({how})")?;
        }
        if let Some(ri) = &r.rotor_inertia {
            let largest = ri.relative_sigma.iter().fold(0.0f64, |a, &b| a.max(b));
            let errors = match ri.errors {
                crate::spacecraft::RotorErrors::Shared => "shared",
                crate::spacecraft::RotorErrors::Independent => "independent",
            };
            let tilt = ri.axis_sigma_deg.iter().fold(0.0f64, |a, &b| a.max(b));
            let tilt = if tilt > 0.0 {
                format!(", axis tilts up to {tilt:.2}°")
            } else {
                String::new()
            };
            let tag = ri.time_tag_sigma_s.iter().fold(0.0f64, |a, &b| a.max(b));
            let tilt = if tag > 0.0 {
                format!("{tilt}, own time tags up to {tag:.3} s")
            } else {
                tilt
            };
            writeln!(
                s,
                "rotors ({} rotors, {errors} spin-inertia errors up to {:.2} % each{tilt}; {} error sources): their σ in each element's σ up to {:.1e} kg m²",
                ri.rotors.len(),
                100.0 * largest,
                ri.sources.len(),
                ri.sigma_kg_m2.iter().fold(0.0f64, |a, &b| a.max(b))
            )?;
        }
        if let Some(c) = &r.rotor_calibration {
            writeln!(
                s,
                "rotors calibrated with J (against the spacecraft file; the data fix {} of {} combinations, the file's σ the rest; total angular momentum {:.1} % of the rotors', {:.1} times its scatter):",
                c.data_fixed,
                c.sources.len(),
                100.0 * c.momentum_ratio,
                c.momentum_significance
            )?;
            for (k, name) in c.sources.iter().enumerate() {
                let (scale, unit) = match c.unit[k] {
                    "relative" => (100.0, " %"),
                    "s" => (1e3, " ms"),
                    _ => (1.0, "°"),
                };
                writeln!(
                    s,
                    "  {name}: {:+.4}{unit} ± {:.4}{unit} (file: ± {:.4}{unit})",
                    scale * c.value[k],
                    scale * c.sigma[k],
                    scale * c.prior_sigma[k]
                )?;
            }
        }
        if let Some(t) = r.torque_bias_nm {
            let test = r
                .torque_test
                .map(|t| match t.shift_z {
                    Some(z) if t.shift_in_sigma => format!(
                        " (χ²₃ = {:.3e} > {TORQUE_CHI2}, and it moves the answer by {z:.3e} σ > {TORQUE_SHIFT_Z}, \
                         but the residual variances with and without it do not tell the two apart: the move is in σ)",
                        t.chi2
                    ),
                    Some(z) => format!(
                        " (the data need it: χ²₃ = {:.3e} > {TORQUE_CHI2}, and it moves the answer by {z:.3e} σ > {TORQUE_SHIFT_Z})",
                        t.chi2
                    ),
                    None => format!(" (the data need it: χ²₃ = {:.3e} > {TORQUE_CHI2})", t.chi2),
                })
                .unwrap_or_default();
            writeln!(
                s,
                "unknown constant torque (body) [N m]: [{:.3e}, {:.3e}, {:.3e}]{test}",
                t[0], t[1], t[2]
            )?;
        } else if let Some(t) = r.torque_test.filter(|t| t.held_at_zero) {
            match t.shift_z {
                Some(z) if t.chi2 > TORQUE_CHI2 => writeln!(
                    s,
                    "unknown constant torque: held at zero, it would move the answer by at most \
                     {z:.2} σ (≤ {TORQUE_SHIFT_Z}; χ²₃ = {:.2} > {TORQUE_CHI2}); the move is in σ",
                    t.chi2
                )?,
                _ => writeln!(
                    s,
                    "unknown constant torque: held at zero, the data give no evidence of one \
                     (χ²₃ = {:.2} ≤ {TORQUE_CHI2})",
                    t.chi2
                )?,
            }
        }
        if let Some(d) = r.damping_nms {
            match r.damping_sigma_nms {
                Some(sd) => writeln!(s, "unknown damping −D ω: D = {d:.3e} ± {sd:.1e} N m s")?,
                None => writeln!(s, "unknown damping −D ω: D = {d:.3e} N m s")?,
            }
        }
        if let Some(o) = &r.outside {
            outside_lines(s, o)?;
        }
        match r.drift_weighted {
            Some(true) => writeln!(
                s,
                "attitude drift: the rows are weighted for it (generalised least squares)"
            )?,
            Some(false) => writeln!(
                s,
                "attitude drift: the unweighted rows' answer (their bias outweighs their noise, or no first answer to weight with within the samples kept)"
            )?,
            None => {}
        }
        if let Some(e) = r.relative_error {
            writeln!(s, "relative Frobenius error vs truth: {e:.3e}")?;
        }
        if let Some(w) = r.residual_consistency {
            if w.ratio > INCONSISTENT_RATIO {
                writeln!(
                    s,
                    "residuals: the most distinct span, t = {:.1}–{:.1} s, has {} the rest's variance (beyond {INCONSISTENT_RATIO}; inconsistent only if the answer moves by {SHIFT_Z} σ without it)",
                    w.t_start_s, w.t_end_s, crate::text::Times(w.ratio)
                )?;
            } else {
                writeln!(
                    s,
                    "residuals: the most distinct span, t = {:.1}–{:.1} s, has {} the rest's variance (inconsistent beyond {INCONSISTENT_RATIO})",
                    w.t_start_s, w.t_end_s, crate::text::Times(w.ratio)
                )?;
            }
        }
        if let Some(g) = r.gyro_noise_estimated_deg_s_rthz {
            writeln!(
                s,
                "gyro noise: {g:.3e} deg/s/√Hz, estimated from the rates; its errors-in-variables shrinkage of J compensated (a stated density replaces it, 0 for none)"
            )?;
        }
        let estimated = r.gyro_noise_estimated_deg_s_rthz.is_some();
        if let Some(r) = r.gyro_density_ratio {
            if estimated {
                writeln!(
                    s,
                    "residuals: {r:.2} times the variance the estimated gyro density alone implies"
                )?;
            } else {
                writeln!(
                    s,
                    "residuals: {r:.2} times the variance the stated gyro density alone implies (overstated below {DENSITY_OVERSTATED_RATIO})"
                )?;
            }
        }
        if let Some(x) = &r.excitation {
            let mut line = String::from("excitation: singular values of R");
            for v in x.singular_values {
                let _ = write!(line, " {v:.2e}");
            }
            writeln!(s, "{line}")?;
            if let Some(sig) = x.element_sigma {
                let mut line = String::from("  1-sigma per element (sensor noise only) [kg m²]:");
                for (k, (n, v)) in COMPONENT_NAMES.iter().zip(sig).enumerate() {
                    let _ = write!(line, "{} {n} {v:.1e}", if k == 0 { "" } else { "," });
                }
                writeln!(s, "{line}")?;
            }
            for a in &x.advice {
                writeln!(s, "  warning: {a}")?;
            }
        }
        for w in r.warning_list() {
            if !matches!(w, Warning::Excitation(_)) {
                writeln!(s, "warning: {w}")?;
            }
        }
        Ok(())
    }
}

/// The report's lines on the torques of outside measurements.
fn outside_lines(
    s: &mut fmt::Formatter<'_>,
    o: &crate::estimator::external_torque::OutsideEstimates,
) -> fmt::Result {
    use crate::estimator::external_torque::Estimated3;
    if o.gravity_gradient {
        writeln!(
            s,
            "gravity gradient: modelled from the positions (r_x,r_y,r_z)"
        )?;
    }
    let vector = |s: &mut fmt::Formatter<'_>, what: &str, e: &Estimated3, unit: &str| {
        let [x, y, z] = e.value;
        let sigma = e
            .sigma
            .map(|v| v.map_or_else(|| "—".into(), |v| format!("{v:.1e}")));
        writeln!(
            s,
            "{what} = [{x:.4e}, {y:.4e}, {z:.4e}] ± [{}] {unit}",
            sigma.join(", ")
        )?;
        if let Some([x, y, z]) = e.undetermined_direction {
            writeln!(
                s,
                "  not determined along [{x:.3}, {y:.3}, {z:.3}] (body axes): that component gives no torque in these data, and its value is not an estimate"
            )?;
        }
        Ok(())
    };
    if let Some(m) = &o.residual_dipole_am2 {
        vector(s, "residual magnetic dipole m (body axes)", m, "A m²")?;
    }
    if let Some(c) = &o.centre_of_mass_m {
        vector(
            s,
            "centre of mass c (body axes, from the known torque's origin)",
            c,
            "m",
        )?;
    }
    Ok(())
}
