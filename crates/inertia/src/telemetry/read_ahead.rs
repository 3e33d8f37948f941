//! Reading a CSV file on a second thread while the estimator runs on the first.
//!
//! Parsing the CSV is about a tenth of the time of a long file's estimate; a
//! [`ReadAhead`] moves it to a reader thread that fills batches of
//! `BATCH_SAMPLES` (512) samples into a bounded channel of `BATCHES_AHEAD` (8) batches, so
//! memory stays fixed whatever the file's length. It yields exactly what the
//! [`TelemetryReader`] would, in order, each item with the line it came from; the reader
//! stops at its first error, as the reader does. Dropping a `ReadAhead` early (an
//! estimator error) stops the thread at its next batch.

use super::csv::{ReadStats, TelemetryError, TelemetryReader};
use crate::sample::Sample;
use std::collections::vec_deque::VecDeque;
use std::io::Read;
use std::sync::mpsc::{sync_channel, Receiver};
use std::thread::JoinHandle;

/// Samples per batch handed from the reader thread to the estimator.
pub(crate) const BATCH_SAMPLES: usize = 512;

/// Batches the reader thread may be ahead (bounded memory).
pub(crate) const BATCHES_AHEAD: usize = 8;

/// One item of the reader, with the line it ended on and the bytes consumed by then.
struct Item {
    sample: Result<Sample, TelemetryError>,
    line: u64,
    byte_position: u64,
    /// The rotors' speeds ([`TelemetryReader::last_speeds`]; empty without them).
    speeds: Vec<f64>,
    /// The thrusters' throttles ([`TelemetryReader::last_throttles`]).
    throttles: Vec<f64>,
}

/// A [`TelemetryReader`] running on its own thread ([module docs](self)).
pub struct ReadAhead {
    batches: Receiver<Vec<Item>>,
    current: VecDeque<Item>,
    thread: Option<JoinHandle<ReadStats>>,
    last_line: u64,
    byte_position: u64,
    speeds: Vec<f64>,
    throttles: Vec<f64>,
}

impl ReadAhead {
    /// Start reading `reader` on a new thread.
    #[must_use]
    pub fn new<R: Read + Send + 'static>(mut reader: TelemetryReader<R>) -> Self {
        let (tx, batches) = sync_channel(BATCHES_AHEAD);
        let thread = std::thread::spawn(move || {
            let mut batch = Vec::with_capacity(BATCH_SAMPLES);
            while let Some(sample) = reader.next() {
                batch.push(Item {
                    sample,
                    line: reader.last_line(),
                    byte_position: reader.byte_position(),
                    speeds: reader.last_speeds().to_vec(),
                    throttles: reader.last_throttles().to_vec(),
                });
                if batch.len() == BATCH_SAMPLES {
                    let full = core::mem::replace(&mut batch, Vec::with_capacity(BATCH_SAMPLES));
                    if tx.send(full).is_err() {
                        // The estimator stopped listening.
                        return reader.stats();
                    }
                }
            }
            if !batch.is_empty() {
                let _ = tx.send(batch);
            }
            reader.stats()
        });
        Self {
            batches,
            current: VecDeque::new(),
            thread: Some(thread),
            last_line: 0,
            byte_position: 0,
            speeds: Vec::new(),
            throttles: Vec::new(),
        }
    }

    /// Line (1-based) of the last item returned, as [`TelemetryReader::last_line`].
    #[must_use]
    pub fn last_line(&self) -> u64 {
        self.last_line
    }

    /// The rotors' speeds of the last item returned, as
    /// [`TelemetryReader::last_speeds`].
    #[must_use]
    pub fn last_speeds(&self) -> &[f64] {
        &self.speeds
    }

    /// The thrusters' throttles of the last item returned, as
    /// [`TelemetryReader::last_throttles`].
    #[must_use]
    pub fn last_throttles(&self) -> &[f64] {
        &self.throttles
    }

    /// Bytes consumed up to the last item returned (for progress reporting).
    #[must_use]
    pub fn byte_position(&self) -> u64 {
        self.byte_position
    }

    /// The reader's counts once every item has been returned, as
    /// [`TelemetryReader::stats`]. `None` if the reader thread panicked (a bug).
    #[must_use]
    pub fn finish(mut self) -> Option<ReadStats> {
        // Drain, so that a thread blocked on a full channel can end.
        drop(core::mem::replace(&mut self.batches, sync_channel(0).1));
        self.thread.take()?.join().ok()
    }
}

impl Iterator for ReadAhead {
    type Item = Result<Sample, TelemetryError>;

    fn next(&mut self) -> Option<Self::Item> {
        if self.current.is_empty() {
            // A closed channel is the end of the file (or a reader that stopped).
            self.current = self.batches.recv().ok()?.into();
        }
        let item = self.current.pop_front()?;
        self.last_line = item.line;
        self.byte_position = item.byte_position;
        self.speeds = item.speeds;
        self.throttles = item.throttles;
        Some(item.sample)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::telemetry::csv::{write_samples, CsvOptions};

    fn samples(n: usize) -> Vec<Sample> {
        (0..n)
            .map(|k| Sample {
                t_s: k as f64 * 0.1,
                q: crate::attitude::Quaternion::IDENTITY,
                rho_nms: nalgebra::Vector3::new(k as f64, 0.5, -1.0),
                tau_nm: nalgebra::Vector3::zeros(),
                omega_rad_s: None,
                external: Default::default(),
            })
            .collect()
    }

    fn csv_of(samples: &[Sample]) -> Vec<u8> {
        let mut out = Vec::new();
        write_samples(&mut out, samples).unwrap();
        out
    }

    /// Each item (its message if an error) with its line, and the counts.
    type Read = (Vec<(Result<Sample, String>, u64)>, ReadStats);

    fn direct(bytes: &[u8]) -> Read {
        let mut r = TelemetryReader::new(bytes, "t.csv", CsvOptions::default()).unwrap();
        let mut out = Vec::new();
        while let Some(s) = r.next() {
            out.push((s.map_err(|e| e.to_string()), r.last_line()));
        }
        (out, r.stats())
    }

    fn ahead(bytes: Vec<u8>) -> Read {
        let r = TelemetryReader::new(std::io::Cursor::new(bytes), "t.csv", CsvOptions::default())
            .unwrap();
        let mut a = ReadAhead::new(r);
        let mut out = Vec::new();
        while let Some(s) = a.next() {
            out.push((s.map_err(|e| e.to_string()), a.last_line()));
        }
        (out, a.finish().expect("reader thread"))
    }

    #[test]
    fn the_same_items_lines_and_counts_as_the_reader() {
        // Across batch boundaries, and with an error mid-file that ends the reading.
        for n in [
            0,
            1,
            BATCH_SAMPLES - 1,
            BATCH_SAMPLES,
            3 * BATCH_SAMPLES + 7,
        ] {
            let bytes = csv_of(&samples(n));
            let (d, ds) = direct(&bytes);
            let (a, r#as) = ahead(bytes);
            assert_eq!(d, a, "{n} samples");
            assert_eq!(ds, r#as);
            assert_eq!(a.len(), n);
        }
        let mut bytes = csv_of(&samples(2 * BATCH_SAMPLES));
        let text = String::from_utf8(bytes.clone()).unwrap();
        let line = text.lines().nth(700).unwrap().to_string();
        bytes = text
            .replacen(&line, &line.replacen('0', "x", 1), 1)
            .into_bytes();
        let (d, ds) = direct(&bytes);
        let (a, r#as) = ahead(bytes);
        assert_eq!(d, a);
        assert_eq!(ds, r#as);
        assert_eq!(a.len(), 700);
        let (last, line) = a.last().unwrap();
        assert!(last.as_ref().unwrap_err().contains("t.csv:701"), "{last:?}");
        assert_eq!(*line, 701);
    }

    #[test]
    fn dropping_it_early_ends_the_reader_thread() {
        let r = TelemetryReader::new(
            std::io::Cursor::new(csv_of(&samples(40 * BATCH_SAMPLES))),
            "t.csv",
            CsvOptions::default(),
        )
        .unwrap();
        let mut a = ReadAhead::new(r);
        assert!(a.next().unwrap().is_ok());
        // The thread is blocked on a full channel; finish() must not hang.
        let stats = a.finish().expect("reader thread");
        // It stopped when its next batch found no listener: at most the channel's
        // batches, the one it was sending and the one it was filling were read.
        assert!(
            stats.rows <= (BATCHES_AHEAD + 3) * BATCH_SAMPLES,
            "{} rows read",
            stats.rows
        );
    }
}
