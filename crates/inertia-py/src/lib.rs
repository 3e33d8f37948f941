//! `inertia._inertia`: the native half of the `inertia` Python package.
//!
//! A thin layer over the library, in the manner of Clarabel.rs's Python interface: every
//! computation is the library's (the CSV reader, `pipeline::Pipeline`/`pipeline::batch`,
//! `pipeline::report::Report`, `sim`), called as the command line calls it, so results
//! and messages are the command line's. This module converts arguments and arrays,
//! releases the GIL around reading, simulating and estimating, and returns the report as
//! its JSON text (the `--json` schema), which the Python half turns into an `Estimate`.

mod errors;
mod kwargs;
mod plan;
mod read;
mod run;
mod samples;
mod settings;
mod sim;
mod stream;

use errors::{type_error, value_error, DataError, Failure};
use inertia::estimator::Estimate;
use inertia::pipeline::history::HEADER;
use inertia::pipeline::report::Report;
use inertia::run_description::RunDescription;
use inertia::sample::{External, Sample};
use inertia::telemetry::gate::RawExternal;
use kwargs::Kwargs;
use numpy::ndarray::{Array1, Array2};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyReadonlyArrayDyn};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use read::read;
use run::Origin;
use samples::{Checker, Naming, Row, Stats};
use settings::Convention;

/// Telemetry held in memory: what `read_csv` read or `simulate` made, checked and in
/// this library's convention (Hamilton, body → inertial, scalar last).
#[pyclass(module = "inertia._inertia", frozen)]
pub struct Telemetry {
    pub samples: Vec<Sample>,
    /// Each sample's line in its file.
    pub lines: Option<Vec<u64>>,
    /// The file's name as given.
    pub file: Option<String>,
    pub stats: Stats,
    pub q_columns: String,
    /// The name in reports and messages: the file's, `<arrays>` or `<simulated>`.
    pub label: String,
    /// The spacecraft file's rotors, where the file was read with one.
    pub rotors: Option<Rotors>,
}

impl Telemetry {
    /// Where these samples came from, to name them in messages.
    fn origin(&self) -> Origin {
        match (&self.file, &self.lines) {
            (Some(name), Some(lines)) => Origin::File {
                name: name.clone(),
                lines: lines.clone(),
                q_columns: self.q_columns.clone(),
            },
            _ => Origin::Memory {
                naming: Naming::Arrays,
                label: self.label.clone(),
            },
        }
    }
}

/// What pickling keeps of [`Rotors`]: the spacecraft file's text and name, the speeds.
type RotorsState<'py> = (String, String, Bound<'py, PyArray2<f64>>);

/// A spacecraft file's rotors and their speeds, as `read_csv(spacecraft=…)` read them.
#[derive(Clone)]
pub struct Rotors {
    pub spacecraft: inertia::spacecraft::Spacecraft,
    /// The file's text and name (to rebuild it when unpickled).
    pub source: (String, String),
    /// One stored speed per rotor and sample, flat.
    pub speeds: Vec<f64>,
}

fn column<'py>(py: Python<'py>, v: Vec<f64>) -> Bound<'py, PyArray1<f64>> {
    Array1::from_vec(v).into_pyarray(py)
}

pub fn matrix<'py, const N: usize>(
    py: Python<'py>,
    rows: impl ExactSizeIterator<Item = [f64; N]>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let n = rows.len();
    let flat: Vec<f64> = rows.flatten().collect();
    Array2::from_shape_vec((n, N), flat)
        .map(|a| a.into_pyarray(py))
        .map_err(|e| pyo3::exceptions::PyRuntimeError::new_err(e.to_string()))
}

/// A 3×3 matrix as a numpy array.
pub fn matrix3<'py>(
    py: Python<'py>,
    m: &nalgebra::Matrix3<f64>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    matrix(py, (0..3).map(|r| [m[(r, 0)], m[(r, 1)], m[(r, 2)]]))
}

impl Telemetry {
    /// One outside measurement of every sample as an (N, 3) array; None where the
    /// samples lack it (the gate takes it for all samples or none).
    fn external<'py>(
        &self,
        py: Python<'py>,
        of: fn(&External) -> Option<nalgebra::Vector3<f64>>,
    ) -> PyResult<Option<Bound<'py, PyArray2<f64>>>> {
        let v: Option<Vec<[f64; 3]>> = self
            .samples
            .iter()
            .map(|s| of(&s.external).map(Into::into))
            .collect();
        v.filter(|v| !v.is_empty())
            .map(|v| matrix(py, v.into_iter()))
            .transpose()
    }
}

#[pymethods]
impl Telemetry {
    /// Time, s (N,).
    #[getter]
    fn t<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        column(py, self.samples.iter().map(|s| s.t_s).collect())
    }
    /// Attitude quaternions (N, 4): [x, y, z, w], Hamilton, body → inertial, unit norm.
    #[getter]
    fn q<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        matrix(py, self.samples.iter().map(|s| s.q.to_xyzw()))
    }
    /// Total rotor angular momentum, N m s, body axes (N, 3).
    #[getter]
    fn rho<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        matrix(py, self.samples.iter().map(|s| s.rho_nms.into()))
    }
    /// Known external torque, N m, body axes (N, 3) (zeros when none was given; with
    /// commanded dipoles, their torque `m × B` included).
    #[getter]
    fn tau<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        matrix(py, self.samples.iter().map(|s| s.tau_nm.into()))
    }
    /// Gyro rate averaged over [t_k, t_{k+1}], rad/s, body axes (N, 3), or None.
    #[getter]
    fn w<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyArray2<f64>>>> {
        let rates: Option<Vec<[f64; 3]>> = self
            .samples
            .iter()
            .map(|s| s.omega_rad_s.map(Into::into))
            .collect();
        rates
            .filter(|r| !r.is_empty())
            .map(|r| matrix(py, r.into_iter()))
            .transpose()
    }
    /// Inertial position, m (N, 3), or None.
    #[getter]
    fn r<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyArray2<f64>>>> {
        self.external(py, |e| e.position_m)
    }
    /// Magnetic field, T, body axes (N, 3), or None.
    #[getter]
    fn b<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyArray2<f64>>>> {
        self.external(py, |e| e.field_t)
    }
    /// External force, N, body axes (N, 3), or None.
    #[getter]
    fn f<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyArray2<f64>>>> {
        self.external(py, |e| e.force_n)
    }
    /// The file's name, or None.
    #[getter]
    fn file(&self) -> Option<String> {
        self.file.clone()
    }
    /// Each sample's 1-based line in its file, or None.
    #[getter]
    fn lines<'py>(&self, py: Python<'py>) -> Option<Bound<'py, PyArray1<u64>>> {
        self.lines
            .clone()
            .map(|l| Array1::from_vec(l).into_pyarray(py))
    }
    /// What the reader counted: rows, renormalised quaternions, sign flips, the shortest
    /// and longest step (s).
    #[getter]
    fn stats<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        d.set_item("rows", self.stats.rows)?;
        d.set_item("renormalised", self.stats.renormalised)?;
        d.set_item("sign_flips", self.stats.sign_flips)?;
        d.set_item("min_step_s", self.stats.min_step_s)?;
        d.set_item("max_step_s", self.stats.max_step_s)?;
        d.set_item("attitude_from_gyro", self.stats.attitude_from_gyro)?;
        Ok(d)
    }
    fn __len__(&self) -> usize {
        self.samples.len()
    }
    /// The quaternion columns' names (for messages).
    #[getter]
    fn q_columns(&self) -> String {
        self.q_columns.clone()
    }
    /// The name in reports: the file's, `<arrays>` or `<simulated>`.
    #[getter]
    fn label(&self) -> String {
        self.label.clone()
    }
    /// The spacecraft file's text, name and the rotors' speeds (N, rotors), or None.
    fn rotors_state<'py>(&self, py: Python<'py>) -> PyResult<Option<RotorsState<'py>>> {
        let Some(r) = &self.rotors else {
            return Ok(None);
        };
        let m = r.spacecraft.rotors.len();
        let a = numpy::ndarray::Array2::from_shape_vec((self.samples.len(), m), r.speeds.clone())
            .map_err(|e| value_error(e.to_string()))?;
        Ok(Some((
            r.source.0.clone(),
            r.source.1.clone(),
            a.into_pyarray(py),
        )))
    }

    /// Estimate from these samples (see `inertia.estimate`).
    #[pyo3(signature = (kwargs=None))]
    fn estimate<'py>(
        slf: PyRef<'py, Self>,
        py: Python<'py>,
        kwargs: Option<&Bound<'py, PyDict>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        estimate_records(py, vec![slf], kwargs)
    }
}

/// Estimate from several records of one spacecraft together (`inertia.estimate` with a
/// list: one J, each record its own initial momenta and torques; `batch=True`).
#[pyfunction]
#[pyo3(signature = (records, kwargs=None))]
fn estimate_records<'py>(
    py: Python<'py>,
    records: Vec<PyRef<'py, Telemetry>>,
    kwargs: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyAny>> {
    let kw = Kwargs::new(kwargs, py, "estimate")?;
    let (s, d) = settings::run(&kw, "estimate")?;
    if let Some(name) = d
        .given()
        .into_iter()
        .find(|k| RunDescription::INPUT_KEYS.contains(k))
    {
        return Err(value_error(format!(
            "{name}: these samples were already read and checked; give it to read_csv"
        )));
    }
    let config = s.pipeline.validate().map_err(settings::settings_error)?;
    let origins: Vec<Origin> = records.iter().map(|t| t.origin()).collect();
    let parts: Vec<run::Record<'_>> = records
        .iter()
        .zip(&origins)
        .map(|(t, origin)| run::Record {
            samples: &t.samples,
            rotors: t.rotors.as_ref(),
            stats: &t.stats,
            origin,
        })
        .collect();
    let out = py
        .allow_threads(|| run::run_records(&parts, config, &s))
        .map_err(|f| f.into_py(py))?;
    result(py, &out.report, out.history.as_deref())
}

/// `(report JSON, report text, history columns or None)`.
fn result<'py>(
    py: Python<'py>,
    report: &Report,
    history: Option<&[Estimate]>,
) -> PyResult<Bound<'py, PyAny>> {
    let json = serde_json::to_string(report)
        .map_err(|e| pyo3::exceptions::PyRuntimeError::new_err(e.to_string()))?;
    let text = report.text(run::keyword_names, "keyword").to_string();
    let h = history.map(|h| history_columns(py, h)).transpose()?;
    Ok((json, text, h).into_pyobject(py)?.into_any())
}

/// The history as columns (`inertia::pipeline::history::HEADER`): floats (NaN where
/// not available), `status` and `reason` as lists of strings (`reason` None where none).
fn history_columns<'py>(py: Python<'py>, h: &[Estimate]) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    let nan = f64::NAN;
    d.set_item(HEADER[0], column(py, h.iter().map(|e| e.t_s).collect()))?;
    for k in 0..6 {
        d.set_item(
            HEADER[1 + k],
            column(py, h.iter().map(|e| e.j().map_or(nan, |j| j[k])).collect()),
        )?;
        d.set_item(
            HEADER[10 + k],
            column(
                py,
                h.iter()
                    .map(|e| e.sigma_kg_m2().map_or(nan, |s| s[k]))
                    .collect(),
            ),
        )?;
    }
    d.set_item(
        "status",
        PyList::new(py, h.iter().map(|e| e.observability.code()))?,
    )?;
    d.set_item(
        "condition",
        column(
            py,
            h.iter()
                .map(|e| e.observability.condition().unwrap_or(nan))
                .collect(),
        ),
    )?;
    d.set_item(
        "iterations",
        column(
            py,
            h.iter()
                .map(|e| e.solution.map_or(nan, |s| f64::from(s.iterations)))
                .collect(),
        ),
    )?;
    d.set_item(
        "reason",
        PyList::new(
            py,
            h.iter()
                .map(|e| e.observability.reason().map(|r| r.to_string())),
        )?,
    )?;
    Ok(d)
}

/// Read a telemetry CSV file as `inertia estimate` reads it.
#[pyfunction]
#[pyo3(signature = (path, kwargs=None))]
fn read_csv(
    py: Python<'_>,
    path: std::path::PathBuf,
    kwargs: Option<&Bound<'_, PyDict>>,
) -> PyResult<Telemetry> {
    let kw = Kwargs::new(kwargs, py, "read_csv")?;
    let d = settings::describe(&kw, "read_csv")?;
    only_input(&d, "read_csv")?;
    let spacecraft = d
        .spacecraft
        .as_deref()
        .map(
            |p| -> PyResult<(inertia::spacecraft::Spacecraft, (String, String))> {
                let p = p.display().to_string();
                let text = std::fs::read_to_string(&p).map_err(|e| {
                    pyo3::exceptions::PyOSError::new_err(format!("cannot read {p}: {e}"))
                })?;
                let sc = inertia::spacecraft::Spacecraft::parse(&text, &p)
                    .map_err(|e| value_error(e.to_string()))?;
                Ok((sc, (text, p)))
            },
        )
        .transpose()?;
    let mut options = d
        .csv_options(&|k| k.to_string())
        .map_err(|e| value_error(e.message))?;
    options.speed_columns = spacecraft
        .as_ref()
        .map_or_else(Vec::new, |s| s.0.speed_columns());
    options.thruster_columns = spacecraft
        .as_ref()
        .map_or_else(Vec::new, |s| s.0.thruster_columns());
    py.allow_threads(|| read(&path, options, spacecraft))
        .map_err(|f| f.into_py(py))
}

/// Only input conventions: a run setting given to `function` (which reads) is an
/// unexpected keyword.
fn only_input(d: &RunDescription, function: &str) -> PyResult<()> {
    match d
        .given()
        .into_iter()
        .find(|k| RunDescription::SETTINGS_KEYS.contains(k))
    {
        Some(k) => Err(type_error(format!(
            "{function}() got an unexpected keyword argument '{k}'"
        ))),
        None => Ok(()),
    }
}

/// The optional arrays of outside measurements, in [`samples::EXTERNAL_ARGUMENTS`]'
/// order: `r`, `b`, `f`, `dipole`.
pub type ExternalArrays<'a, 'py> = [Option<&'a PyReadonlyArrayDyn<'py, f64>>; 4];

/// Rows of float64 arrays, checked for shape against `t`.
pub fn rows(
    t: &PyReadonlyArrayDyn<'_, f64>,
    q: Option<&PyReadonlyArrayDyn<'_, f64>>,
    rho: &PyReadonlyArrayDyn<'_, f64>,
    tau: Option<&PyReadonlyArrayDyn<'_, f64>>,
    w: Option<&PyReadonlyArrayDyn<'_, f64>>,
    external: ExternalArrays<'_, '_>,
) -> PyResult<Vec<Row>> {
    let t = t.as_array();
    if t.ndim() != 1 {
        return Err(value_error(format!(
            "t: expected a 1-D array of times (N,), got shape {:?}",
            t.shape()
        )));
    }
    let n = t.len();
    let check =
        |name: &str, a: &numpy::ndarray::ArrayViewD<'_, f64>, cols: usize| -> PyResult<()> {
            if a.shape() != [n, cols] {
                return Err(value_error(format!(
                    "{name}: expected shape (N, {cols}) = ({n}, {cols}) to match t, got {:?}",
                    a.shape()
                )));
            }
            Ok(())
        };
    let q = q.map(|a| a.as_array());
    let rho = rho.as_array();
    if let Some(a) = &q {
        check("q", a, 4)?;
    }
    check("rho", &rho, 3)?;
    let tau = tau.map(|a| a.as_array());
    let w = w.map(|a| a.as_array());
    if let Some(a) = &tau {
        check("tau", a, 3)?;
    }
    if let Some(a) = &w {
        check("w", a, 3)?;
    }
    let external = external.map(|a| a.map(|a| a.as_array()));
    for (name, a) in samples::EXTERNAL_ARGUMENTS.iter().zip(&external) {
        if let Some(a) = a {
            check(name, a, 3)?;
        }
    }
    let three =
        |a: &numpy::ndarray::ArrayViewD<'_, f64>, i: usize| [a[[i, 0]], a[[i, 1]], a[[i, 2]]];
    let [r, b, f, dipole] = &external;
    let at =
        |a: &Option<numpy::ndarray::ArrayViewD<'_, f64>>, i: usize| a.as_ref().map(|a| three(a, i));
    Ok((0..n)
        .map(|i| Row {
            t: t[[i]],
            // Without quaternions the gate integrates the gyro and ignores these.
            q: q.as_ref().map_or([0.0, 0.0, 0.0, 1.0], |q| {
                [q[[i, 0]], q[[i, 1]], q[[i, 2]], q[[i, 3]]]
            }),
            rho: three(&rho, i),
            tau: tau.as_ref().map(|a| three(a, i)),
            w: w.as_ref().map(|a| three(a, i)),
            external: RawExternal {
                position_m: at(r, i),
                field_t: at(b, i),
                force_n: at(f, i),
                dipole_am2: at(dipole, i),
            },
        })
        .collect())
}

/// Check rows into samples (no GIL needed).
fn check_rows(
    rows: &[Row],
    conv: &Convention,
    naming: &Naming,
) -> Result<(Vec<Sample>, Stats), Failure> {
    let mut checker = Checker::new(conv);
    let samples = rows
        .iter()
        .enumerate()
        .map(|(i, r)| checker.sample(r, i, naming))
        .collect::<Result<Vec<_>, _>>()?;
    Ok((samples, checker.stats()))
}

/// Estimate from arrays (or a table's columns, named by `frame_columns`).
#[pyfunction]
#[pyo3(signature = (t, q, rho, tau=None, w=None, r=None, b=None, f=None, dipole=None, kwargs=None, frame_columns=None, label=None))]
#[allow(clippy::too_many_arguments)]
fn estimate_arrays<'py>(
    py: Python<'py>,
    t: PyReadonlyArrayDyn<'py, f64>,
    q: Option<PyReadonlyArrayDyn<'py, f64>>,
    rho: PyReadonlyArrayDyn<'py, f64>,
    tau: Option<PyReadonlyArrayDyn<'py, f64>>,
    w: Option<PyReadonlyArrayDyn<'py, f64>>,
    r: Option<PyReadonlyArrayDyn<'py, f64>>,
    b: Option<PyReadonlyArrayDyn<'py, f64>>,
    f: Option<PyReadonlyArrayDyn<'py, f64>>,
    dipole: Option<PyReadonlyArrayDyn<'py, f64>>,
    kwargs: Option<&Bound<'py, PyDict>>,
    frame_columns: Option<Vec<String>>,
    label: Option<String>,
) -> PyResult<Bound<'py, PyAny>> {
    let kw = Kwargs::new(kwargs, py, "estimate")?;
    let (s, d) = settings::run(&kw, "estimate")?;
    let mut conv = settings::convention(&d)?;
    if q.is_none() {
        conv = conv.without_quaternions()?;
    }
    let config = s.pipeline.validate().map_err(settings::settings_error)?;
    let external = [r.as_ref(), b.as_ref(), f.as_ref(), dipole.as_ref()];
    let rows = rows(&t, q.as_ref(), &rho, tau.as_ref(), w.as_ref(), external)?;
    let naming = match frame_columns {
        Some(c) if c.len() == samples::FRAME_COLUMNS => Naming::Frame(c),
        Some(_) => {
            return Err(value_error(format!(
                "frame_columns: expected {} names",
                samples::FRAME_COLUMNS
            )))
        }
        None => Naming::Arrays,
    };
    let origin = Origin::Memory {
        naming: naming.clone(),
        label: label.unwrap_or_else(|| "<arrays>".into()),
    };
    let out = py
        .allow_threads(|| {
            let (samples, stats) = check_rows(&rows, &conv, &naming)?;
            run::run(&samples, None, &stats, &origin, config, &s)
        })
        .map_err(|f| f.into_py(py))?;
    result(py, &out.report, out.history.as_deref())
}

/// Telemetry from arrays, checked (quaternion convention applied, renormalised).
#[pyfunction]
#[pyo3(signature = (t, q, rho, tau=None, w=None, r=None, b=None, f=None, dipole=None, kwargs=None))]
#[allow(clippy::too_many_arguments)]
fn samples_from_arrays<'py>(
    py: Python<'py>,
    t: PyReadonlyArrayDyn<'py, f64>,
    q: Option<PyReadonlyArrayDyn<'py, f64>>,
    rho: PyReadonlyArrayDyn<'py, f64>,
    tau: Option<PyReadonlyArrayDyn<'py, f64>>,
    w: Option<PyReadonlyArrayDyn<'py, f64>>,
    r: Option<PyReadonlyArrayDyn<'py, f64>>,
    b: Option<PyReadonlyArrayDyn<'py, f64>>,
    f: Option<PyReadonlyArrayDyn<'py, f64>>,
    dipole: Option<PyReadonlyArrayDyn<'py, f64>>,
    kwargs: Option<&Bound<'py, PyDict>>,
) -> PyResult<Telemetry> {
    let kw = Kwargs::new(kwargs, py, "Telemetry")?;
    let d = settings::describe(&kw, "Telemetry")?;
    only_input(&d, "Telemetry")?;
    let mut conv = settings::convention(&d)?;
    if q.is_none() {
        conv = conv.without_quaternions()?;
    }
    let external = [r.as_ref(), b.as_ref(), f.as_ref(), dipole.as_ref()];
    let rows = rows(&t, q.as_ref(), &rho, tau.as_ref(), w.as_ref(), external)?;
    let (samples, stats) = py
        .allow_threads(|| check_rows(&rows, &conv, &Naming::Arrays))
        .map_err(|f| f.into_py(py))?;
    Ok(Telemetry {
        samples,
        lines: None,
        file: None,
        stats,
        q_columns: "q".into(),
        label: "<arrays>".into(),
        rotors: None,
    })
}

/// Telemetry rebuilt from what a `Telemetry` held (unpickling): the values were
/// checked when it was made, so they are taken as they are, bit for bit.
#[pyfunction]
#[pyo3(signature = (t, q, rho, tau, w, file, lines, stats, q_columns, label, rotors=None, r=None, b=None, f=None))]
#[allow(clippy::too_many_arguments)]
fn restore<'py>(
    t: PyReadonlyArrayDyn<'py, f64>,
    q: PyReadonlyArrayDyn<'py, f64>,
    rho: PyReadonlyArrayDyn<'py, f64>,
    tau: PyReadonlyArrayDyn<'py, f64>,
    w: Option<PyReadonlyArrayDyn<'py, f64>>,
    file: Option<String>,
    lines: Option<Vec<u64>>,
    stats: (usize, usize, usize, f64, f64, bool),
    q_columns: String,
    label: String,
    rotors: Option<(String, String, PyReadonlyArrayDyn<'py, f64>)>,
    r: Option<PyReadonlyArrayDyn<'py, f64>>,
    b: Option<PyReadonlyArrayDyn<'py, f64>>,
    f: Option<PyReadonlyArrayDyn<'py, f64>>,
) -> PyResult<Telemetry> {
    // The commanded dipoles' torque is in `tau` already.
    let external = [r.as_ref(), b.as_ref(), f.as_ref(), None];
    let rows = rows(&t, Some(&q), &rho, Some(&tau), w.as_ref(), external)?;
    let rotors = rotors
        .map(|(text, name, speeds)| -> PyResult<Rotors> {
            let spacecraft = inertia::spacecraft::Spacecraft::parse(&text, &name)
                .map_err(|e| value_error(e.to_string()))?;
            let speeds: Vec<f64> = speeds.as_array().iter().copied().collect();
            if speeds.len() != rows.len() * spacecraft.rotors.len() {
                return Err(value_error("rotors: one speed per rotor and sample"));
            }
            // A thruster file's torque and force are in the pickled samples already (as
            // `read_csv` put them); the run is given the file without its thrusters.
            Ok(Rotors {
                spacecraft,
                source: (text, name),
                speeds,
            })
        })
        .transpose()?;
    if lines.as_ref().is_some_and(|l| l.len() != rows.len()) {
        return Err(value_error("lines: one per sample"));
    }
    let samples = rows
        .iter()
        .map(|r| Sample {
            t_s: r.t,
            q: inertia::attitude::Quaternion::from_xyzw(r.q),
            rho_nms: r.rho.into(),
            tau_nm: r.tau.unwrap_or_default().into(),
            omega_rad_s: r.w.map(Into::into),
            external: External {
                position_m: r.external.position_m.map(Into::into),
                field_t: r.external.field_t.map(Into::into),
                force_n: r.external.force_n.map(Into::into),
            },
        })
        .collect();
    let (rows_read, renormalised, sign_flips, min_step_s, max_step_s, attitude_from_gyro) = stats;
    Ok(Telemetry {
        samples,
        lines,
        file,
        stats: Stats {
            rows: rows_read,
            renormalised,
            sign_flips,
            min_step_s,
            max_step_s,
            rejected: 0,
            attitude_from_gyro,
        },
        q_columns,
        label,
        rotors,
    })
}

/// The registered estimators: `(name, summary)`.
#[pyfunction]
fn estimators() -> Vec<(&'static str, &'static str)> {
    inertia::pipeline::registry::ESTIMATORS
        .iter()
        .map(|e| (e.name, e.summary))
        .collect()
}

#[pymodule]
fn _inertia(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("DataError", m.py().get_type::<DataError>())?;
    m.add(
        "DEFAULT_ESTIMATOR",
        inertia::pipeline::PipelineSettings::DEFAULT_ESTIMATOR,
    )?;
    m.add("SETTINGS_KEYS", RunDescription::SETTINGS_KEYS.to_vec())?;
    m.add("INPUT_KEYS", RunDescription::INPUT_KEYS.to_vec())?;
    m.add_class::<Telemetry>()?;
    m.add_class::<stream::Stream>()?;
    m.add_function(wrap_pyfunction!(read_csv, m)?)?;
    m.add_function(wrap_pyfunction!(estimate_arrays, m)?)?;
    m.add_function(wrap_pyfunction!(estimate_records, m)?)?;
    m.add_function(wrap_pyfunction!(samples_from_arrays, m)?)?;
    m.add_function(wrap_pyfunction!(estimators, m)?)?;
    m.add_function(wrap_pyfunction!(restore, m)?)?;
    m.add_function(wrap_pyfunction!(sim::simulate, m)?)?;
    m.add_function(wrap_pyfunction!(plan::plan, m)?)?;
    Ok(())
}
