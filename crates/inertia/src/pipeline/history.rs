//! Estimate histories as CSV (feature `csv`), schema version [`SCHEMA_VERSION`]:
//!
//! ```text
//! t,J11,J22,J33,J12,J13,J23,status,condition,iterations,sJ11,sJ22,sJ33,sJ12,sJ13,sJ23,reason
//! ```
//!
//! `t` in s; `J..` and the standard deviations `sJ..` in kg m² (products are tensor
//! entries, `J12 = −Σ m x y`); `status` is [`Observability::code`]; `condition` is
//! `σ_1/σ_6` of `R` when determined; `iterations` the solver's; `reason` says why the
//! data fall short, when they do. Empty fields mean "not available". Floats are written
//! in the shortest form that reads back to the same value.
//!
//! [`Observability::code`]: crate::estimator::observability::Observability::code

use crate::estimator::Estimate;
use std::io::Write;

/// Version of the history columns; it changes whenever a column is added, removed or
/// changes meaning.
pub const SCHEMA_VERSION: u32 = 1;

/// The header.
pub const HEADER: [&str; 17] = [
    "t",
    "J11",
    "J22",
    "J33",
    "J12",
    "J13",
    "J23",
    "status",
    "condition",
    "iterations",
    "sJ11",
    "sJ22",
    "sJ33",
    "sJ12",
    "sJ13",
    "sJ23",
    "reason",
];

/// A history being written.
pub struct HistoryWriter<W: Write> {
    w: csv::Writer<W>,
    buf: ryu::Buffer,
    reason: std::string::String,
}

impl<W: Write> HistoryWriter<W> {
    /// Write the header to `out`.
    pub fn new(out: W) -> Result<Self, csv::Error> {
        let mut w = csv::Writer::from_writer(out);
        w.write_record(HEADER)?;
        Ok(Self {
            w,
            buf: ryu::Buffer::new(),
            reason: std::string::String::new(),
        })
    }

    /// Append one estimate (no allocation per field).
    pub fn write(&mut self, e: &Estimate) -> Result<(), csv::Error> {
        use core::fmt::Write as _;
        let buf = &mut self.buf;
        let w = &mut self.w;
        let mut field = |w: &mut csv::Writer<W>, v: Option<f64>| match v {
            Some(v) if v.is_finite() => w.write_field(buf.format_finite(v)),
            _ => w.write_field(b""),
        };
        let j = e.j();
        let sigma = e.sigma_kg_m2();
        field(w, Some(e.t_s))?;
        for k in 0..6 {
            field(w, j.map(|j| j[k]))?;
        }
        w.write_field(e.observability.code())?;
        field(w, e.observability.condition())?;
        field(w, e.solution.map(|s| f64::from(s.iterations)))?;
        for k in 0..6 {
            field(w, sigma.map(|s| s[k]))?;
        }
        self.reason.clear();
        if let Some(r) = e.observability.reason() {
            let _ = write!(self.reason, "{r}");
        }
        w.write_field(&self.reason)?;
        w.write_record(None::<&[u8]>)
    }

    /// Flush and return the writer.
    pub fn finish(self) -> Result<W, csv::Error> {
        self.w
            .into_inner()
            .map_err(|e| csv::Error::from(std::io::Error::other(e.to_string())))
    }
}
