//! The names of the choice-valued settings, once.
//!
//! Every setting whose value is one of a few words (the model of the rotor momentum, the
//! rotation source, the inertial torque, the glitch policy, the constraint set, the
//! convention of products of inertia, the quaternion format, the gyro unit) has its
//! names here, through [`Choice`]: the command line offers [`Choice::NAMES`], Python and a
//! run file ([`crate::run_description`]) parse with [`Choice::parse`] (or `FromStr`), and
//! an unknown word is [`PipelineError::UnknownChoice`] naming the setting and the known
//! words. The estimators and solver backends are named by their registry
//! ([`crate::pipeline::registry`]).

use crate::constraints::{Consistency, ProductConvention};
use crate::estimator::momentum_rows::{RhoModel, RotationSource};
use crate::pipeline::{InertialTorque, PipelineError};
use crate::telemetry::gate::{GyroUnit, QuaternionFormat};
use crate::telemetry::glitch::GlitchPolicy;

/// A setting whose value is one of a few names.
pub trait Choice: Sized + Copy + PartialEq + 'static {
    /// The setting, as options, keywords and files name it (`rho_model`).
    const SETTING: &'static str;
    /// Every value, in the order of [`Self::NAMES`].
    const ALL: &'static [Self];
    /// Every value's name.
    const NAMES: &'static [&'static str];
    /// [`Self::NAMES`] joined by `", "` (the "known" part of an error).
    const KNOWN: &'static str;

    /// This value's name.
    #[must_use]
    fn choice_name(self) -> &'static str {
        Self::ALL
            .iter()
            .position(|v| *v == self)
            .map_or("?", |i| Self::NAMES[i])
    }

    /// The value called `s` (`_` taken for `-`); an unknown name is
    /// [`PipelineError::UnknownChoice`].
    fn parse(s: &str) -> Result<Self, PipelineError> {
        let t = s.trim();
        Self::NAMES
            .iter()
            .position(|n| *n == t || (t.contains('_') && *n == t.replace('_', "-")))
            .map(|i| Self::ALL[i])
            .ok_or_else(|| PipelineError::UnknownChoice {
                setting: Self::SETTING,
                value: s.into(),
                expected: Self::KNOWN,
            })
    }
}

macro_rules! choice {
    ($t:ty, $setting:literal, $known:literal, [$($v:expr => $name:literal),+ $(,)?]) => {
        impl Choice for $t {
            const SETTING: &'static str = $setting;
            const ALL: &'static [Self] = &[$($v),+];
            const NAMES: &'static [&'static str] = &[$($name),+];
            const KNOWN: &'static str = $known;
        }

        impl core::str::FromStr for $t {
            type Err = PipelineError;

            fn from_str(s: &str) -> Result<Self, Self::Err> {
                <$t as Choice>::parse(s)
            }
        }

        #[cfg(feature = "serde")]
        impl<'de> serde::Deserialize<'de> for $t {
            fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
                d.deserialize_str(ChoiceVisitor::<$t>(core::marker::PhantomData))
            }
        }
    };
}

choice!(RhoModel, "rho_model", "auto, smooth, held, plain", [
    RhoModel::Auto => "auto",
    RhoModel::Smooth => "smooth",
    RhoModel::Held => "held",
    RhoModel::Plain => "plain",
]);
choice!(RotationSource, "rotation_source", "attitude, gyro", [
    RotationSource::Attitude => "attitude",
    RotationSource::Gyro => "gyro",
]);
choice!(InertialTorque, "inertial_torque", "off, on, auto, short", [
    InertialTorque::Off => "off",
    InertialTorque::On => "on",
    InertialTorque::Auto => "auto",
    InertialTorque::Short => "short",
]);
choice!(GlitchPolicy, "glitches", "stop, keep", [
    GlitchPolicy::Stop => "stop",
    GlitchPolicy::Keep => "keep",
]);
choice!(Consistency, "constraints", "physical, paper, positive-definite", [
    Consistency::Physical => "physical",
    Consistency::PaperTriangle => "paper",
    Consistency::PositiveDefiniteOnly => "positive-definite",
]);
choice!(ProductConvention, "products", "tensor, cad", [
    ProductConvention::Tensor => "tensor",
    ProductConvention::Cad => "cad",
]);
choice!(QuaternionFormat, "quaternion", "scalar-last, scalar-first, jpl, conjugate", [
    QuaternionFormat::HamiltonScalarLast => "scalar-last",
    QuaternionFormat::HamiltonScalarFirst => "scalar-first",
    QuaternionFormat::Jpl => "jpl",
    QuaternionFormat::Conjugate => "conjugate",
]);
choice!(GyroUnit, "gyro_unit", "rad/s, deg/s", [
    GyroUnit::RadPerS => "rad/s",
    GyroUnit::DegPerS => "deg/s",
]);

/// Deserialises a [`Choice`] from its name: an unknown one is an invalid value whose
/// expectation lists the known names.
#[cfg(feature = "serde")]
struct ChoiceVisitor<T>(core::marker::PhantomData<T>);

#[cfg(feature = "serde")]
impl<T: Choice> serde::de::Visitor<'_> for ChoiceVisitor<T> {
    type Value = T;

    fn expecting(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(f, "one of {}", T::KNOWN)
    }

    fn visit_str<E: serde::de::Error>(self, v: &str) -> Result<T, E> {
        T::parse(v).map_err(|_| E::invalid_value(serde::de::Unexpected::Str(v), &self))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::string::String;

    fn check<T: Choice + core::fmt::Debug + core::str::FromStr<Err = PipelineError>>() {
        assert_eq!(T::ALL.len(), T::NAMES.len(), "{}", T::SETTING);
        assert_eq!(T::KNOWN, T::NAMES.join(", "), "{}", T::SETTING);
        for (v, n) in T::ALL.iter().zip(T::NAMES) {
            assert_eq!(v.choice_name(), *n);
            assert_eq!(n.parse::<T>().unwrap(), *v);
        }
        let e = "nope".parse::<T>().unwrap_err();
        assert_eq!(
            e.to_string(),
            String::from("setting `")
                + T::SETTING
                + "`: unknown value `nope` (known: "
                + T::KNOWN
                + ")"
        );
    }

    #[test]
    fn every_choice_names_each_value_once_and_parses_it_back() {
        check::<RhoModel>();
        check::<RotationSource>();
        check::<InertialTorque>();
        check::<GlitchPolicy>();
        check::<Consistency>();
        check::<ProductConvention>();
        check::<QuaternionFormat>();
        check::<GyroUnit>();
        // The names the reports use are the same.
        for v in Consistency::ALL {
            assert_eq!(v.name(), v.choice_name());
        }
        assert_eq!(
            "positive_definite".parse::<Consistency>(),
            Ok(Consistency::PositiveDefiniteOnly)
        );
    }
}
