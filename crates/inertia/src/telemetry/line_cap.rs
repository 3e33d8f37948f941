//! A reader that fails as soon as a line grows longer than a limit, so that a file
//! without line breaks is refused after [`super::csv::MAX_LINE_BYTES`] bytes instead of
//! being read into memory.

use std::io::{self, Read};

/// The error payload of a line over the limit (found by downcasting the I/O error).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct LineTooLong {
    /// The 1-based physical line.
    pub line: u64,
    /// The limit, bytes.
    pub limit: usize,
}

impl std::fmt::Display for LineTooLong {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "line {} is longer than {} bytes", self.line, self.limit)
    }
}

impl std::error::Error for LineTooLong {}

/// Counts bytes since the last `\n` and fails past `limit`.
pub(crate) struct LineCap<R> {
    inner: R,
    limit: usize,
    run: usize,
    newlines: u64,
}

impl<R: Read> LineCap<R> {
    pub(crate) fn new(inner: R, limit: usize) -> Self {
        Self {
            inner,
            limit,
            run: 0,
            newlines: 0,
        }
    }
}

impl<R: Read> Read for LineCap<R> {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        let n = self.inner.read(buf)?;
        let chunk = &buf[..n];
        match chunk.iter().rposition(|&b| b == b'\n') {
            Some(last) => {
                // The line that ended in this chunk.
                let first = chunk.iter().position(|&b| b == b'\n').unwrap_or(last);
                if self.run + first > self.limit {
                    return Err(self.too_long());
                }
                self.newlines += chunk.iter().filter(|&&b| b == b'\n').count() as u64;
                self.run = n - 1 - last;
            }
            None => self.run += n,
        }
        if self.run > self.limit {
            return Err(self.too_long());
        }
        Ok(n)
    }
}

impl<R> LineCap<R> {
    fn too_long(&self) -> io::Error {
        io::Error::new(
            io::ErrorKind::InvalidData,
            LineTooLong {
                line: self.newlines + 1,
                limit: self.limit,
            },
        )
    }
}
