//! Estimate histories as CSV: `t,J11,J22,J33,J12,J13,J23,status,condition,iterations,reason`.

use crate::error::{write_failed, CliError};
use crate::runner::HistoryRow;
use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};

/// The header.
pub const HEADER: [&str; 11] = [
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
    "reason",
];

/// A history file being written.
pub struct HistoryWriter {
    w: csv::Writer<BufWriter<File>>,
    path: PathBuf,
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
        })
    }

    /// Append one row.
    pub fn write(&mut self, r: &HistoryRow) -> Result<(), CliError> {
        let mut rec: Vec<String> = Vec::with_capacity(HEADER.len());
        rec.push(r.t_s.to_string());
        for k in 0..6 {
            rec.push(r.j.map_or(String::new(), |j| j[k].to_string()));
        }
        rec.push(r.status.code().to_string());
        rec.push(r.condition.map_or(String::new(), |c| c.to_string()));
        rec.push(r.iterations.map_or(String::new(), |c| c.to_string()));
        rec.push(r.status.reason().unwrap_or("").to_string());
        self.w
            .write_record(&rec)
            .map_err(|e| write_failed(&self.path, e))
    }

    /// Flush to disk.
    pub fn finish(mut self) -> Result<(), CliError> {
        self.w.flush().map_err(|e| write_failed(&self.path, e))
    }
}
