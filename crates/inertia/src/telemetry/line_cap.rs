//! A reader that fails as soon as a line grows longer than a limit, so that a file
//! without line breaks is refused after [`super::csv::MAX_LINE_BYTES`] bytes instead of
//! being read into memory; and that numbers the lines with content, because the `csv`
//! crate's record positions are a line short after a CRLF line end (rust-csv #395) and
//! name the blank line before a record instead of the record's own (#208).

use std::collections::VecDeque;
use std::io::{self, Read};

/// The error payload of a line over the limit (found by downcasting the I/O error).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct LineTooLong {
    /// The 1-based physical line.
    pub(crate) line: u64,
    /// The limit, bytes.
    pub(crate) limit: usize,
}

impl std::fmt::Display for LineTooLong {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "line {} is longer than {} bytes", self.line, self.limit)
    }
}

impl std::error::Error for LineTooLong {}

/// Counts bytes since the last `\n` and fails past `limit`; keeps the numbers of the
/// lines with content (a byte other than `\r`) that no record has claimed yet.
pub(crate) struct LineCap<R> {
    inner: R,
    limit: usize,
    run: usize,
    newlines: u64,
    /// Whether the line being read has content so far.
    content: bool,
    /// Lines with content read ahead of the records, in order (bounded by the CSV
    /// reader's buffer).
    pending: VecDeque<u64>,
}

impl<R: Read> LineCap<R> {
    pub(crate) fn new(inner: R, limit: usize) -> Self {
        Self {
            inner,
            limit,
            run: 0,
            newlines: 0,
            content: false,
            pending: VecDeque::new(),
        }
    }

    /// The 1-based line of the next record (the CSV reader skips blank lines, and a
    /// record here is one line: fields hold no line breaks).
    pub(crate) fn claim_line(&mut self) -> Option<u64> {
        self.pending.pop_front()
    }
}

impl<R: Read> Read for LineCap<R> {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        let n = self.inner.read(buf)?;
        let chunk = &buf[..n];
        if n == 0 && self.content {
            // The last line, without a line break.
            self.pending.push_back(self.newlines + 1);
            self.content = false;
        }
        let mut line = self.newlines + 1;
        for &b in chunk {
            if b == b'\n' {
                if self.content {
                    self.pending.push_back(line);
                }
                line += 1;
                self.content = false;
            } else if b != b'\r' {
                self.content = true;
            }
        }
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
