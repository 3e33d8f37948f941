//! The streaming estimator: samples pushed one at a time (or in blocks) into one
//! `inertia::pipeline::Pipeline`, checked as the CSV reader checks rows.

use crate::errors::Failure;
use crate::run::check_against_step;
use crate::samples::{Checker, Naming, Row};
use crate::settings::{self, Convention, Kwargs};
use inertia::pipeline::report::{InputSummary, Report};
use inertia::pipeline::{Pipeline, PipelineConfig, PipelineError};
use numpy::PyReadonlyArrayDyn;
use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::sync::Mutex;

struct State {
    pipeline: Pipeline,
    config: PipelineConfig,
    checker: Checker,
    /// Input samples accepted.
    index: usize,
    first_t: [f64; 2],
    gyro: Option<bool>,
    /// The error that stopped the estimator.
    stopped: Option<String>,
}

/// A streaming estimator (the Python `inertia.Estimator` wraps it).
#[pyclass(module = "inertia._inertia")]
pub struct Stream {
    state: Mutex<State>,
    conv: Convention,
}

impl State {
    fn push(&mut self, row: &Row, conv: &Convention) -> Result<bool, Failure> {
        if let Some(m) = &self.stopped {
            return Err(Failure::Argument(format!(
                "the estimator stopped on an earlier error ({m}); create a new Estimator"
            )));
        }
        let i = self.index;
        let has_w = row.w.is_some();
        match self.gyro {
            None => {
                let entry = self.config.estimator();
                if entry.capabilities.needs_gyro && !has_w {
                    return Err(Failure::Argument(format!(
                        "w: the {} estimator needs gyro rates (w_x,w_y,w_z)",
                        entry.name
                    )));
                }
            }
            Some(g) if g != has_w => {
                return Err(Failure::Argument(format!(
                    "w: sample {i}: gyro rates {} here but {} for the earlier samples",
                    if has_w { "given" } else { "missing" },
                    if g { "given" } else { "missing" },
                )))
            }
            Some(_) => {}
        }
        let s = self
            .checker
            .sample(row, i, conv, &Naming::Arrays)
            .map_err(|m| Failure::Data(m, None))?;
        if i < 2 {
            self.first_t[i] = s.t_s;
        }
        if i == 1 {
            check_against_step(&self.config, s.t_s - self.first_t[0], "sample 1")?;
        }
        let mut produced = false;
        let r = self.pipeline.push_each(&s, |_| produced = true);
        self.gyro = Some(has_w);
        self.index += 1;
        if let Err(e) = r {
            let m = data_message(e, i);
            self.stopped = Some(m.clone());
            return Err(Failure::Data(m, None));
        }
        Ok(produced)
    }

    fn report(&self) -> Option<Report> {
        let st = self.checker.stats;
        Report::of_pipeline(&self.pipeline).map(|r| {
            r.with_input(InputSummary {
                file: "<stream>".into(),
                sample_period_s: self
                    .config
                    .resample_s()
                    .unwrap_or(self.first_t[1] - self.first_t[0]),
                renormalised: st.renormalised,
                sign_flips: st.sign_flips,
                min_step_s: st.min_step_s,
                max_step_s: st.max_step_s,
            })
        })
    }
}

fn data_message(e: PipelineError, i: usize) -> String {
    crate::run::python_options(match e {
        PipelineError::Estimator {
            source: inertia::estimator::EstimatorError::Solve(s),
            ..
        } => format!("sample {i}: the solver failed on these data: {s}"),
        other => format!("sample {i}: {other}"),
    })
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
        let conv = settings::convention(&kw)?;
        let pipeline_settings = settings::pipeline(&kw)?;
        kw.finish()?;
        let config = pipeline_settings
            .validate()
            .map_err(settings::settings_error)?;
        let pipeline = Pipeline::from_config(config).map_err(settings::settings_error)?;
        Ok(Self {
            state: Mutex::new(State {
                pipeline,
                config,
                checker: Checker::default(),
                index: 0,
                first_t: [f64::NAN; 2],
                gyro: None,
                stopped: None,
            }),
            conv,
        })
    }

    /// Push one sample; `True` when it produced an estimate.
    #[pyo3(signature = (t, q, rho, tau=None, w=None))]
    fn push(
        &self,
        py: Python<'_>,
        t: f64,
        q: [f64; 4],
        rho: [f64; 3],
        tau: Option<[f64; 3]>,
        w: Option<[f64; 3]>,
    ) -> PyResult<bool> {
        let row = Row { t, q, rho, tau, w };
        let mut guard = self.lock()?;
        let st: &mut State = &mut guard;
        let conv = self.conv;
        py.allow_threads(|| st.push(&row, &conv))
            .map_err(|f| f.into_py(py))
    }

    /// Push a block of samples (arrays as for `estimate`); the number of estimates made.
    #[pyo3(signature = (t, q, rho, tau=None, w=None))]
    fn push_many<'py>(
        &self,
        py: Python<'py>,
        t: PyReadonlyArrayDyn<'py, f64>,
        q: PyReadonlyArrayDyn<'py, f64>,
        rho: PyReadonlyArrayDyn<'py, f64>,
        tau: Option<PyReadonlyArrayDyn<'py, f64>>,
        w: Option<PyReadonlyArrayDyn<'py, f64>>,
    ) -> PyResult<usize> {
        let rows = crate::rows(&t, &q, &rho, tau.as_ref(), w.as_ref())?;
        let mut guard = self.lock()?;
        let st: &mut State = &mut guard;
        let conv = self.conv;
        py.allow_threads(|| {
            let mut n = 0;
            for r in &rows {
                n += usize::from(st.push(r, &conv)?);
            }
            Ok(n)
        })
        .map_err(|f: Failure| f.into_py(py))
    }

    /// `(report JSON, report text)` of the newest estimate, or None before one.
    fn report(&self) -> PyResult<Option<(String, String)>> {
        let st = self.lock()?;
        st.report()
            .map(|r| {
                serde_json::to_string(&r)
                    .map(|j| (j, r.to_string()))
                    .map_err(|e| PyRuntimeError::new_err(e.to_string()))
            })
            .transpose()
    }

    /// Input samples accepted so far.
    #[getter]
    fn samples(&self) -> PyResult<usize> {
        Ok(self.lock()?.index)
    }

    /// The estimator's name.
    #[getter]
    fn estimator(&self) -> PyResult<&'static str> {
        Ok(self.lock()?.config.estimator().name)
    }
}
