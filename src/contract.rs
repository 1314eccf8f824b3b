//! The crate's policy for invalid call arguments (README, “Conventions: invalid input”).
//!
//! A call argument outside its function's documented domain is a contract violation: a
//! direction that is not unit (zero, NaN or ±∞ components, or |‖ω‖² − 1| beyond
//! [`DIRECTION_TOLERANCE`]), a NaN scalar, or a scalar outside its stated range (a cosine
//! beyond ±(1 + [`DIRECTION_TOLERANCE`]), a uniform outside [0, 1], a relative index that is
//! not finite and > 0). Every public entry point checks its arguments with one
//! [`require!`] line at its top:
//!
//! - debug builds panic there (the message starts with `invalid input`);
//! - release builds return the function's documented *nothing* instead of a plausible value:
//!   0 for BSDF values, phase functions, vertex terms and densities (D, P²², D_ωi, pdfs); `None`
//!   for samplers that return an `Option`; a NaN direction (and a zero weight) for samplers
//!   that return a bare vector; NaN for every other quantity, which has no neutral value
//!   (Λ, G1, projected areas, Fresnel terms, heights, C¹, normalization factors).
//!
//! Grazing, exactly horizontal and below-horizon unit directions are valid input.
//!
//! The checks sit at the public boundary only. Inside the walks, which call the slope and
//! material methods once or more per bounce with directions they produced themselves (unit up
//! to rounding), the crate calls their `*_unchecked` forms and the unchecked Fresnel and frame
//! helpers: a walk pays for the check of its own arguments once per call, never per bounce.
//! Each check is written once: the sealed [`Material`](crate::research::Material) trait's public
//! methods are provided ones that validate and call the required unchecked body; the slope
//! traits' hidden `*_unchecked` methods default to the checked ones, which the crate's slopes
//! override with the unchecked bodies.

use glam::{DVec3, Vec3};

/// The largest |‖ω‖² − 1| a direction argument may have (a length within about 5e-4 of 1):
/// loose enough for directions normalized in f32 and carried through a few frame changes,
/// tight enough to reject anything that is not meant to be unit. The renderer layer's
/// direction check uses the same bound.
pub const DIRECTION_TOLERANCE: f32 = 1e-3;

/// Whether `w` is a unit direction up to [`DIRECTION_TOLERANCE`]. One comparison: NaN fails
/// it, and so do infinite components (‖ω‖² = ∞ or NaN) and the zero vector.
#[inline(always)]
pub(crate) fn is_direction(w: Vec3) -> bool {
    (w.length_squared() - 1.0).abs() <= DIRECTION_TOLERANCE
}

/// [`is_direction`] for a direction given in double precision.
#[inline(always)]
pub(crate) fn is_direction64(w: DVec3) -> bool {
    (w.length_squared() - 1.0).abs() <= f64::from(DIRECTION_TOLERANCE)
}

/// Whether `c` is a cosine, |c| ≤ 1 + [`DIRECTION_TOLERANCE`] (a dot product of two valid
/// directions); NaN fails.
#[inline(always)]
pub(crate) fn is_cosine(c: f32) -> bool {
    c.abs() <= 1.0 + DIRECTION_TOLERANCE
}

/// Whether `u` is a uniform number, in [0, 1]; NaN fails.
#[inline(always)]
pub(crate) fn is_uniform(u: f32) -> bool {
    (0.0..=1.0).contains(&u)
}

/// Whether every uniform of `u` is in [0, 1].
#[inline(always)]
pub(crate) fn are_uniform(u: &[f32]) -> bool {
    u.iter().all(|&x| is_uniform(x))
}

/// Whether `k` can serve as the normal of a plane: any length, as long as ‖k‖² is a normal
/// finite f32 (not zero, NaN or ∞, and neither under- nor overflowing).
#[inline(always)]
pub(crate) fn is_plane_normal(k: Vec3) -> bool {
    let len_sq = k.length_squared();
    (f32::MIN_POSITIVE..=f32::MAX).contains(&len_sq)
}

/// Whether `eta` is a relative index of refraction: finite and > 0, as the constructors
/// require.
#[inline(always)]
pub(crate) fn is_index(eta: f32) -> bool {
    eta.is_finite() && eta > 0.0
}

/// Reports a contract violation: panics in debug builds, does nothing in release builds
/// (the caller then returns its documented nothing). Cold, so that the checks stay off the
/// hot path's layout.
#[cold]
#[inline(never)]
#[track_caller]
pub(crate) fn violated(what: &str, args: core::fmt::Arguments<'_>) {
    if cfg!(debug_assertions) {
        panic!(
            "invalid input: `{what}` does not hold ({args}); see the README, “Conventions: invalid input”"
        );
    }
}

/// Reports an invalid argument of the renderer layer: panics in debug builds with
/// `invalid input: ` and the description (which names the argument and its value), does
/// nothing in release builds. Cold, as [`violated`].
#[cold]
#[inline(never)]
#[track_caller]
pub(crate) fn violated_argument(description: core::fmt::Arguments<'_>) {
    if cfg!(debug_assertions) {
        panic!("invalid input: {description}");
    }
}

/// `require!(condition, nothing; arg, …)`: if `condition` is false, reports a contract
/// violation (a panic in debug builds, see [`violated`]) and returns `nothing` from the
/// enclosing function. The listed arguments are printed in the panic message.
macro_rules! require {
    ($cond:expr, $nothing:expr $(; $($arg:expr),+)?) => {
        if !($cond) {
            $crate::contract::violated(
                stringify!($cond),
                format_args!(concat!("" $($(, stringify!($arg), " = {:?}; ")+)?) $($(, $arg)+)?),
            );
            return $nothing;
        }
    };
}
