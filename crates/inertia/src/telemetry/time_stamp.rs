//! ISO-8601 / RFC 3339 time stamps on a leap-second-free scale (feature `csv`).
//!
//! UTC inserts leap seconds (`23:59:60`), so UTC time stamps do not measure elapsed
//! seconds across one. [`Clock::parse`] returns seconds on a continuous scale (like TAI):
//! the Unix time plus the number of leap seconds inserted before the stamp. It counts
//! the leap seconds of the IERS table up to the end of 2016 ([`LEAP_SECOND_ENDS`]) and
//! any later one that the file itself shows (a stamp with second 60), so steps across a
//! leap second are true elapsed time: `23:59:59.9`, `23:59:60.0`, …, `23:59:60.9`,
//! `00:00:00.0` are all 0.1 s apart.

/// Unix time of the end (the following midnight, UTC) of each leap second inserted
/// since 1972, from the IERS table (27, the last at the end of 2016-12-31).
pub(crate) const LEAP_SECOND_ENDS: [i64; 27] = [
    78_796_800,
    94_694_400,
    126_230_400,
    157_766_400,
    189_302_400,
    220_924_800,
    252_460_800,
    283_996_800,
    315_532_800,
    362_793_600,
    394_329_600,
    425_865_600,
    489_024_000,
    567_993_600,
    631_152_000,
    662_688_000,
    709_948_800,
    741_484_800,
    773_020_800,
    820_454_400,
    867_715_200,
    915_148_800,
    1_136_073_600,
    1_230_768_000,
    1_341_100_800,
    1_435_708_800,
    1_483_228_800,
];

/// Converts time stamps to seconds on a continuous scale, counting leap seconds.
#[derive(Debug, Clone, Default)]
pub(crate) struct Clock {
    /// Ends of leap seconds seen in the data and absent from the table.
    seen: Vec<i64>,
}

/// Why a time stamp was refused.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum StampError {
    /// Not an ISO-8601 / RFC 3339 time stamp.
    Unparsable,
    /// Second 60 anywhere but at 23:59:60 UTC.
    NotALeapSecond,
}

impl Clock {
    /// Leap seconds that ended at or before Unix time `unix`.
    fn leaps_before(&self, unix: i64) -> i64 {
        let n = LEAP_SECOND_ENDS.iter().filter(|&&e| e <= unix).count()
            + self.seen.iter().filter(|&&e| e <= unix).count();
        i64::try_from(n).unwrap_or(i64::MAX)
    }

    /// `(seconds, nanoseconds)` of a time stamp on the continuous scale (Unix time plus
    /// leap seconds so far); without an offset it is taken as UTC.
    pub(crate) fn parse(&mut self, raw: &str) -> Result<(i64, i64), StampError> {
        let Some(i) = leap_second_field(raw) else {
            let (unix, nanos) = unix_time(raw).ok_or(StampError::Unparsable)?;
            return Ok((unix + self.leaps_before(unix), nanos));
        };
        // Parse 23:59:60.f as 23:59:59.f, one second later.
        let mut text = String::from(raw);
        text.replace_range(i..i + 2, "59");
        let (unix59, nanos) = unix_time(&text).ok_or(StampError::Unparsable)?;
        if unix59.rem_euclid(86_400) != 86_399 {
            return Err(StampError::NotALeapSecond);
        }
        let end = unix59 + 1;
        if !LEAP_SECOND_ENDS.contains(&end) && !self.seen.contains(&end) {
            self.seen.push(end);
        }
        Ok((end + self.leaps_before(unix59), nanos))
    }
}

/// The byte index of a seconds field `60` (`hh:mm:60`, then the end, a fraction or an
/// offset).
fn leap_second_field(raw: &str) -> Option<usize> {
    let b = raw.as_bytes();
    (6..b.len().saturating_sub(1)).find(|&i| {
        b[i - 1] == b':'
            && b[i - 4] == b':'
            && b[i..i + 2] == *b"60"
            && b.get(i + 2).is_none_or(|c| !c.is_ascii_digit())
            && [i - 3, i - 2, i - 6, i - 5]
                .iter()
                .all(|&k| b[k].is_ascii_digit())
    })
}

/// Unix time `(seconds, nanoseconds)` of an ISO-8601 / RFC 3339 time stamp.
fn unix_time(raw: &str) -> Option<(i64, i64)> {
    use time::format_description::well_known::{Iso8601, Rfc3339};
    let dt = time::OffsetDateTime::parse(raw, &Rfc3339)
        .or_else(|_| time::OffsetDateTime::parse(raw, &Iso8601::DEFAULT))
        .or_else(|_| time::PrimitiveDateTime::parse(raw, &Iso8601::DEFAULT).map(|p| p.assume_utc()))
        .ok()?;
    Some((dt.unix_timestamp(), i64::from(dt.nanosecond())))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn seconds(c: &mut Clock, s: &str) -> f64 {
        let (a, n) = c.parse(s).unwrap();
        a as f64 + n as f64 * 1e-9
    }

    #[test]
    fn the_table_is_the_iers_one() {
        for &e in &LEAP_SECOND_ENDS {
            let d = time::OffsetDateTime::from_unix_timestamp(e).unwrap();
            assert_eq!((d.hour(), d.minute(), d.second(), d.day()), (0, 0, 0, 1));
            assert!(matches!(
                d.month(),
                time::Month::January | time::Month::July
            ));
        }
    }

    #[test]
    fn steps_across_a_leap_second_are_elapsed_seconds() {
        let mut c = Clock::default();
        let t: Vec<f64> = [
            "2016-12-31T23:59:59.9Z",
            "2016-12-31T23:59:60.0Z",
            "2016-12-31T23:59:60.1Z",
            "2016-12-31T23:59:60.9Z",
            "2017-01-01T00:00:00.0Z",
            "2017-01-01T00:00:00.1Z",
        ]
        .iter()
        .map(|s| seconds(&mut c, s))
        .collect();
        let steps: Vec<f64> = t.windows(2).map(|w| w[1] - w[0]).collect();
        for (s, want) in steps.iter().zip([0.1, 0.1, 0.8, 0.1, 0.1]) {
            assert!((s - want).abs() < 1e-6, "{steps:?}");
        }
        // Across the leap second without a sample in it: still 1 s more than Unix time.
        let mut c = Clock::default();
        let a = seconds(&mut c, "2016-12-31T23:59:59Z");
        let b = seconds(&mut c, "2017-01-01T00:00:00Z");
        assert_eq!(b - a, 2.0);
        // With an offset: 00:59:60+01:00 is the same leap second.
        let mut c = Clock::default();
        let a = seconds(&mut c, "2016-12-31T23:59:59.5Z");
        let b = seconds(&mut c, "2017-01-01T00:59:60.5+01:00");
        assert!((b - a - 1.0).abs() < 1e-6, "{}", b - a);
    }

    #[test]
    fn a_leap_second_outside_the_table_is_counted_from_the_data() {
        let mut c = Clock::default();
        let a = seconds(&mut c, "2030-06-30T23:59:59.5Z");
        let b = seconds(&mut c, "2030-06-30T23:59:60.5Z");
        let d = seconds(&mut c, "2030-07-01T00:00:00.5Z");
        assert!((b - a - 1.0).abs() < 1e-6 && (d - b - 1.0).abs() < 1e-6);
    }

    #[test]
    fn second_60_elsewhere_is_refused() {
        let mut c = Clock::default();
        assert_eq!(
            c.parse("2016-12-31T12:00:60Z"),
            Err(StampError::NotALeapSecond)
        );
        assert_eq!(c.parse("nonsense"), Err(StampError::Unparsable));
    }
}
