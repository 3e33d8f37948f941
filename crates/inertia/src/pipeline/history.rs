//! Estimate histories as CSV (feature `csv`):
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

/// Pending output is handed to the writer in pieces of about this size.
const CHUNK: usize = 1 << 16;

/// A history being written.
///
/// The rows are formed directly, byte for byte as the `csv` crate's default writer forms
/// them (only `reason` can need quoting: a field holding `,`, `"`, `\r` or `\n` is
/// quoted, with `"` doubled), into a buffer handed to `out` in pieces of about 64 KiB:
/// no allocation per row or field, and no per-field quoting scan of the numbers.
pub(crate) struct HistoryWriter<W: Write> {
    /// `None` only once [`Self::finish`] has taken it.
    out: Option<W>,
    pending: std::vec::Vec<u8>,
    buf: ryu::Buffer,
    reason: std::string::String,
}

impl<W: Write> HistoryWriter<W> {
    /// Write the header to `out`.
    pub(crate) fn new(out: W) -> Result<Self, csv::Error> {
        let mut pending = std::vec::Vec::with_capacity(CHUNK + 1024);
        pending.extend_from_slice(HEADER.join(",").as_bytes());
        pending.push(b'\n');
        Ok(Self {
            out: Some(out),
            pending,
            buf: ryu::Buffer::new(),
            reason: std::string::String::new(),
        })
    }

    /// Append one estimate (no allocation).
    pub(crate) fn write(&mut self, e: &Estimate) -> Result<(), csv::Error> {
        use core::fmt::Write as _;
        let Self {
            out,
            pending: line,
            buf,
            reason,
        } = self;
        let mut field = |line: &mut std::vec::Vec<u8>, v: Option<f64>| {
            if let Some(v) = v.filter(|v| v.is_finite()) {
                line.extend_from_slice(buf.format_finite(v).as_bytes());
            }
            line.push(b',');
        };
        let j = e.j();
        let sigma = e.sigma_kg_m2();
        field(line, Some(e.t_s));
        for k in 0..6 {
            field(line, j.map(|j| j[k]));
        }
        line.extend_from_slice(e.observability.code().as_bytes());
        line.push(b',');
        field(line, e.observability.condition());
        field(line, e.solution.map(|s| f64::from(s.iterations)));
        for k in 0..6 {
            field(line, sigma.map(|s| s[k]));
        }
        reason.clear();
        if let Some(r) = e.observability.reason() {
            let _ = write!(reason, "{r}");
        }
        push_quoted(line, reason.as_bytes());
        line.push(b'\n');
        if line.len() >= CHUNK {
            if let Some(out) = out.as_mut() {
                out.write_all(line)?;
            }
            line.clear();
        }
        Ok(())
    }

    /// Flush and return the writer.
    pub(crate) fn finish(mut self) -> Result<W, csv::Error> {
        let mut out = self.out.take().ok_or_else(|| {
            csv::Error::from(std::io::Error::other("history writer already finished"))
        })?;
        out.write_all(&self.pending)?;
        self.pending.clear();
        out.flush()?;
        Ok(out)
    }
}

impl<W: Write> Drop for HistoryWriter<W> {
    /// Hand what is pending to the writer (errors are lost: call [`Self::finish`] to see
    /// them), as the `csv` crate's writer does when dropped.
    fn drop(&mut self) {
        if let Some(out) = self.out.as_mut() {
            let _ = out.write_all(&self.pending);
            let _ = out.flush();
        }
    }
}

/// Estimates handed to the writer thread at a time.
pub(crate) const BEHIND_BATCH: usize = 256;

/// Batches the writer thread may have waiting (8,192 estimates, 3.5 MB): room for the
/// writer to stall while its output is synced to disk (the CLI syncs every 32 MiB, about
/// 80,000 rows, which took 13–17 ms, or 3,000–4,000 samples of the estimator, in the
/// 1,000,000-sample run) without stopping the estimator. With 8 batches the estimator
/// waited at each sync: that run took 0.1–0.2 s longer.
pub(crate) const BEHIND_BATCHES: usize = 32;

/// A `HistoryWriter` on its own thread: formatting the numbers (about a tenth of a
/// long run) overlaps the estimator. Estimates are handed over in batches of
/// `BEHIND_BATCH` through a channel bounded at `BEHIND_BATCHES`, so memory stays
/// fixed. The output is the same byte for byte; a write error stops the thread and is
/// returned by the next [`Self::write`] or by [`Self::finish`].
pub struct WriteBehind<W: Write + Send + 'static> {
    batch: std::vec::Vec<Estimate>,
    to_writer: Option<std::sync::mpsc::SyncSender<std::vec::Vec<Estimate>>>,
    thread: Option<std::thread::JoinHandle<Result<W, csv::Error>>>,
}

impl<W: Write + Send + 'static> WriteBehind<W> {
    /// Start a writer thread on `out` (the header is written at once).
    pub fn new(out: W) -> Result<Self, csv::Error> {
        let mut w = HistoryWriter::new(out)?;
        let (tx, rx) = std::sync::mpsc::sync_channel::<std::vec::Vec<Estimate>>(BEHIND_BATCHES);
        let thread = std::thread::spawn(move || {
            for batch in rx {
                for e in &batch {
                    w.write(e)?;
                }
            }
            w.finish()
        });
        Ok(Self {
            batch: std::vec::Vec::with_capacity(BEHIND_BATCH),
            to_writer: Some(tx),
            thread: Some(thread),
        })
    }

    /// Append one estimate.
    pub fn write(&mut self, e: &Estimate) -> Result<(), csv::Error> {
        self.batch.push(*e);
        if self.batch.len() < BEHIND_BATCH {
            return Ok(());
        }
        let full = core::mem::replace(&mut self.batch, std::vec::Vec::with_capacity(BEHIND_BATCH));
        let sent = self
            .to_writer
            .as_ref()
            .is_some_and(|tx| tx.send(full).is_ok());
        if sent {
            Ok(())
        } else {
            // The thread stopped at a write error: return it.
            self.join().map(|_| ())
        }
    }

    /// Write what is pending, flush, and return the writer.
    pub fn finish(mut self) -> Result<W, csv::Error> {
        if !self.batch.is_empty() {
            let rest = core::mem::take(&mut self.batch);
            if let Some(tx) = &self.to_writer {
                // A closed channel: the thread's error is returned below.
                let _ = tx.send(rest);
            }
        }
        self.join()
    }

    /// Close the channel and wait for the thread.
    fn join(&mut self) -> Result<W, csv::Error> {
        self.to_writer = None;
        let gone = || csv::Error::from(std::io::Error::other("history writer already finished"));
        match self.thread.take().ok_or_else(gone)?.join() {
            Ok(result) => result,
            Err(_) => Err(csv::Error::from(std::io::Error::other(
                "the history writer thread failed",
            ))),
        }
    }
}

impl<W: Write + Send + 'static> Drop for WriteBehind<W> {
    /// Hand what is pending to the writer and wait for it (errors are lost: call
    /// [`Self::finish`] to see them), as `HistoryWriter` does when dropped.
    fn drop(&mut self) {
        if self.thread.is_some() {
            if let Some(tx) = &self.to_writer {
                let _ = tx.send(core::mem::take(&mut self.batch));
            }
            let _ = self.join();
        }
    }
}

/// A field as the `csv` crate's default writer forms it: quoted, with quotes doubled,
/// when it holds a delimiter, a quote or a line break.
fn push_quoted(line: &mut std::vec::Vec<u8>, field: &[u8]) {
    // A fold rather than `any`: no early exit, so it vectorises.
    let special = field.iter().fold(false, |acc, b| {
        acc | matches!(b, b',' | b'"' | b'\r' | b'\n')
    });
    if !special {
        line.extend_from_slice(field);
        return;
    }
    line.push(b'"');
    for &b in field {
        if b == b'"' {
            line.push(b'"');
        }
        line.push(b);
    }
    line.push(b'"');
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::estimator::observability::{Observability, Unobservable};
    use crate::estimator::uncertainty::Uncertainty;
    use crate::solver::{Residuals, Solution, SolveStatus};

    /// The history as the `csv` crate's writer forms it (the previous implementation).
    fn reference(estimates: &[Estimate]) -> std::vec::Vec<u8> {
        let mut w = csv::Writer::from_writer(std::vec::Vec::new());
        w.write_record(HEADER).unwrap();
        let mut buf = ryu::Buffer::new();
        for e in estimates {
            let mut field = |w: &mut csv::Writer<_>, v: Option<f64>| match v {
                Some(v) if v.is_finite() => w.write_field(buf.format_finite(v)).unwrap(),
                _ => w.write_field(b"").unwrap(),
            };
            let (j, sigma) = (e.j(), e.sigma_kg_m2());
            field(&mut w, Some(e.t_s));
            for k in 0..6 {
                field(&mut w, j.map(|j| j[k]));
            }
            w.write_field(e.observability.code()).unwrap();
            field(&mut w, e.observability.condition());
            field(&mut w, e.solution.map(|s| f64::from(s.iterations)));
            for k in 0..6 {
                field(&mut w, sigma.map(|s| s[k]));
            }
            let reason = e
                .observability
                .reason()
                .map(|r| std::format!("{r}"))
                .unwrap_or_default();
            w.write_field(reason).unwrap();
            w.write_record(None::<&[u8]>).unwrap();
        }
        w.into_inner().unwrap()
    }

    fn estimates() -> std::vec::Vec<Estimate> {
        let solution = |j: [f64; 6], iterations| {
            Some(Solution {
                j: crate::tensor::InertiaVector::from_row_slice(&j),
                objective: 0.0,
                status: SolveStatus::Optimal,
                iterations,
                residuals: Residuals::default(),
            })
        };
        let uncertainty = Some(Uncertainty {
            sigma_kg_m2: [1e-3, 2.5e-4, 3.0, 1e-300, 7.0, 0.1],
            noise_kg_m2: [0.0; 6],
            bias_kg_m2: [0.0; 6],
            model_spread_kg_m2: [0.0; 6],
            rotor_scale_kg_m2: [0.0; 6],
            time_tag_kg_m2: [0.0; 6],
            rotor_inertia_kg_m2: [0.0; 6],
            torque_scale_kg_m2: [0.0; 6],
            principal_sigma_kg_m2: [0.0; 3],
        });
        let mut out = std::vec::Vec::new();
        let statuses = [
            Observability::Determined { condition: 12.5 },
            Observability::Determined {
                condition: f64::INFINITY,
            },
            Observability::FromPrior(Unobservable::ConflictsWithConstraints { chi2: 190.0 }),
            Observability::FromPrior(Unobservable::NoExcitation),
            Observability::NotObservable(Unobservable::AtFloor {
                min_moment_kg_m2: -1e-3,
                unconstrained_negative: true,
                mirror_determined: false,
            }),
            Observability::NotObservable(Unobservable::RankDeficient { rank: 4 }),
            Observability::NotObservable(Unobservable::Uncertain {
                relative_sigma: f64::INFINITY,
                threshold: 0.1,
                dominant: crate::estimator::uncertainty::SigmaPart::Noise,
            }),
            Observability::Unchecked,
        ];
        for (k, observability) in statuses.into_iter().enumerate() {
            let has = observability.has_answer();
            out.push(Estimate {
                t_s: 0.1 * k as f64,
                rows: 3 * k,
                observability,
                prior: None,
                solution: if has {
                    solution([1.0, 2.0, 3.0, -0.01, 1e-17, f64::NAN], k as u32)
                } else {
                    None
                },
                uncertainty: if k % 2 == 0 { uncertainty } else { None },
            });
        }
        out
    }

    /// Byte for byte what the `csv` crate's writer makes, including a reason that must be
    /// quoted (it holds a comma), across many chunks.
    #[test]
    fn matches_csv_crate_writer() {
        let mut all = estimates();
        assert!(all.iter().any(|e| e
            .observability
            .reason()
            .is_some_and(|r| std::format!("{r}").contains(','))));
        let base = all.clone();
        for k in 1..2000 {
            all.extend(base.iter().map(|e| Estimate {
                t_s: e.t_s + f64::from(k),
                ..*e
            }));
        }
        let mut w = HistoryWriter::new(std::vec::Vec::new()).unwrap();
        for e in &all {
            w.write(e).unwrap();
        }
        let got = w.finish().unwrap();
        assert!(got.len() > 2 * CHUNK);
        assert_eq!(
            std::string::String::from_utf8(got).unwrap(),
            std::string::String::from_utf8(reference(&all)).unwrap()
        );
    }

    #[test]
    fn quoting_follows_csv_rules() {
        let mut line = std::vec::Vec::new();
        push_quoted(&mut line, b"plain: text");
        push_quoted(&mut line, b"a, b");
        push_quoted(&mut line, b"say \"x\"");
        assert_eq!(line, b"plain: text\"a, b\"\"say \"\"x\"\"\"");
    }

    /// The thread's output is the same file, across batches and with a partial last one.
    #[test]
    fn written_behind_is_the_same_file() {
        let base = estimates();
        for n in [0, 1, BEHIND_BATCH, 3 * BEHIND_BATCH + 5] {
            let all: std::vec::Vec<Estimate> = base.iter().cycle().take(n).copied().collect();
            let mut w = WriteBehind::new(std::vec::Vec::new()).unwrap();
            for e in &all {
                w.write(e).unwrap();
            }
            assert_eq!(w.finish().unwrap(), reference(&all), "{n} estimates");
        }
    }

    /// A writer that fails after `ok` bytes.
    #[derive(Debug)]
    struct Failing {
        ok: usize,
    }

    impl Write for Failing {
        fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
            if buf.len() > self.ok {
                return Err(std::io::Error::other("disk full"));
            }
            self.ok -= buf.len();
            Ok(buf.len())
        }
        fn flush(&mut self) -> std::io::Result<()> {
            Ok(())
        }
    }

    /// A write error on the thread reaches the caller, from `write` or from `finish`.
    #[test]
    fn a_write_error_behind_is_returned() {
        let base = estimates();
        let mut w = WriteBehind::new(Failing { ok: 10 * CHUNK }).unwrap();
        let mut failed = None;
        for (k, e) in base.iter().cycle().take(200 * BEHIND_BATCH).enumerate() {
            if let Err(err) = w.write(e) {
                failed = Some((k, err));
                break;
            }
        }
        let (k, err) = failed.expect("the error reaches write");
        assert!(
            k < 200 * BEHIND_BATCH && err.to_string().contains("disk full"),
            "{err}"
        );
        let mut w = WriteBehind::new(Failing { ok: 100 }).unwrap();
        w.write(&base[0]).unwrap();
        assert!(w.finish().unwrap_err().to_string().contains("disk full"));
    }
}
