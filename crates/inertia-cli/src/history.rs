//! Estimate histories as CSV:
//! `t,J11,J22,J33,J12,J13,J23,status,condition,iterations,sJ11,…,sJ23,reason` (the `s`
//! columns are standard deviations, kg m², of the variational estimator).

use crate::error::{write_failed, CliError};
use crate::runner::HistoryRow;
use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};

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

/// A history file being written.
pub struct HistoryWriter {
    w: csv::Writer<BufWriter<File>>,
    path: PathBuf,
    buf: ryu::Buffer,
}

impl HistoryWriter {
    /// Create the file and write the header.
    pub fn create(path: &Path) -> Result<Self, CliError> {
        let f = File::create(path).map_err(|e| write_failed(path, e))?;
        let mut w = csv::Writer::from_writer(BufWriter::new(f));
        w.write_record(HEADER).map_err(|e| write_failed(path, e))?;
        Ok(Self {
            w,
            path: path.to_path_buf(),
            buf: ryu::Buffer::new(),
        })
    }

    /// Append one row (shortest round-trip float formatting, no allocation per field).
    pub fn write(&mut self, r: &HistoryRow) -> Result<(), CliError> {
        let buf = &mut self.buf;
        let mut field = |w: &mut csv::Writer<BufWriter<File>>, v: Option<f64>| match v {
            Some(v) if v.is_finite() => w.write_field(buf.format_finite(v)),
            _ => w.write_field(b""),
        };
        let res = (|| {
            field(&mut self.w, Some(r.t_s))?;
            for k in 0..6 {
                field(&mut self.w, r.j.map(|j| j[k]))?;
            }
            self.w.write_field(r.status.code())?;
            field(&mut self.w, r.condition)?;
            field(&mut self.w, r.iterations.map(f64::from))?;
            for k in 0..6 {
                field(&mut self.w, r.uncertainty.map(|u| u.sigma_kg_m2[k]))?;
            }
            self.w.write_field(r.status.reason().unwrap_or(""))?;
            self.w.write_record(None::<&[u8]>)
        })();
        res.map_err(|e| write_failed(&self.path, e))
    }

    /// Flush to disk.
    pub fn finish(mut self) -> Result<(), CliError> {
        self.w.flush().map_err(|e| write_failed(&self.path, e))
    }
}
