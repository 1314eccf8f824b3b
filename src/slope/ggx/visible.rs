//! The GGX visible-normal kernels: the spherical-cap method (Dupuy and Benyoub 2023,
//! “Sampling Visible GGX Normals with Spherical Caps”) in the stretched configuration of α = 1,
//! exact on the whole sphere of incident directions, and its bounded cap for reflections (Eto
//! and Tokuyoshi 2023, “Bounded VNDF Sampling for Smith–GGX Reflections”, eqs. 5–8).

use super::Ggx;
use crate::lanes::{Lanes, V3};
use crate::rng::{TAIL_CUT, cut_tails};
use crate::slope::MicrosurfaceSlope;
use crate::special::{sin_cos_turns, sin_cos_turns_of};
use crate::vector::{
    DIRECT_SCALE_RANGE, VISIBLE_DOT_MARGIN, ensure_visible, normalize_fast, normalize_scaled,
};
use glam::{DVec3, Vec3};

/// A GGX visible normal for a unit ωi, exact for every ωi: stretch ωi to α = 1, sample the
/// visible hemisphere with the spherical cap, unstretch (Dupuy and Benyoub 2023, with the cap
/// z > −ωi.z, which is also valid for ωi.z < 0). The stretched ωi is not normalized: the cap
/// is sampled at its scale (a square root, no division). No argument check (the callers have
/// done it).
#[must_use]
#[inline(always)]
pub(crate) fn sample_spherical_cap(ggx: &Ggx, wi: Vec3, u1: f32, u2: f32) -> Vec3 {
    sample_stretched_cap(ggx, wi, CapBound::FULL, u1, u2)
}

/// [`sample_spherical_cap`]'s normal up to a positive scale, with its squared length
/// ([`sample_stretched_cap_scaled`]).
#[must_use]
#[inline(always)]
pub(crate) fn sample_spherical_cap_scaled(ggx: &Ggx, wi: Vec3, u1: f32, u2: f32) -> (Vec3, f32) {
    sample_stretched_cap_scaled(ggx, wi, CapBound::FULL, u1, u2)
}

/// The lower end of the cap of [`sample_visible_cap`], c.z ≥ −k v̂.z, given by κ = 1 + k ∈ (0, 2]
/// (κ = 2: the whole visible cap c.z ≥ −v̂.z of Dupuy and Benyoub; κ < 2: the bounded caps of
/// [`GgxBoundedCap`](crate::vndf::GgxBoundedCap)). Only views above the horizon (v.z > 0) are
/// bounded: below it the cap is always the whole visible one.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct CapBound {
    /// κ = 1 + k.
    pub(crate) kappa: f32,
}

impl CapBound {
    /// The whole visible cap, k = 1.
    pub(crate) const FULL: Self = Self { kappa: 2.0 };

    /// The cap's height scaled by len, len (1 + k v̂.z) = len + k v.z, written without
    /// cancellation: len + (κ − 1) v.z for κ ≥ 1 (κ − 1 exact), (len − v.z) + κ v.z with
    /// len − v.z = |v_xy|²/(len + v.z) for κ < 1, and |v_xy|²/(len − v.z) (= len + v.z) for
    /// the whole cap of a view below the horizon.
    #[inline(always)]
    pub(crate) fn top(self, v: Vec3, len: f32) -> f32 {
        top_of(self.kappa, V3::of(v), len)
    }

    /// [`Self::top`] in double precision (len = |v| in f64).
    #[inline(always)]
    pub(crate) fn top64(self, v: DVec3, len: f64) -> f64 {
        let kappa = f64::from(self.kappa);
        if v.z < 0.0 {
            (v.x * v.x + v.y * v.y) / (len - v.z)
        } else if kappa >= 1.0 {
            len + (kappa - 1.0) * v.z
        } else {
            (v.x * v.x + v.y * v.y) / (len + v.z) + kappa * v.z
        }
    }

    /// The height of the cap's bottom above the plane of −v, len (v̂.z − b) = (1 − k) v.z =
    /// (2 − κ) v.z ≥ 0: 0 for the whole cap (also below the horizon, where κ = 2), written −0
    /// there, the one addend the compiler drops: the cap's height (1 − u1) top + lift ≥ +0 is
    /// the same with (2 − κ) v.z = ±0 and without it, and for [`CapBound::FULL`] the addition
    /// folds away.
    #[inline(always)]
    fn lift(self, v: Vec3) -> f32 {
        if self.kappa == 2.0 { -0.0 } else { (2.0 - self.kappa) * v.z }
    }
}

/// [`CapBound::top`] for every lane type: len + (κ − 1) v.z for κ ≥ 1, |v_xy|²/(len + v.z) +
/// κ v.z for κ < 1, |v_xy|²/(len − v.z) below the horizon (where κ is always 2).
#[inline(always)]
pub(crate) fn top_of<L: Lanes>(kappa: L, v: V3<L>, len: L) -> L {
    let one = L::lit(1.0);
    L::choose(
        v.z.lt(L::lit(0.0)),
        || (v.x * v.x + v.y * v.y) / (len - v.z),
        || {
            L::choose(
                kappa.ge(one),
                || len + (kappa - one) * v.z,
                || (v.x * v.x + v.y * v.y) / (len + v.z) + kappa * v.z,
            )
        },
    )
}

/// [`sample_spherical_cap`] with the cap bounded below by `bound`: stretch, sample the cap
/// c.z ≥ −k v̂.z, unstretch. The same normalization as `sample_spherical_cap` (`bound` is
/// relative to v̂, so it holds for the rescaled v of huge or tiny stretched views).
#[must_use]
#[inline(always)]
pub(crate) fn sample_stretched_cap(ggx: &Ggx, wi: Vec3, bound: CapBound, u1: f32, u2: f32) -> Vec3 {
    unit_visible(wi, stretched_cap_point(ggx, wi, bound, u1, u2))
}

/// The robust finish of an unstretched cap point m: normalized ([`normalize_fast`]) and made
/// visible from ωi ([`ensure_visible`]).
#[inline(always)]
fn unit_visible(wi: Vec3, m: Vec3) -> Vec3 {
    ensure_visible(wi, normalize_fast(m, Vec3::Z))
}

/// The normal of [`sample_stretched_cap`] up to a positive scale: (m, |m|²). On the common
/// path m is the unstretched cap point itself (in the direct range and clearly visible,
/// [`scaled_visible_of`]), so that a caller whose formulas are homogeneous in the normal needs
/// neither its square root nor a division by it; elsewhere m is the unit normal of
/// [`sample_stretched_cap`]'s robust path and |m|² = 1.
#[must_use]
#[inline(always)]
pub(crate) fn sample_stretched_cap_scaled(
    ggx: &Ggx,
    wi: Vec3,
    bound: CapBound,
    u1: f32,
    u2: f32,
) -> (Vec3, f32) {
    let m = stretched_cap_point(ggx, wi, bound, u1, u2);
    let (len_sq, common) = scaled_visible_of(V3::of(wi), V3::of(m));
    if common { (m, len_sq) } else { (unit_visible(wi, m), 1.0) }
}

/// The unstretched cap point of [`sample_stretched_cap`], before its normalization: stretch
/// ωi (normalized directly in the safe range, rescaled otherwise), sample the cap, unstretch.
#[must_use]
#[inline(always)]
fn stretched_cap_point(ggx: &Ggx, wi: Vec3, bound: CapBound, u1: f32, u2: f32) -> Vec3 {
    let (alpha_x, alpha_y) = (ggx.alpha_x(), ggx.alpha_y());
    let stretched = stretch_of(alpha_x, alpha_y, V3::of(wi)).vec3();
    let len_sq = stretched.length_squared();
    let (v, len) = if in_direct_range(len_sq) {
        (stretched, len_sq.sqrt())
    } else {
        (normalize_scaled(stretched, Vec3::Z), 1.0)
    };
    let h = sample_visible_cap(v, len, bound, u1, u2);
    stretch_of(alpha_x, alpha_y, V3::of(h)).vec3()
}

/// |m|² of a normal m given up to its scale, and the mask of the lanes where m is used as it
/// is: |m|² in the direct range and m clearly visible from ωi, ωi·m > 0 and
/// (ωi·m)² > `VISIBLE_DOT_MARGIN`² |m|² (the test ωi·m̂ > `VISIBLE_DOT_MARGIN` of
/// [`ensure_visible`] without the square root). The others take the robust path
/// ([`ensure_visible`] on the normalized m).
#[inline(always)]
pub(crate) fn scaled_visible_of<L: Lanes>(wi: V3<L>, m: V3<L>) -> (L, L::Mask) {
    let len_sq = m.length_squared();
    let k = wi.dot(m);
    let margin = L::lit(VISIBLE_DOT_MARGIN);
    let visible = k.gt(L::lit(0.0)) & (k * k).gt(margin * margin * len_sq);
    (len_sq, in_direct_range(len_sq) & visible)
}

/// (αx x, αy y, z): the stretch of ωi to the α = 1 configuration, and the unstretch of a
/// sampled (unnormalized) normal back to (αx, αy).
#[inline(always)]
pub(crate) fn stretch_of<L: Lanes>(alpha_x: L, alpha_y: L, w: V3<L>) -> V3<L> {
    V3::new(alpha_x * w.x, alpha_y * w.y, w.z)
}

/// Whether a squared length is normalized directly (`DIRECT_SCALE_RANGE`).
#[inline(always)]
pub(crate) fn in_direct_range<L: Lanes>(len_sq: L) -> L::Mask {
    len_sq.gt(L::lit(DIRECT_SCALE_RANGE.0)) & len_sq.lt(L::lit(DIRECT_SCALE_RANGE.1))
}

/// The GGX visible normal of [`sample_stretched_cap`] for every lane type, on its common path,
/// with the cap bounded by κ ([`kappa_of`]; 2 for the whole cap of [`sample_spherical_cap`]):
/// the stretched ωi normalized directly, the cap point away from −v̂, the unstretched normal
/// normalized directly and clearly visible. Returns the normal and the mask of the lanes where
/// that path is the scalar sampler's, bit for bit; the others need the scalar sampler.
#[inline(always)]
pub(crate) fn sample_cap_of<L: Lanes>(
    alpha_x: L,
    alpha_y: L,
    wi: V3<L>,
    kappa: L,
    u1: L,
    u2: L,
) -> (V3<L>, L::Mask) {
    let (m, common) = cap_point_of(alpha_x, alpha_y, wi, kappa, u1, u2);
    let m_len_sq = m.length_squared();
    let m = m.scale(L::lit(1.0) / m_len_sq.sqrt());
    let visible = wi.dot(m).gt(L::lit(VISIBLE_DOT_MARGIN));
    (m, common & in_direct_range(m_len_sq) & visible)
}

/// [`sample_stretched_cap_scaled`] for every lane type on its common path (the whole cap,
/// κ = 2, or bounded as in [`sample_cap_of`]): the unstretched cap point m, |m|², and the mask
/// of the lanes where they are the scalar sampler's, bit for bit ([`scaled_visible_of`]).
#[inline(always)]
pub(crate) fn sample_cap_scaled_of<L: Lanes>(
    alpha_x: L,
    alpha_y: L,
    wi: V3<L>,
    kappa: L,
    u1: L,
    u2: L,
) -> (V3<L>, L, L::Mask) {
    let (m, common) = cap_point_of(alpha_x, alpha_y, wi, kappa, u1, u2);
    let (len_sq, scaled_common) = scaled_visible_of(wi, m);
    (m, len_sq, common & scaled_common)
}

/// [`stretched_cap_point`] for every lane type, with the mask of the lanes on its common path
/// (the stretched ωi normalized directly, the cap point away from −v̂).
#[inline(always)]
fn cap_point_of<L: Lanes>(alpha_x: L, alpha_y: L, wi: V3<L>, kappa: L, u1: L, u2: L) -> (V3<L>, L::Mask) {
    let v = stretch_of(alpha_x, alpha_y, wi);
    let len_sq = v.length_squared();
    let len = len_sq.sqrt();
    let lift = (L::lit(2.0) - kappa) * v.z;
    let (h, away) = cap_direct(v, len, top_of(kappa, v, len), lift, u1, u2);
    (stretch_of(alpha_x, alpha_y, h), in_direct_range(len_sq) & away)
}

/// Samples the normals of the unit upper hemisphere visible from the direction `v` of length
/// `len` > 0, with density ∝ max(0, v·m) on m.z ≥ 0; returns them **unnormalized** (`len`
/// times v̂ + c, of length in [0, 2 len]), since every caller rescales anyway.
///
/// normalize(v̂ + c) has density max(0, v̂·m)/π when c is uniform on the sphere (the map
/// c = reflect(v̂, m) has Jacobian 4 v̂·m); restricting m.z ≥ 0 restricts c to the cap
/// c.z ≥ −v̂.z, sampled uniformly by a uniform c.z. Everything is scaled by `len`, so that
/// v̂ = v/len is never formed. Returns 0 when v̂ = −z (empty cap).
///
/// The cap's height uniform u1 is cut to [2⁻²⁴, 1 − 2⁻²⁴] (the crate's tail policy, `rng`):
/// the sample for u1 = 0 has 2⁻²⁴ of the cap above it instead of sitting on its pole, the one
/// for u1 = 1 − 2⁻²⁴ has 2⁻²⁴ below it. The azimuth u2 is not cut.
///
/// The horizontal part v_xy + len c_xy is a sum of nearly opposite vectors where c approaches
/// −v̂ (the bottom of the cap, u1 → 1, on the far side): its f32 error, about 2ε len, is at most
/// 128ε ≈ 8e-6 relative (the direction of h) while |h| ≥ len/64, and beyond that h is
/// recomputed by [`cap_near_opposite`] without cancellation (error about ε): a half disk of
/// radius 1/64 around −v̂ on the cap, 6e-5/(1 + v̂.z) of the samples (0.03 % above the
/// horizon; about 1.5 % for the thin caps of far backfacing views, v̂.z = −0.998).
#[must_use]
#[inline(always)]
pub(crate) fn sample_visible_hemisphere(v: Vec3, len: f32, u1: f32, u2: f32) -> Vec3 {
    sample_visible_cap(v, len, CapBound::FULL, u1, u2)
}

/// [`sample_visible_hemisphere`] on the cap c.z ≥ −k v̂.z of `bound` (Eto and Tokuyoshi 2023):
/// c.z uniform in [−k v̂.z, 1], i.e. len c.z = (1 − u1) top − k v.z with top = len + k v.z
/// ([`CapBound`]'s cancellation-free form) and h.z = len c.z + v.z = (1 − u1) top + (1 − k) v.z;
/// len − len c.z is still exactly u1 top. The normals are those of the whole cap whose c lies
/// in the bounded one, each with the density max(0, v̂·m)/π scaled by (1 + v̂.z)/(1 + k v̂.z).
/// For the whole cap (κ = 2) top is len + v.z (or its backfacing form) and the lift an exact
/// 0: the map of Dupuy and Benyoub bit for bit.
#[must_use]
#[inline(always)]
pub(crate) fn sample_visible_cap(v: Vec3, len: f32, bound: CapBound, u1: f32, u2: f32) -> Vec3 {
    debug_assert!((0.0..=1.0).contains(&u2), "u2 = {u2} outside [0, 1]");
    let (h, away) = cap_direct(V3::of(v), len, bound.top(v, len), bound.lift(v), u1, u2);
    if away {
        return h.vec3();
    }
    cap_near_opposite(v, bound, cut_tails(u1), u2).unwrap_or(h.vec3())
}

/// The cap point h of [`sample_visible_cap`] in its direct form, for every lane type, given the
/// cap's scaled height `top` and `lift` ([`CapBound::top`], [`CapBound::lift`]; the whole cap's
/// for the lanes), with the mask of the lanes where it is away from −v̂ (|h| ≥ len/64: kept; the
/// others are recomputed by [`cap_near_opposite`]).
#[inline(always)]
pub(crate) fn cap_direct<L: Lanes>(v: V3<L>, len: L, top: L, lift: L, u1: L, u2: L) -> (V3<L>, L::Mask) {
    let u1 = u1.clamp(L::lit(TAIL_CUT), L::lit(1.0 - TAIL_CUT));
    // len·(c.z + v̂.z) = (1 − u1)(len + v.z), and len²(1 − c.z²) = len² − (len c.z)², whose
    // factor len − len c.z is exactly u1 (len + v.z): both without cancellation
    // len + v.z written as (v.x² + v.y²)/(len − v.z) below the horizon: for a backfacing ωi
    // of a low-roughness surface v̂ ≈ −z and the direct sum cancels (GGX α = 1e-4 at θ = 2.3:
    // it rounded to 0 and every sample became the fallback horizontal normal)
    let h_z = (L::lit(1.0) - u1) * top + lift;
    let z_scaled = h_z - v.z;
    let r = (u1 * top * (len + z_scaled)).max(L::lit(0.0)).sqrt();
    let (sin_phi, cos_phi) = sin_cos_turns_of(u2);
    let h = V3::new(r * cos_phi + v.x, r * sin_phi + v.y, h_z);
    // |h| ≥ h.z: the height alone clears the test for all but the bottom of the cap
    let near = L::lit(NEAR_OPPOSITE);
    let away = h_z.ge(near * len) | h.length_squared().ge(near * near * (len * len));
    (h, away)
}

/// |h| below this fraction of len is recomputed by [`cap_near_opposite`].
const NEAR_OPPOSITE: f32 = 1.0 / 64.0;

/// h = v + len c for a cap point c near −v̂, in double precision and in the azimuth frame of v:
/// with s = |v_xy|, ê = v_xy/s, ψ = 2π u2 − φo the azimuth of c_xy measured from −ê (φo the
/// azimuth of −ê, so that the map is the direct one up to the f32 error of its azimuth, a
/// fraction of one 2⁻²⁴ step of u2) and r = len |c_xy|, h_xy = (s − r cos ψ) ê − r sin ψ ê⊥
/// with s − r cos ψ = (s² − r²)/(s + r) + 2r sin²(ψ/2), all without cancellation: with
/// z = len c.z = (1 − u1)(len + v.z) − v.z and r² = u1 (len + v.z)(len + z) as in the direct
/// form, s² − r² = (z − v.z)(z + v.z). Here len = |v| in double precision: the f32 `len` of
/// the caller differs from |v| by ε len, and near −v̂ a sphere of that radius instead of |v|
/// moves the point by about as much as |h| itself. sin(ψ/2) and cos(ψ/2) come from
/// (sin, cos)(π u2) and the half angle of φo by the angle-difference formulas (no library
/// call). `None` for v along ±z (no cancellation there: v_xy = 0).
#[inline(never)]
fn cap_near_opposite(v: Vec3, bound: CapBound, u1: f32, u2: f32) -> Option<Vec3> {
    let (vx, vy, vz, u1) = (f64::from(v.x), f64::from(v.y), f64::from(v.z), f64::from(u1));
    let s_sq = vx * vx + vy * vy;
    if s_sq == 0.0 {
        return None;
    }
    let s = s_sq.sqrt();
    let len = (s_sq + vz * vz).sqrt();
    // as in the f32 form: len + v.z = |v_xy|²/(len − v.z) below the horizon, without cancellation
    // and bounded as in `CapBound::top` and `CapBound::lift`
    let top = bound.top64(DVec3::new(vx, vy, vz), len);
    let h_z = (1.0 - u1) * top + (2.0 - f64::from(bound.kappa)) * vz;
    let z = h_z - vz;
    let r = (u1 * top * (len + z)).max(0.0).sqrt();
    let s_sq_minus_r_sq = (z - vz) * h_z;
    // half angle of φo ∈ (−π, π]: cos(φo/2) ≥ 0, sin(φo/2) with the sign of sin φo, each from
    // the half-angle formula that does not cancel (φo = ±π for sin φo = ±0 give the same h)
    let (cos_o, sin_o) = (-vx / s, -vy / s);
    let (sin_oh, cos_oh) = if cos_o >= 0.0 {
        let c = (0.5 * (1.0 + cos_o)).sqrt();
        (sin_o / (2.0 * c), c)
    } else {
        let sh = (0.5 * (1.0 - cos_o)).sqrt().copysign(sin_o);
        (sh, sin_o / (2.0 * sh))
    };
    let (sin_a, cos_a) = sin_cos_turns(0.5 * u2);
    let (sin_a, cos_a) = (f64::from(sin_a), f64::from(cos_a));
    let unit = 1.0 / (sin_a * sin_a + cos_a * cos_a).sqrt();
    let (sin_a, cos_a) = (sin_a * unit, cos_a * unit);
    let sin_half = sin_a * cos_oh - cos_a * sin_oh;
    let cos_half = cos_a * cos_oh + sin_a * sin_oh;
    let along = s_sq_minus_r_sq / (s + r) + 2.0 * r * sin_half * sin_half;
    let across = -2.0 * r * sin_half * cos_half;
    let (ex, ey) = (vx / s, vy / s);
    Some(Vec3::new((along * ex - across * ey) as f32, (along * ey + across * ex) as f32, h_z as f32))
}

/// Relative margin added to κ = 1 + k (a larger k is always valid).
const KAPPA_MARGIN: f32 = 1.0 + 1.0 / 1_048_576.0; // 1 + 2⁻²⁰
/// Largest a² the bound uses (a = min(αx, αy) clamped to 1e3).
const MAX_BOUND_ALPHA_SQ: f32 = 1e6;

/// The bound of eqs. 5–6 for a view ωi (any length: the bound depends on its direction):
/// κ = 1 + k from sin θi = |ωi,xy|/|ωi| and a = min(αx, αy, 1e3), raised by 2⁻²⁰ relative and
/// at most 2 (the whole cap); the whole cap for ωi.z ≤ 0 (and for NaN). See
/// [`GgxBoundedCap`](crate::vndf::GgxBoundedCap) for the bound and the cancellation-free forms. (A NaN κ, which valid input never gives,
/// becomes 2 through `f32::min`.)
#[must_use]
#[inline(always)]
pub(crate) fn cap_bound(ggx: &Ggx, wi: Vec3) -> CapBound {
    if wi.z <= 0.0 {
        return CapBound::FULL;
    }
    CapBound { kappa: kappa_of(ggx.alpha_x().min(ggx.alpha_y()), V3::of(wi)) }
}

/// κ of [`cap_bound`] for a view above the horizon, for every lane type; `alpha` = min(αx, αy).
#[inline(always)]
pub(crate) fn kappa_of<L: Lanes>(alpha: L, wi: V3<L>) -> L {
    let one = L::lit(1.0);
    let a_sq = (alpha * alpha).min(L::lit(MAX_BOUND_ALPHA_SQ));
    let t_sq = wi.x * wi.x + wi.y * wi.y;
    // sin θ = t/r with t = |ωi,xy| and r = |ωi|, which is 1 within 5e-4 (1 − 1e-3 ≤ r² ≤ 1 +
    // 1e-3, the crate's direction tolerance): r = (1 + r²)/2 to within (r² − 1)²/8 ≤ 1.3e-7
    // relative, without a square root. κ is written homogeneous in (t, r), with σ₊ = r + t
    // and σ₋ = r − t, whose cancellation near grazing costs at most ε r absolute in terms
    // that are at least r (a ≤ 1: σ₊ + a² σ₋) or a² r (a > 1), i.e. a few ulps of κ
    let (t, r) = (t_sq.sqrt(), L::lit(0.5) * (one + (t_sq + wi.z * wi.z)));
    let (plus, minus) = (r + t, r - t);
    let smooth = a_sq.le(one);
    let numerator = L::choose(smooth, || r + (one - a_sq) * t, || minus + a_sq * t);
    let denominator = L::choose(smooth, || plus + a_sq * minus, || minus + a_sq * plus);
    (L::lit(2.0) * numerator / denominator * L::lit(KAPPA_MARGIN)).min(L::lit(2.0))
}

/// A reflection normal from the bounded cap of ωi (unit), no argument check: the spherical
/// cap's stretch, cap and unstretch with the cap bounded by [`cap_bound`].
#[must_use]
#[inline(always)]
pub(crate) fn sample_bounded_cap(ggx: &Ggx, wi: Vec3, u1: f32, u2: f32) -> Vec3 {
    sample_stretched_cap(ggx, wi, cap_bound(ggx, wi), u1, u2)
}

/// The bounded projected area A_b = (L + k ωi.z)/2 of a unit ωi (A for ωi.z ≤ 0), in f32 from
/// the cancellation-free forms of [`CapBound`] (relative error a few ulps).
#[must_use]
#[inline(always)]
pub(crate) fn bounded_area(ggx: &Ggx, wi: Vec3) -> f32 {
    bounded_area_of(ggx.alpha_x(), ggx.alpha_y(), V3::of(wi), cap_bound(ggx, wi).kappa)
}

/// [`bounded_area`] for every lane type, given κ: L as the sampler forms it
/// ([`sample_stretched_cap`], [`sample_cap_of`]), so that the two share it.
#[inline(always)]
pub(crate) fn bounded_area_of<L: Lanes>(alpha_x: L, alpha_y: L, wi: V3<L>, kappa: L) -> L {
    let v = stretch_of(alpha_x, alpha_y, wi);
    L::lit(0.5) * top_of(kappa, v, v.length_squared().sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The cancellation-free form of the cap describes the same point as the direct one: where
    /// the direct form is still accurate (len/64 ≤ |h| ≤ len/2, error ≤ 128ε), the two
    /// directions agree to 2e-5. Away from the poles of v only: the direct form's len ± v.z
    /// cancel as v̂.z → ∓1 (relative error ε/(1 ± v̂.z) in r, measured 3e-4 in h at
    /// 1 − |v̂.z| = 1e-4), which the cancellation-free form, in f64, does not share.
    #[test]
    fn cap_near_opposite_is_the_direct_map() {
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 40) as f32 / 16_777_216.0
        };
        let (mut compared, mut worst) = (0, 0.0f64);
        for _ in 0..400_000 {
            let theta = core::f32::consts::PI * next();
            let phi = core::f32::consts::TAU * next();
            let scale = [0.05f32, 0.5, 1.0, 3.0][(4.0 * next()) as usize % 4];
            let v = Vec3::new(scale * theta.sin() * phi.cos(), scale * theta.sin() * phi.sin(), theta.cos());
            let len = v.length();
            if v.z.abs() > 0.9 * len {
                continue;
            }
            // u1 near 1 and u2 near the far side, where |h| is small
            let (u1, u2) = (1.0 - 0.05 * next() * next(), next());
            let top = len + v.z;
            let h_z = (1.0 - u1) * top;
            let r = (u1 * top * (len + h_z - v.z)).max(0.0).sqrt();
            let (sin_phi, cos_phi) = sin_cos_turns(u2);
            let direct = Vec3::new(r * cos_phi + v.x, r * sin_phi + v.y, h_z);
            let ratio = direct.length() / len;
            if !(1.0 / 64.0..=0.5).contains(&ratio) {
                continue;
            }
            let Some(exact) = cap_near_opposite(v, CapBound::FULL, u1, u2) else { continue };
            let gap = f64::from((direct.normalize() - exact.normalize()).length());
            worst = worst.max(gap);
            compared += 1;
        }
        eprintln!("cap_near_opposite vs direct: {compared} samples, largest gap {worst:.2e}");
        assert!(compared > 1000, "only {compared} samples compared");
        assert!(worst < 2e-5, "the two forms differ by {worst:e}");
    }
}
