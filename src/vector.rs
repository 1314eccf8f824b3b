//! Vector kernels of the samplers and walks: normalization that survives tiny and huge
//! vectors, the cheap renormalization of nearly unit vectors, normals from slopes, and the
//! visibility guarantee of sampled normals.

use glam::Vec3;

/// An f32 dot product of two unit vectors above this is positive in exact arithmetic too
/// (its rounding error is at most 3 ulp of 1 ≈ 1.8e-7).
pub(crate) const VISIBLE_DOT_MARGIN: f32 = 1e-6;

/// Largest number of halvings tried by [`ensure_visible`].
const VISIBILITY_NUDGES: i32 = 24;

/// A sampled normal with ωi·ωm > 0 as evaluated in f64 from the f32 vectors (what `d_wi`
/// tests). Exact sampling gives ωi·ωm > 0; rounding the normal to f32 can flip the sign for
/// normals within about 1e-7 rad of the visibility boundary (grazing or backfacing ωi, low α).
/// Those are moved towards ωi by the smallest power-of-two step that makes them visible (and
/// kept in the upper hemisphere): a displacement of ~1e-7 rad of a mass of order 1e-5.
#[must_use]
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
#[must_use]
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
#[must_use]
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
#[must_use]
#[inline(always)]
pub(crate) fn renormalize(v: Vec3, fallback: Vec3) -> Vec3 {
    let len_sq = v.length_squared();
    if (len_sq - 1.0).abs() <= NEARLY_UNIT { v * (1.5 - 0.5 * len_sq) } else { normalize_fast(v, fallback) }
}

/// `v` normalized after dividing by its largest component, so that tiny (even subnormal) and
/// huge vectors come out unit; `fallback` for a zero or non-finite vector.
#[must_use]
#[inline(always)]
pub(crate) fn normalize_scaled(v: Vec3, fallback: Vec3) -> Vec3 {
    let scale = v.abs().max_element();
    // `max_element` skips a NaN component next to finite ones: test the vector itself
    if !(scale > 0.0 && scale.is_finite()) || v.is_nan() {
        return fallback;
    }
    (v / scale).normalize()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A small deterministic generator of uniforms in [0, 1) (xorshift64).
    fn uniforms(seed: u64) -> impl FnMut() -> f32 {
        let mut state = seed;
        move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 40) as f32 / 16_777_216.0
        }
    }

    fn direction(next: &mut impl FnMut() -> f32) -> Vec3 {
        let z = 2.0 * next() - 1.0;
        let r = (1.0 - z * z).max(0.0).sqrt();
        let phi = core::f32::consts::TAU * next();
        Vec3::new(r * phi.cos(), r * phi.sin(), z)
    }

    fn length64(v: Vec3) -> f64 {
        v.as_dvec3().length()
    }

    /// Normals that are already visible are returned unchanged; normals a hair on the wrong
    /// side of the visibility boundary (⟨ωi, ωm⟩ ≤ 0 in f64, what the densities test) are made
    /// visible by a move of at most 2⁻⁵ε·2²⁴ = 1e-6 rad towards ωi, stay unit and in the upper
    /// hemisphere.
    #[test]
    fn ensure_visible_moves_only_invisible_normals_and_barely() {
        let mut next = uniforms(0x9e37_79b9_7f4a_7c15);
        let (mut moved, mut largest_move) = (0, 0.0f64);
        for _ in 0..20_000 {
            let wi = direction(&mut next);
            // a unit normal on or just behind the boundary ⟨ωi, m⟩ = 0, in the upper hemisphere
            let t = Vec3::new(-wi.y, wi.x, 0.0);
            let t = if t.length_squared() > 1e-6 { t.normalize() } else { Vec3::X };
            let edge = wi.cross(t).normalize();
            let edge = if edge.z < 0.0 { -edge } else { edge };
            let behind = (edge - 1e-7 * next() * wi).normalize();
            for wm in [edge, behind] {
                if wm.z < 0.0 || !wm.is_finite() {
                    continue;
                }
                let out = ensure_visible(wi, wm);
                let dot = wi.as_dvec3().dot(out.as_dvec3());
                if wi.as_dvec3().dot(wm.as_dvec3()) > 0.0 {
                    assert_eq!(out, wm, "a visible normal was moved (ωi = {wi}, ωm = {wm})");
                    continue;
                }
                moved += 1;
                assert!(dot > 0.0, "still invisible: ωi = {wi}, ωm = {wm} → {out}, ⟨ωi, ωm⟩ = {dot:e}");
                assert!(out.z >= 0.0, "below the horizon: {out}");
                assert!((length64(out) - 1.0).abs() < 4e-7, "not unit: |{out}| = {}", length64(out));
                let angle = (out - wm).as_dvec3().length();
                largest_move = largest_move.max(angle);
            }
        }
        eprintln!("ensure_visible: {moved} normals moved, largest move {largest_move:e} rad");
        assert!(moved > 1000, "only {moved} invisible normals were constructed");
        assert!(largest_move <= 1e-6, "moved by {largest_move:e} rad");
        // a clearly visible normal is left alone; one far on the wrong side (which no exact
        // sampler produces) is still made visible, by the last, large steps
        assert_eq!(ensure_visible(Vec3::Z, Vec3::Z), Vec3::Z);
        let (wi, away) = (Vec3::new(0.0, -0.8, -0.6), Vec3::new(0.0, 0.6, 0.8));
        assert!(wi.as_dvec3().dot(ensure_visible(wi, away).as_dvec3()) > 0.0);
    }

    /// One Newton step makes a nearly unit vector unit: for ‖v‖² = 1 + ε, |ε| ≤ 2⁻¹², the
    /// result is within (3/8)ε² + 4 ulp of unit length and keeps its direction; other vectors
    /// (tiny, huge, far from unit) are normalized through `normalize_fast`.
    #[test]
    fn renormalize_makes_nearly_unit_vectors_unit() {
        let mut next = uniforms(0x2545_f491_4f6c_dd1d);
        let mut worst = 0.0f64;
        for _ in 0..100_000 {
            let u = direction(&mut next);
            let eps = (2.0 * next() - 1.0) * NEARLY_UNIT;
            let v = u * (1.0 + eps).sqrt();
            let r = renormalize(v, Vec3::Z);
            let e = f64::from(eps);
            let bound = 0.375 * e * e + 4.0 * f64::from(f32::EPSILON) / 2.0;
            let err = (length64(r) - 1.0).abs();
            worst = worst.max(err);
            assert!(err <= bound, "|‖r‖ − 1| = {err:e} > {bound:e} for ε = {eps:e}");
            assert!((r.as_dvec3().normalize() - u.as_dvec3().normalize()).length() < 3e-7);
        }
        eprintln!("renormalize: worst |‖r‖ − 1| = {worst:e}");
        for v in [Vec3::new(3.0, 4.0, 0.0), Vec3::new(1e-20, 0.0, 1e-20), Vec3::new(1e25, -1e25, 0.0)] {
            let r = renormalize(v, Vec3::Z);
            assert!((length64(r) - 1.0).abs() < 4e-7, "|renormalize({v})| = {}", length64(r));
        }
    }

    /// `normalize_fast` and `normalize_scaled` give unit vectors along v for every finite
    /// non-zero v, from subnormal to `f32::MAX` components, and the fallback otherwise (also
    /// for a NaN component next to finite ones, which `max_element` skips).
    #[test]
    fn normalize_fast_and_scaled_cover_the_f32_range() {
        let mut next = uniforms(0x5851_f42d_4c95_7f2d);
        for _ in 0..20_000 {
            let d = direction(&mut next);
            // scales from 2⁻¹⁴⁹ (subnormal) to 2¹²⁷
            let exponent = (next() * 276.0) as i32 - 149;
            let scale = 2f32.powi(exponent.clamp(-126, 127))
                * if exponent < -126 { 2f32.powi(exponent + 126) } else { 1.0 };
            let v = d * scale;
            if v == Vec3::ZERO || !v.is_finite() {
                continue;
            }
            for n in [normalize_fast(v, Vec3::NAN), normalize_scaled(v, Vec3::NAN)] {
                assert!((length64(n) - 1.0).abs() < 4e-7, "|normalize({v})| = {}", length64(n));
                // along v (subnormal components carry few bits: compare with v's own direction)
                let along = v.as_dvec3().normalize();
                assert!((n.as_dvec3() - along).length() < 1e-6, "{v} → {n}");
            }
        }
        let huge = Vec3::new(f32::MAX, f32::MAX, -f32::MAX);
        assert!((length64(normalize_fast(huge, Vec3::NAN)) - 1.0).abs() < 4e-7);
        let tiny = Vec3::new(f32::from_bits(1), 0.0, f32::from_bits(1));
        assert!((normalize_fast(tiny, Vec3::NAN) - Vec3::new(1.0, 0.0, 1.0).normalize()).length() < 1e-6);
        for bad in [Vec3::ZERO, Vec3::new(f32::INFINITY, 0.0, 1.0), Vec3::new(f32::NAN, 1.0, 0.0), Vec3::NAN]
        {
            assert_eq!(normalize_fast(bad, Vec3::Y), Vec3::Y, "normalize_fast({bad})");
            assert_eq!(normalize_scaled(bad, Vec3::Y), Vec3::Y, "normalize_scaled({bad})");
        }
    }

    /// Normals from slopes: unit, pointing against the slope, and finite for huge and infinite
    /// slopes (an infinite slope is the horizontal normal).
    #[test]
    fn normal_from_slopes_is_unit_for_every_slope() {
        for (x, y) in
            [(0.0, 0.0), (0.3, -2.0), (1e17, 1.0), (1e19, -1e19), (f32::MAX, 0.0), (f32::INFINITY, 0.0)]
        {
            let n = normal_from_slopes(x, y);
            assert!(n.is_finite() && (length64(n) - 1.0).abs() < 4e-7, "normal_from_slopes({x}, {y}) = {n}");
            assert!(
                n.z >= 0.0 && (x == 0.0 || n.x.signum() == -x.signum()),
                "normal_from_slopes({x}, {y}) = {n}"
            );
            // slopes are −n.x/n.z, −n.y/n.z where representable
            if x.abs() < 1e6 && y.abs() < 1e6 {
                assert!(
                    (-n.x / n.z - x).abs() <= 1e-6 * (1.0 + x.abs())
                        && (-n.y / n.z - y).abs() <= 1e-6 * (1.0 + y.abs())
                );
            }
        }
        let n = normal_from_slopes(f32::INFINITY, 0.0);
        assert!(n.x == -1.0 && n.y == 0.0 && (0.0..1e-30).contains(&n.z), "horizontal: {n}");
    }
}
