//! The values of a run description that are not a plain number, flag or name: a
//! fraction (`"10%"` or `0.1`), element bounds, an inertia (a matrix or a file), a
//! prior's σ, the wheel-speed time tag. Each deserialises from what the command line, a
//! run file and Python give, and says what it expected when it cannot.

use crate::estimator::wheel_delay::WheelDelay;
use crate::tensor::Component;
use core::fmt;
use serde::de::{self, Deserializer, MapAccess, SeqAccess, Unexpected, Visitor};
use serde::Deserialize;
use std::format;
use std::path::PathBuf;
use std::string::String;
use std::vec::Vec;

/// A fraction, `"10%"` or `0.1` (finite, ≥ 0).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Fraction(pub f64);

impl core::str::FromStr for Fraction {
    type Err = &'static str;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let t = s.trim();
        let v = match t.strip_suffix('%') {
            Some(p) => p.trim().parse::<f64>().map(|v| v / 100.0),
            None => t.parse::<f64>(),
        }
        .map_err(|_| "expected e.g. 10% or 0.1")?;
        Self::checked(v).ok_or("must be finite and >= 0")
    }
}

impl Fraction {
    fn checked(v: f64) -> Option<Self> {
        (v.is_finite() && v >= 0.0).then_some(Self(v))
    }
}

struct FractionVisitor;

impl Visitor<'_> for FractionVisitor {
    type Value = Fraction;

    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("a number or a percentage such as \"10%\" (finite, >= 0)")
    }

    fn visit_str<E: de::Error>(self, v: &str) -> Result<Fraction, E> {
        v.parse()
            .map_err(|_| E::invalid_value(Unexpected::Str(v), &self))
    }

    fn visit_f64<E: de::Error>(self, v: f64) -> Result<Fraction, E> {
        Fraction::checked(v).ok_or_else(|| E::invalid_value(Unexpected::Float(v), &self))
    }

    fn visit_i64<E: de::Error>(self, v: i64) -> Result<Fraction, E> {
        self.visit_f64(v as f64)
    }

    fn visit_u64<E: de::Error>(self, v: u64) -> Result<Fraction, E> {
        self.visit_f64(v as f64)
    }
}

impl<'de> Deserialize<'de> for Fraction {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(FractionVisitor)
    }
}

/// One element bound: the element and its lower and upper bound, kg m² (either may be
/// absent).
pub type ElementBound = (Component, Option<f64>, Option<f64>);

/// Element bounds: strings in the command line's form (`"J33=2.7:3.3"`, one or a list), or
/// a table `{J33 = [2.7, 3.3]}` (Python: a dict whose ranges may hold `None`).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Bounds(pub Vec<ElementBound>);

const BOUND_EXAMPLE: &str = "expected e.g. J33=2.7:3.3, J12=:0.05";

/// `Jij=LO:HI`, its error naming the text.
pub(crate) fn parse_bound(s: &str) -> Result<ElementBound, String> {
    crate::constraints::parse_bound(s)
        .map_err(|why| format!("bounds {s:?}: {why} ({BOUND_EXAMPLE})"))
}

struct BoundsVisitor;

impl<'de> Visitor<'de> for BoundsVisitor {
    type Value = Bounds;

    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(
            "a dict {\"J33\": (2.7, 3.3)} (a table J33 = [2.7, 3.3]) or strings like \"J33=2.7:3.3\"",
        )
    }

    fn visit_str<E: de::Error>(self, v: &str) -> Result<Bounds, E> {
        parse_bound(v).map(|b| Bounds(vec![b])).map_err(E::custom)
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Bounds, A::Error> {
        let mut out = Vec::new();
        while let Some(s) = seq.next_element::<String>()? {
            out.push(parse_bound(&s).map_err(de::Error::custom)?);
        }
        Ok(Bounds(out))
    }

    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Bounds, A::Error> {
        let mut out = Vec::new();
        while let Some(name) = map.next_key::<String>()? {
            let c = Component::from_name(name.trim()).ok_or_else(|| {
                de::Error::custom(format!(
                    "bounds[{name:?}]: unknown element (J11, J22, J33, J12, J13, J23)"
                ))
            })?;
            let (lo, hi): (Option<f64>, Option<f64>) = map.next_value().map_err(|_| {
                de::Error::custom(format!(
                    "bounds[{name:?}]: expected (low, high), kg m², either may be None"
                ))
            })?;
            for x in [lo, hi].into_iter().flatten() {
                if !x.is_finite() {
                    return Err(de::Error::custom(format!(
                        "bounds[{name:?}]: {} is not finite",
                        crate::text::Num(x)
                    )));
                }
            }
            if lo.is_none() && hi.is_none() {
                return Err(de::Error::custom(format!(
                    "bounds[{name:?}]: no bound given"
                )));
            }
            out.push((c, lo, hi));
        }
        Ok(Bounds(out))
    }
}

impl<'de> Deserialize<'de> for Bounds {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(BoundsVisitor)
    }
}

/// An inertia given as a 3×3 matrix, kg m², or as a file (the command line's JSON
/// inertia file, which the front end reads).
#[derive(Debug, Clone, PartialEq)]
pub enum InertiaInput {
    /// Rows of the matrix.
    Matrix([[f64; 3]; 3]),
    /// A file.
    File(PathBuf),
}

struct InertiaVisitor;

impl<'de> Visitor<'de> for InertiaVisitor {
    type Value = InertiaInput;

    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("a 3×3 matrix of numbers or a file name")
    }

    fn visit_str<E: de::Error>(self, v: &str) -> Result<InertiaInput, E> {
        Ok(InertiaInput::File(PathBuf::from(v)))
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<InertiaInput, A::Error> {
        let mut rows = Vec::new();
        while let Some(r) = seq.next_element::<Vec<f64>>()? {
            rows.push(r);
        }
        matrix(&rows)
            .map(InertiaInput::Matrix)
            .ok_or_else(|| de::Error::custom("expected a 3×3 matrix"))
    }
}

fn matrix(rows: &[Vec<f64>]) -> Option<[[f64; 3]; 3]> {
    (rows.len() == 3 && rows.iter().all(|r| r.len() == 3))
        .then(|| core::array::from_fn(|r| core::array::from_fn(|c| rows[r][c])))
}

impl<'de> Deserialize<'de> for InertiaInput {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(InertiaVisitor)
    }
}

/// The σ of a prior: relative (`"5%"`), absolute for every element (`0.02` or
/// `"0.02"`, kg m²), or per element (a symmetric 3×3 matrix, kg m²).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PriorSigma {
    /// A fraction of each element's scale.
    Relative(f64),
    /// kg m², every element.
    Absolute(f64),
    /// kg m², per element (rows of the matrix).
    Matrix([[f64; 3]; 3]),
}

impl core::str::FromStr for PriorSigma {
    type Err = &'static str;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        const WHY: &str = "expected a relative σ such as 5% or an absolute one in kg m² such as 0.02, finite and > 0";
        let t = s.trim();
        let out = match t.strip_suffix('%') {
            Some(p) => PriorSigma::Relative(p.trim().parse::<f64>().map_err(|_| WHY)? / 100.0),
            None => PriorSigma::Absolute(t.parse::<f64>().map_err(|_| WHY)?),
        };
        match out {
            PriorSigma::Relative(v) | PriorSigma::Absolute(v) if v.is_finite() && v > 0.0 => {
                Ok(out)
            }
            _ => Err(WHY),
        }
    }
}

struct PriorSigmaVisitor;

impl<'de> Visitor<'de> for PriorSigmaVisitor {
    type Value = PriorSigma;

    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("a relative σ such as \"5%\", a number (kg m², finite and > 0) or a 3×3 matrix")
    }

    fn visit_str<E: de::Error>(self, v: &str) -> Result<PriorSigma, E> {
        v.parse()
            .map_err(|_| E::invalid_value(Unexpected::Str(v), &self))
    }

    fn visit_f64<E: de::Error>(self, v: f64) -> Result<PriorSigma, E> {
        if v.is_finite() && v > 0.0 {
            Ok(PriorSigma::Absolute(v))
        } else {
            Err(E::invalid_value(Unexpected::Float(v), &self))
        }
    }

    fn visit_i64<E: de::Error>(self, v: i64) -> Result<PriorSigma, E> {
        self.visit_f64(v as f64)
    }

    fn visit_u64<E: de::Error>(self, v: u64) -> Result<PriorSigma, E> {
        self.visit_f64(v as f64)
    }

    fn visit_seq<A: SeqAccess<'de>>(self, seq: A) -> Result<PriorSigma, A::Error> {
        match InertiaVisitor.visit_seq(seq)? {
            InertiaInput::Matrix(m) => Ok(PriorSigma::Matrix(m)),
            InertiaInput::File(_) => Err(de::Error::custom("expected a 3×3 matrix")),
        }
    }
}

impl<'de> Deserialize<'de> for PriorSigma {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(PriorSigmaVisitor)
    }
}

/// The wheel-speed time tag: `"off"`, `"estimate"`, or the delay in seconds (a number or
/// its text).
pub(crate) fn wheel_delay<'de, D: Deserializer<'de>>(d: D) -> Result<Option<WheelDelay>, D::Error> {
    struct V;
    impl Visitor<'_> for V {
        type Value = WheelDelay;

        fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
            f.write_str("off, estimate, or the delay in seconds")
        }

        fn visit_str<E: de::Error>(self, v: &str) -> Result<WheelDelay, E> {
            crate::pipeline::parse_wheel_delay(v)
                .map_err(|_| E::invalid_value(Unexpected::Str(v), &self))
        }

        fn visit_f64<E: de::Error>(self, v: f64) -> Result<WheelDelay, E> {
            if v.is_finite() {
                Ok(WheelDelay::KnownS(v))
            } else {
                Err(E::invalid_value(Unexpected::Float(v), &self))
            }
        }

        fn visit_i64<E: de::Error>(self, v: i64) -> Result<WheelDelay, E> {
            self.visit_f64(v as f64)
        }

        fn visit_u64<E: de::Error>(self, v: u64) -> Result<WheelDelay, E> {
            self.visit_f64(v as f64)
        }
    }
    d.deserialize_any(V).map(Some)
}
