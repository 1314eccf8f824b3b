//! The crate's error type.

use core::fmt;

/// Why a constructor rejected its arguments.
///
/// Every constructor of the crate validates its parameters and returns this error instead
/// of clamping them silently. The enum is `#[non_exhaustive]`: match it with a wildcard arm.
#[non_exhaustive]
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Error {
    /// A scalar parameter is NaN, infinite or outside its documented range.
    InvalidParameter {
        /// Name of the parameter, as in the constructor's signature (`"alpha_x"`, `"eta"`…).
        name: &'static str,
        /// The rejected value.
        value: f32,
        /// The range the parameter must lie in, in words (`"finite and > 0"`).
        expected: &'static str,
    },
    /// A model was given a material it does not cover.
    UnsupportedMaterial {
        /// The model (its type name, `"Invariance"`).
        model: &'static str,
        /// The materials it covers, in words.
        expected: &'static str,
    },
    /// A slice of a batch call is not as long as the batch's first slice (the batch API,
    /// [`BatchBsdf`](crate::BatchBsdf)): nothing was computed.
    LengthMismatch {
        /// Name of the slice (`"wi.x"`, `"pdf"`…).
        name: &'static str,
        /// The batch's length (that of its first direction slice).
        expected: usize,
        /// The slice's length.
        found: usize,
    },
}

impl Error {
    /// Checks that `value` is finite and strictly positive.
    pub(crate) fn check_positive(name: &'static str, value: f32) -> Result<f32, Error> {
        if value.is_finite() && value > 0.0 {
            Ok(value)
        } else {
            Err(Error::InvalidParameter { name, value, expected: "finite and > 0" })
        }
    }

    /// Checks that `value` is finite and non-negative.
    pub(crate) fn check_non_negative(name: &'static str, value: f32) -> Result<f32, Error> {
        if value.is_finite() && value >= 0.0 {
            Ok(value)
        } else {
            Err(Error::InvalidParameter { name, value, expected: "finite and >= 0" })
        }
    }

    /// Checks that `value` lies in [0, 1].
    pub(crate) fn check_unit_interval(name: &'static str, value: f32) -> Result<f32, Error> {
        if (0.0..=1.0).contains(&value) {
            Ok(value)
        } else {
            Err(Error::InvalidParameter { name, value, expected: "in [0, 1]" })
        }
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::InvalidParameter { name, value, expected } => {
                write!(f, "invalid parameter `{name}` = {value}: expected {expected}")
            }
            Error::UnsupportedMaterial { model, expected } => {
                write!(f, "unsupported material for `{model}`: expected {expected}")
            }
            Error::LengthMismatch { name, expected, found } => {
                write!(f, "batch slice `{name}` has {found} elements: expected {expected}")
            }
        }
    }
}

impl std::error::Error for Error {}
