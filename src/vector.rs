//! Vector kernels of the samplers and walks: normalization that survives tiny and huge
//! vectors, the cheap renormalization of nearly unit vectors, normals from slopes, and the
//! visibility guarantee of sampled normals.

use glam::Vec3;

/// An f32 dot product of two unit vectors above this is positive in exact arithmetic too
/// (its rounding error is at most 3 ulp of 1 ≈ 1.8e-7).
const VISIBLE_DOT_MARGIN: f32 = 1e-6;

/// Largest number of halvings tried by [`ensure_visible`].
const VISIBILITY_NUDGES: i32 = 24;

/// A sampled normal with ωi·ωm > 0 as evaluated in f64 from the f32 vectors (what `d_wi`
/// tests). Exact sampling gives ωi·ωm > 0; rounding the normal to f32 can flip the sign for
/// normals within about 1e-7 rad of the visibility boundary (grazing or backfacing ωi, low α).
/// Those are moved towards ωi by the smallest power-of-two step that makes them visible (and
/// kept in the upper hemisphere): a displacement of ~1e-7 rad of a mass of order 1e-5.
#[inline(always)]
pub(crate) fn ensure_visible(wi: Vec3, wm: Vec3) -> Vec3 {
    // for unit vectors the f32 dot product is within 3 ulp of 1, i.e. 2e-7, of the exact one
    if wi.dot(wm) > VISIBLE_DOT_MARGIN {
        return wm;
    }
    if wi.as_dvec3().dot(wm.as_dvec3()) > 0.0 || wi.length_squared() == 0.0 {
        return wm;
    }
    let w = wi.normalize();
    let mut step = f32::EPSILON;
    for _ in 0..VISIBILITY_NUDGES {
        let m = (wm + step * w).normalize_or(wm);
        if wi.as_dvec3().dot(m.as_dvec3()) > 0.0 && m.z >= 0.0 {
            return m;
        }
        step *= 2.0;
    }
    wm
}

/// Slopes below this in magnitude are turned into normals directly (their squares cannot
/// overflow); larger ones are scaled first.
const DIRECT_SLOPE_BELOW: f32 = 1e18;

/// The unit normal (−x̃, −ỹ, 1)/‖·‖ of the slopes (x̃, ỹ), without overflow for huge slopes
/// (an infinite slope gives the horizontal normal).
#[inline(always)]
pub(crate) fn normal_from_slopes(slope_x: f32, slope_y: f32) -> Vec3 {
    if slope_x.abs() < DIRECT_SLOPE_BELOW && slope_y.abs() < DIRECT_SLOPE_BELOW {
        let inv_len = 1.0 / (1.0 + slope_x * slope_x + slope_y * slope_y).sqrt();
        return Vec3::new(-slope_x * inv_len, -slope_y * inv_len, inv_len);
    }
    let (sx, sy) = (slope_x.clamp(-f32::MAX, f32::MAX), slope_y.clamp(-f32::MAX, f32::MAX));
    let scale = sx.abs().max(sy.abs()).max(1.0);
    normalize_scaled(Vec3::new(-sx / scale, -sy / scale, 1.0 / scale), Vec3::Z)
}

/// Squared lengths between these bounds are normalized directly: no component's square
/// overflows, and components whose squares underflow are below 2⁻²⁴ of the length.
pub(crate) const DIRECT_SCALE_RANGE: (f32, f32) = (1e-30, 1e30);

/// `v` normalized: directly where |v|² is in a safe range, else by [`normalize_scaled`]
/// (`fallback` for a zero or non-finite vector).
#[inline(always)]
pub(crate) fn normalize_fast(v: Vec3, fallback: Vec3) -> Vec3 {
    let len_sq = v.length_squared();
    if len_sq > DIRECT_SCALE_RANGE.0 && len_sq < DIRECT_SCALE_RANGE.1 {
        v * (1.0 / len_sq.sqrt())
    } else {
        normalize_scaled(v, fallback)
    }
}

/// Largest |‖v‖² − 1| that [`renormalize`] corrects by one Newton step.
const NEARLY_UNIT: f32 = 1.0 / 4096.0;

/// A vector that is unit up to rounding (e.g. a reflection of unit vectors), made unit again
/// without a square root or a division: v (3 − ‖v‖²)/2 is the Newton step for 1/‖v‖ from 1,
/// whose relative error (3/8)ε² for ‖v‖² = 1 + ε is below 2.3e-8 for |ε| ≤ 2⁻¹². Other
/// vectors go through [`normalize_fast`].
#[inline(always)]
pub(crate) fn renormalize(v: Vec3, fallback: Vec3) -> Vec3 {
    let len_sq = v.length_squared();
    if (len_sq - 1.0).abs() <= NEARLY_UNIT { v * (1.5 - 0.5 * len_sq) } else { normalize_fast(v, fallback) }
}

/// `v` normalized after dividing by its largest component, so that tiny (even subnormal) and
/// huge vectors come out unit; `fallback` for a zero or non-finite vector.
#[inline(always)]
pub(crate) fn normalize_scaled(v: Vec3, fallback: Vec3) -> Vec3 {
    let scale = v.abs().max_element();
    if !(scale > 0.0 && scale.is_finite()) {
        return fallback;
    }
    (v / scale).normalize()
}
