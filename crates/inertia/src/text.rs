//! Numbers and user text in messages: compact, bounded, `no_std`.
//!
//! Every error message of the crate formats floats with [`Num`] (at most 12 significant
//! digits, so `299.8999999999997` prints as `299.9` and `1e308` as `1e308`) and quotes
//! user text with `Quoted` or [`Clipped`] (at most `MAX_QUOTED_CHARS` (80) characters and
//! an ellipsis), so that no input makes a message long.

// The crate-internal helpers here serve the std front ends (pipeline, CSV reader).
#![cfg_attr(not(feature = "std"), allow(dead_code))]

use core::fmt::{self, Write};

/// The most characters of user text a message quotes.
pub(crate) const MAX_QUOTED_CHARS: usize = 80;

/// A float in at most 12 significant digits, trailing zeros removed; fixed notation for
/// magnitudes in `[1e-4, 1e12)`, scientific otherwise (`1e308`, `2.5e-7`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Num(pub f64);

/// A stack buffer for formatting without allocation.
struct Buf {
    bytes: [u8; 48],
    len: usize,
}

impl Buf {
    fn new() -> Self {
        Self {
            bytes: [0; 48],
            len: 0,
        }
    }

    fn as_str(&self) -> &str {
        // Only ASCII from float formatting is written.
        core::str::from_utf8(&self.bytes[..self.len]).unwrap_or("?")
    }
}

impl Write for Buf {
    fn write_str(&mut self, s: &str) -> fmt::Result {
        let end = self.len + s.len();
        if end > self.bytes.len() {
            return Err(fmt::Error);
        }
        self.bytes[self.len..end].copy_from_slice(s.as_bytes());
        self.len = end;
        Ok(())
    }
}

/// `s` without trailing zeros after a decimal point (and without the point if bare).
fn trim_zeros(s: &str) -> &str {
    if !s.contains('.') {
        return s;
    }
    s.trim_end_matches('0').trim_end_matches('.')
}

impl fmt::Display for Num {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let v = self.0;
        if !v.is_finite() || v == 0.0 {
            return write!(f, "{v}");
        }
        let mut sci = Buf::new();
        write!(sci, "{v:.11e}")?;
        let (mantissa, exp) = sci.as_str().split_once('e').unwrap_or((sci.as_str(), "0"));
        let exp: i32 = exp.parse().unwrap_or(0);
        if (-4..12).contains(&exp) {
            let mut fixed = Buf::new();
            let decimals = usize::try_from(11 - exp).unwrap_or(0);
            write!(fixed, "{v:.decimals$}")?;
            f.write_str(trim_zeros(fixed.as_str()))
        } else {
            write!(f, "{}e{exp}", trim_zeros(mantissa))
        }
    }
}

/// A count and a noun, plural unless the count is 1: `1 gap`, `0 gaps`, `2 sign flips`.
#[derive(Debug, Clone, Copy)]
#[cfg_attr(not(feature = "serde"), allow(dead_code))] // used by the report
pub(crate) struct Counted<'a>(pub usize, pub &'a str);

impl fmt::Display for Counted<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let s = if self.0 == 1 { "" } else { "s" };
        write!(f, "{} {}{s}", self.0, self.1)
    }
}

/// The longest prefix of `s` with at most `max_chars` characters, and whether it is all
/// of `s`.
fn prefix(s: &str, max_chars: usize) -> (&str, bool) {
    match s.char_indices().nth(max_chars) {
        Some((i, _)) => (&s[..i], false),
        None => (s, true),
    }
}

/// User text in double quotes with escapes (like `{:?}`), cut after
/// [`MAX_QUOTED_CHARS`] characters: `"abc…" (12345 bytes)`.
#[derive(Debug, Clone, Copy)]
#[cfg_attr(not(feature = "csv"), allow(dead_code))] // used by the CSV reader's messages
pub(crate) struct Quoted<'a>(pub &'a str);

impl fmt::Display for Quoted<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let (head, whole) = prefix(self.0, MAX_QUOTED_CHARS);
        if whole {
            write!(f, "{head:?}")
        } else {
            let quoted_head = head.escape_debug();
            write!(f, "\"{quoted_head}…\" ({} bytes)", self.0.len())
        }
    }
}

/// Text cut after a number of characters (default `MAX_QUOTED_CHARS`, 80) with
/// `… (N bytes)`, and with line breaks shown as spaces: one line, bounded length.
#[derive(Debug, Clone, Copy)]
pub struct Clipped<'a> {
    text: &'a str,
    max_chars: usize,
}

impl<'a> Clipped<'a> {
    /// At most [`MAX_QUOTED_CHARS`] characters of `text`.
    #[must_use]
    pub(crate) fn new(text: &'a str) -> Self {
        Self::with_limit(text, MAX_QUOTED_CHARS)
    }

    /// At most `max_chars` characters of `text`.
    #[must_use]
    pub fn with_limit(text: &'a str, max_chars: usize) -> Self {
        Self { text, max_chars }
    }
}

impl fmt::Display for Clipped<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let (head, whole) = prefix(self.text, self.max_chars);
        for c in head.chars() {
            match c {
                '\n' | '\r' => f.write_char(' ')?,
                // A terminal escape sequence in a file's text is shown, not obeyed.
                c if c.is_control() => write!(f, "{}", c.escape_default())?,
                c => f.write_char(c)?,
            }
        }
        if !whole {
            write!(f, "… ({} bytes)", self.text.len())?;
        }
        Ok(())
    }
}

#[cfg(all(test, feature = "std"))]
mod tests {
    use super::*;

    #[test]
    fn numbers_are_compact() {
        let s = |v: f64| std::format!("{}", Num(v));
        assert_eq!(s(299.8999999999997), "299.9");
        assert_eq!(s(0.30000000000000004), "0.3");
        assert_eq!(s(1e308), "1e308");
        assert_eq!(s(-2.5e-7), "-2.5e-7");
        assert_eq!(s(0.1), "0.1");
        assert_eq!(s(300.0), "300");
        assert_eq!(s(1234.5678), "1234.5678");
        assert_eq!(s(0.0), "0");
        assert_eq!(s(f64::NAN), "NaN");
        assert_eq!(s(f64::MAX), "1.79769313486e308");
        assert_eq!(s(1e11), "100000000000");
        assert_eq!(s(1e12), "1e12");
        assert_eq!(std::format!("{}", Counted(1, "gap")), "1 gap");
        assert_eq!(std::format!("{}", Counted(0, "gap")), "0 gaps");
    }

    #[test]
    fn user_text_is_bounded() {
        let long = "x".repeat(10_000);
        let q = std::format!("{}", Quoted(&long));
        assert!(q.len() < 120, "{q}");
        assert!(q.ends_with("…\" (10000 bytes)"), "{q}");
        assert_eq!(std::format!("{}", Quoted("a\"b")), "\"a\\\"b\"");
        let c = std::format!("{}", Clipped::new(&long));
        assert!(c.len() < 120 && c.contains('…'), "{c}");
        assert_eq!(std::format!("{}", Clipped::with_limit("a\nb", 10)), "a b");
        // Never cuts inside a character.
        let wide = "é".repeat(200);
        assert!(std::format!("{}", Clipped::new(&wide)).starts_with("éé"));
    }

    /// Fuzz finding: a residual span against a rest that fits exactly has an infinite
    /// variance ratio, which the status printed as `inf`.
    #[test]
    fn infinite_ratio_is_worded() {
        let t = std::format!("{}", Times(f64::INFINITY));
        assert!(!t.contains("inf") && t.contains("fits exactly"), "{t}");
        assert_eq!(std::format!("{}", Times(12.0)), "1.2e1 times");
    }
}

/// A variance ratio as `"{r:.1e} times"`, and for an infinite one (the reference
/// variance is zero: the rest fits exactly) words instead of `inf`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Times(pub(crate) f64);

impl fmt::Display for Times {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.0.is_finite() {
            write!(f, "{:.1e} times", self.0)
        } else {
            f.write_str("unboundedly many times (the rest fits exactly)")
        }
    }
}
