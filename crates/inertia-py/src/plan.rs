//! `inertia.plan(...)`: the spacecraft file → `inertia::plan::request::make` → arrays. All
//! the planning is in the library.

use crate::errors::value_error;
use inertia::plan::request::{make, Chain, Request};
use inertia::plan::Vehicle;
use inertia::spacecraft::Spacecraft;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// Plan the calibration manoeuvre for a spacecraft file (the Python wrapper documents the
/// keys of the returned dict).
#[pyfunction]
#[pyo3(signature = (spacecraft, target, duration, max_duration, chain, choose_chain, rehearsals, disturbance))]
#[allow(clippy::too_many_arguments)]
pub fn plan<'py>(
    py: Python<'py>,
    spacecraft: std::path::PathBuf,
    target: f64,
    duration: Option<f64>,
    max_duration: f64,
    chain: Option<f64>,
    choose_chain: bool,
    rehearsals: u64,
    disturbance: f64,
) -> PyResult<Bound<'py, PyDict>> {
    let file = spacecraft.display().to_string();
    let request = Request {
        target_relative: target,
        duration_s: duration,
        max_duration_s: max_duration,
        chain: if choose_chain {
            Chain::Choose
        } else {
            Chain::Fixed(chain)
        },
        rehearsals,
        disturbance_nm_rthz: disturbance,
    };
    let (v, out) = py
        .allow_threads(|| -> Result<_, String> {
            let sc = Spacecraft::load(&spacecraft).map_err(|e| e.to_string())?;
            let v = Vehicle::from_spacecraft(&sc, &file).map_err(|e| e.to_string())?;
            let out = make(&v, &request).map_err(|e| e.to_string())?;
            Ok((v, out))
        })
        .map_err(value_error)?;
    let p = &out.plan;
    let alloc = v
        .limits
        .allocation()
        .map_err(|e| value_error(e.to_string()))?;
    let d = PyDict::new(py);
    let n = p.profile.torque_nm.len();
    d.set_item(
        "t",
        crate::column(
            py,
            (0..n)
                .map(|k| p.profile.t0_s + k as f64 * p.profile.period_s)
                .collect(),
        ),
    )?;
    d.set_item("period_s", p.profile.period_s)?;
    d.set_item(
        "rho_dot_nm",
        crate::matrix(py, p.profile.torque_nm.iter().map(|c| [c.x, c.y, c.z]))?,
    )?;
    let names: Vec<String> = v.limits.wheels.iter().map(|w| w.name.clone()).collect();
    let per_wheel: Vec<Vec<f64>> = p
        .profile
        .torque_nm
        .iter()
        .map(|c| {
            (&alloc * nalgebra::DVector::from_column_slice(c.as_slice()))
                .as_slice()
                .to_vec()
        })
        .collect();
    d.set_item("wheels", names)?;
    d.set_item("wheel_torque_nm", per_wheel)?;
    d.set_item("prediction_t", crate::column(py, p.prediction.t_s.clone()))?;
    d.set_item(
        "sigma_kg_m2",
        crate::matrix(py, p.prediction.sigma_kg_m2.iter().copied())?,
    )?;
    d.set_item(
        "relative_sigma",
        crate::column(py, p.prediction.relative_sigma.clone()),
    )?;
    d.set_item("target_met_s", p.target_met_s)?;
    d.set_item("reported_target_met_s", out.reported_target_met_s)?;
    d.set_item("rehearsal_t", crate::column(py, out.rehearsal.0.clone()))?;
    d.set_item(
        "rehearsal_relative_sigma",
        crate::column(py, out.rehearsal.1.clone()),
    )?;
    d.set_item("margin", v.limits.margin)?;
    let u = PyDict::new(py);
    u.set_item("torque", p.limit_use.torque)?;
    u.set_item("momentum", p.limit_use.momentum)?;
    u.set_item("rate", p.limit_use.rate)?;
    u.set_item("angle", p.limit_use.angle)?;
    d.set_item("limit_use", u)?;
    d.set_item("gap", p.design.gap)?;
    d.set_item("chain_s", out.chain_s)?;
    d.set_item("chain_trials", out.chain_trials.clone())?;
    Ok(d)
}
