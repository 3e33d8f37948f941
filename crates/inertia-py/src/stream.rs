//! The streaming estimator: samples pushed one at a time (or in blocks) into one
//! `inertia::pipeline::Run`, checked as the CSV reader checks rows; `finish` ends the
//! input as `estimate()` does.

use crate::errors::Failure;
use crate::kwargs::Kwargs;
use crate::run::Origin;
use crate::samples::{Checker, Naming, Row};
use crate::settings;
use inertia::pipeline::report::Report;
use inertia::pipeline::Run;
use inertia::telemetry::gate::RawExternal;
use numpy::PyReadonlyArrayDyn;
use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::sync::Mutex;

struct State {
    run: Run,
    checker: Checker,
}

/// A streaming estimator (the Python `inertia.Estimator` wraps it).
#[pyclass(module = "inertia._inertia")]
pub struct Stream {
    state: Mutex<State>,
}

impl State {
    fn push(&mut self, row: &Row) -> Result<bool, Failure> {
        let i = self.run.input_samples();
        let s = self.checker.sample(row, i, &Naming::Arrays)?;
        let mut produced = false;
        self.run
            .push(&s, |_| produced = true)
            .map_err(|e| Origin::arrays().run_error(&e))?;
        Ok(produced)
    }

    /// End of input: the run's last answer, widened by what only the whole input gives
    /// (the held wheel speeds' lag term); `true` when that gave one more estimate.
    fn finish(&mut self) -> Result<bool, Failure> {
        let mut produced = false;
        self.run
            .finish(|_| produced = true)
            .map_err(|e| Origin::arrays().run_error(&e))?;
        Ok(produced)
    }

    fn report(&self) -> Option<Report> {
        self.run.report("<stream>", &self.checker.stats())
    }
}

impl Stream {
    fn lock(&self) -> PyResult<std::sync::MutexGuard<'_, State>> {
        self.state
            .lock()
            .map_err(|_| PyRuntimeError::new_err("the estimator's state was poisoned by a panic"))
    }
}

#[pymethods]
impl Stream {
    #[new]
    #[pyo3(signature = (kwargs=None))]
    fn new(py: Python<'_>, kwargs: Option<&Bound<'_, PyDict>>) -> PyResult<Self> {
        let kw = Kwargs::new(kwargs, py, "Estimator")?;
        let d = settings::describe(&kw, "Estimator")?;
        if d.batch.is_some() {
            return Err(crate::errors::type_error(
                "Estimator() got an unexpected keyword argument 'batch'",
            ));
        }
        let conv = settings::convention(&d)?;
        let pipeline_settings = settings::pipeline(&d)?;
        if pipeline_settings.wheel_delay != Default::default() {
            return Err(crate::errors::value_error(
                "wheel_delay: the wheel speeds' time tag needs the whole record; give it to estimate()",
            ));
        }
        let config = pipeline_settings
            .validate()
            .map_err(settings::settings_error)?;
        let run = Run::new(config, false).map_err(settings::settings_error)?;
        Ok(Self {
            state: Mutex::new(State {
                run,
                checker: Checker::new(&conv),
            }),
        })
    }

    /// Push one sample; `True` when it produced an estimate.
    #[pyo3(signature = (t, q, rho, tau=None, w=None, r=None, b=None, f=None, dipole=None))]
    #[allow(clippy::too_many_arguments)]
    fn push(
        &self,
        py: Python<'_>,
        t: f64,
        q: [f64; 4],
        rho: [f64; 3],
        tau: Option<[f64; 3]>,
        w: Option<[f64; 3]>,
        r: Option<[f64; 3]>,
        b: Option<[f64; 3]>,
        f: Option<[f64; 3]>,
        dipole: Option<[f64; 3]>,
    ) -> PyResult<bool> {
        let row = Row {
            t,
            q,
            rho,
            tau,
            w,
            external: RawExternal {
                position_m: r,
                field_t: b,
                force_n: f,
                dipole_am2: dipole,
            },
        };
        let mut guard = self.lock()?;
        let st: &mut State = &mut guard;
        py.allow_threads(|| st.push(&row))
            .map_err(|f| f.into_py(py))
    }

    /// Push a block of samples (arrays as for `estimate`); the number of estimates made.
    #[pyo3(signature = (t, q, rho, tau=None, w=None, r=None, b=None, f=None, dipole=None))]
    #[allow(clippy::too_many_arguments)]
    fn push_many<'py>(
        &self,
        py: Python<'py>,
        t: PyReadonlyArrayDyn<'py, f64>,
        q: PyReadonlyArrayDyn<'py, f64>,
        rho: PyReadonlyArrayDyn<'py, f64>,
        tau: Option<PyReadonlyArrayDyn<'py, f64>>,
        w: Option<PyReadonlyArrayDyn<'py, f64>>,
        r: Option<PyReadonlyArrayDyn<'py, f64>>,
        b: Option<PyReadonlyArrayDyn<'py, f64>>,
        f: Option<PyReadonlyArrayDyn<'py, f64>>,
        dipole: Option<PyReadonlyArrayDyn<'py, f64>>,
    ) -> PyResult<usize> {
        let external = [r.as_ref(), b.as_ref(), f.as_ref(), dipole.as_ref()];
        let rows = crate::rows(&t, Some(&q), &rho, tau.as_ref(), w.as_ref(), external)?;
        let mut guard = self.lock()?;
        let st: &mut State = &mut guard;
        py.allow_threads(|| {
            let mut n = 0;
            for r in &rows {
                n += usize::from(st.push(r)?);
            }
            Ok(n)
        })
        .map_err(|f: Failure| f.into_py(py))
    }

    /// End of input (`State::finish`); `True` when it gave one more estimate.
    fn finish(&self, py: Python<'_>) -> PyResult<bool> {
        let mut guard = self.lock()?;
        let st: &mut State = &mut guard;
        py.allow_threads(|| st.finish()).map_err(|f| f.into_py(py))
    }

    /// `(report JSON, report text)` of the newest estimate, or None before one.
    fn report(&self) -> PyResult<Option<(String, String)>> {
        let st = self.lock()?;
        st.report()
            .map(|r| {
                serde_json::to_string(&r)
                    .map(|j| (j, r.text(crate::run::keyword_names, "keyword").to_string()))
                    .map_err(|e| PyRuntimeError::new_err(e.to_string()))
            })
            .transpose()
    }

    /// Input samples accepted so far.
    #[getter]
    fn samples(&self) -> PyResult<usize> {
        Ok(self.lock()?.run.input_samples())
    }

    /// The estimator's name.
    #[getter]
    fn estimator(&self) -> PyResult<&'static str> {
        Ok(self.lock()?.run.config().estimator().name)
    }
}
