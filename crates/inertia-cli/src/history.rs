//! The estimate history file (`-o`): the library's CSV history
//! ([`inertia::pipeline::history`]) written to a file.

use crate::error::{write_failed, CliError};
use inertia::estimator::Estimate;
use inertia::pipeline::history::HistoryWriter;
use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};

/// A history file being written.
pub struct HistoryFile {
    w: HistoryWriter<BufWriter<File>>,
    path: PathBuf,
}

impl HistoryFile {
    /// Create the file and write the header.
    pub fn create(path: &Path) -> Result<Self, CliError> {
        let f = File::create(path).map_err(|e| write_failed(path, e))?;
        let w = HistoryWriter::new(BufWriter::new(f)).map_err(|e| write_failed(path, e))?;
        Ok(Self {
            w,
            path: path.to_path_buf(),
        })
    }

    /// Append one estimate.
    pub fn write(&mut self, e: &Estimate) -> Result<(), CliError> {
        self.w.write(e).map_err(|err| write_failed(&self.path, err))
    }

    /// Flush to disk.
    pub fn finish(self) -> Result<(), CliError> {
        self.w
            .finish()
            .map(drop)
            .map_err(|e| write_failed(&self.path, e))
    }
}
