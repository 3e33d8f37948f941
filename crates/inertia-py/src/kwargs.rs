//! Keyword arguments taken out one by one (`simulate`'s; the run settings map onto the
//! library's run description instead, `crate::settings`). Bad values raise `ValueError`
//! (or `TypeError` for a wrong type) naming the argument.

use crate::errors::{type_error, value_error};
use inertia::text::Num;
use nalgebra::Matrix3;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyString};

/// Keyword arguments, taken out one by one; what is left over is an error.
pub struct Kwargs<'py> {
    dict: Bound<'py, PyDict>,
    function: &'static str,
}

impl<'py> Kwargs<'py> {
    pub fn new(
        dict: Option<&Bound<'py, PyDict>>,
        py: Python<'py>,
        function: &'static str,
    ) -> PyResult<Self> {
        let dict = match dict {
            Some(d) => d.copy()?,
            None => PyDict::new(py),
        };
        Ok(Self { dict, function })
    }

    /// The keyword arguments not taken yet.
    pub fn dict(&self) -> &Bound<'py, PyDict> {
        &self.dict
    }

    /// The value of `name`, `None` when absent or `None`.
    pub fn take(&self, name: &str) -> PyResult<Option<Bound<'py, PyAny>>> {
        let v = self.dict.get_item(name)?;
        if v.is_some() {
            self.dict.del_item(name)?;
        }
        Ok(v.filter(|v| !v.is_none()))
    }

    pub fn f64(&self, name: &str) -> PyResult<Option<f64>> {
        self.take(name)?
            .map(|v| {
                if v.is_instance_of::<PyString>() {
                    return Err(type_error(format!(
                        "{name}: expected a number, got a string {v}"
                    )));
                }
                v.extract::<f64>().map_err(|_| {
                    type_error(format!("{name}: expected a number, got {}", type_name(&v)))
                })
            })
            .transpose()
    }

    pub fn finite(&self, name: &str) -> PyResult<Option<f64>> {
        match self.f64(name)? {
            Some(v) if !v.is_finite() => {
                Err(value_error(format!("{name}={}: must be finite", Num(v))))
            }
            v => Ok(v),
        }
    }

    pub fn bool(&self, name: &str, default: bool) -> PyResult<bool> {
        self.take(name)?
            .map(|v| {
                v.extract::<bool>().map_err(|_| {
                    type_error(format!(
                        "{name}: expected True or False, got {}",
                        type_name(&v)
                    ))
                })
            })
            .transpose()
            .map(|v| v.unwrap_or(default))
    }

    pub fn string(&self, name: &str) -> PyResult<Option<String>> {
        self.take(name)?
            .map(|v| {
                v.extract::<String>().map_err(|_| {
                    type_error(format!("{name}: expected a string, got {}", type_name(&v)))
                })
            })
            .transpose()
    }

    /// One of `choices` (`-` and `_` alike).
    pub fn choice(&self, name: &str, choices: &[&'static str]) -> PyResult<Option<&'static str>> {
        let Some(s) = self.string(name)? else {
            return Ok(None);
        };
        let norm = s.replace('_', "-");
        choices
            .iter()
            .find(|c| **c == norm)
            .copied()
            .map(Some)
            .ok_or_else(|| {
                value_error(format!(
                    "{name}={s:?}: expected one of {}",
                    choices.join(", ")
                ))
            })
    }

    /// Three numbers.
    pub fn vector(&self, name: &str) -> PyResult<Option<[f64; 3]>> {
        self.numbers::<3>(name)
    }

    pub fn numbers<const N: usize>(&self, name: &str) -> PyResult<Option<[f64; N]>> {
        self.take(name)?
            .map(|v| {
                let xs: Vec<f64> = v.extract().map_err(|_| {
                    type_error(format!(
                        "{name}: expected {N} numbers, got {}",
                        type_name(&v)
                    ))
                })?;
                let arr: [f64; N] = xs.clone().try_into().map_err(|_| {
                    value_error(format!("{name}: expected {N} numbers, got {}", xs.len()))
                })?;
                if arr.iter().all(|x| x.is_finite()) {
                    Ok(arr)
                } else {
                    Err(value_error(format!("{name}: expected {N} finite numbers")))
                }
            })
            .transpose()
    }

    /// A 3×3 symmetric, finite matrix, kg m².
    pub fn matrix(&self, name: &str) -> PyResult<Option<Matrix3<f64>>> {
        self.take(name)?.map(|v| matrix_value(name, &v)).transpose()
    }

    /// No keyword left: an unknown one is a `TypeError`, as Python raises it.
    pub fn finish(self) -> PyResult<()> {
        if let Some((k, _)) = self.dict.iter().next() {
            return Err(type_error(format!(
                "{}() got an unexpected keyword argument {}",
                self.function,
                k.repr()?
            )));
        }
        Ok(())
    }
}

/// A 3×3 symmetric, finite matrix.
fn matrix_value(name: &str, v: &Bound<'_, PyAny>) -> PyResult<Matrix3<f64>> {
    let rows: Vec<Vec<f64>> = v.extract().map_err(|_| {
        type_error(format!(
            "{name}: expected a 3×3 matrix of numbers, got {}",
            type_name(v)
        ))
    })?;
    if rows.len() != 3 || rows.iter().any(|r| r.len() != 3) {
        return Err(value_error(format!("{name}: expected a 3×3 matrix")));
    }
    let m = Matrix3::from_fn(|r, c| rows[r][c]);
    if !m.iter().all(|x| x.is_finite()) {
        return Err(value_error(format!("{name}: has non-finite entries")));
    }
    if (m - m.transpose()).norm() > 1e-9 * m.norm() {
        return Err(value_error(format!("{name}: is not symmetric")));
    }
    Ok(m)
}

pub fn type_name(v: &Bound<'_, PyAny>) -> String {
    v.get_type()
        .name()
        .map_or_else(|_| "an object".into(), |n| n.to_string())
}
