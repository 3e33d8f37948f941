//! The estimate history file (`-o`): the library's CSV history
//! ([`inertia::pipeline::history`]) written to a file on its own thread
//! ([`WriteBehind`]), put in place only when the run succeeds
//! ([`crate::output::Pending`]).

use crate::error::{write_failed, CliError};
use crate::output::{Pending, Synced};
use inertia::estimator::Estimate;
use inertia::pipeline::history::WriteBehind;
use std::io::BufWriter;
use std::path::Path;

/// A history file being written.
pub struct HistoryFile {
    w: WriteBehind<BufWriter<Synced>>,
    pending: Pending,
}

impl HistoryFile {
    /// Create the (temporary) file and write the header.
    pub fn create(path: &Path) -> Result<Self, CliError> {
        let (pending, f) = Pending::create(path)?;
        let w = WriteBehind::new(f).map_err(|e| write_failed(path, e))?;
        Ok(Self { w, pending })
    }

    /// Append one estimate.
    pub fn write(&mut self, e: &Estimate) -> Result<(), CliError> {
        self.w
            .write(e)
            .map_err(|err| write_failed(self.pending.path(), err))
    }

    /// Flush and move the file into place.
    pub fn finish(self) -> Result<(), CliError> {
        let f = self
            .w
            .finish()
            .map_err(|e| write_failed(self.pending.path(), e))?;
        self.pending.commit(f)
    }
}
