//! The GGX (Trowbridge–Reitz) slope distribution.

use super::{
    DIRECT_SCALE_RANGE, MicrosurfaceSlope, check_roughness, ensure_visible, normalize_fast, normalize_scaled,
    projected_roughness_sq,
};
use crate::error::Error;
use crate::special::sin_cos_turns;
use core::f32::consts::FRAC_1_PI;
use glam::{DVec3, Vec2, Vec3};

/// Smallest cos θm kept when a sampled normal is turned into slopes (only
/// [`Ggx::sample_p22_11`]; the sampled normals themselves are exact).
const MIN_SLOPE_COS: f32 = f32::MIN_POSITIVE;

/// The anisotropic GGX slope distribution (Heitz et al. 2016, supplement §2.3):
///
/// P²²(x̃, ỹ) = 1 / (π αx αy (1 + x̃²/αx² + ỹ²/αy²)²),
/// Λ(ω) = (−1 + sign(a) √(1 + 1/a²))/2 with a = 1/(αᵢ tan θ).
///
/// Visible normals are sampled exactly on the whole sphere with the spherical-cap method of
/// Dupuy and Benyoub 2023 (“Sampling Visible GGX Normals with Spherical Caps”), which also
/// holds for incident directions below the horizon.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ggx {
    alpha_x: f32,
    alpha_y: f32,
}

impl Ggx {
    /// An anisotropic GGX distribution.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] if `alpha_x` or `alpha_y` is NaN, infinite or ≤ 0.
    pub fn new(alpha_x: f32, alpha_y: f32) -> Result<Self, Error> {
        let (alpha_x, alpha_y) = check_roughness(alpha_x, alpha_y)?;
        Ok(Self { alpha_x, alpha_y })
    }

    /// An isotropic GGX distribution, α = αx = αy.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] if `alpha` is NaN, infinite or ≤ 0.
    pub fn isotropic(alpha: f32) -> Result<Self, Error> {
        Self::new(alpha, alpha)
    }
}

/// Λ for the upper hemisphere from q = (αᵢ sin θ)² and z = cos θ ≥ 0, in the
/// cancellation-free form q / (2z(z + √(z² + q))); saturates to `f32::MAX` at z = 0.
#[inline(always)]
fn lambda_up(q: f32, z: f32) -> f32 {
    (q / (2.0 * z * (z + (z * z + q).sqrt()))).min(f32::MAX)
}

impl MicrosurfaceSlope for Ggx {
    #[inline]
    fn alpha_x(&self) -> f32 {
        self.alpha_x
    }

    #[inline]
    fn alpha_y(&self) -> f32 {
        self.alpha_y
    }

    #[inline]
    fn p22(&self, slope_x: f32, slope_y: f32) -> f32 {
        let (x, y) = (slope_x / self.alpha_x, slope_y / self.alpha_y);
        let t = 1.0 + x * x + y * y;
        FRAC_1_PI / (self.alpha_x * self.alpha_y * t * t)
    }

    /// D(ωm) = 1 / (π αx αy (m.x²/αx² + m.y²/αy² + m.z²)²) for m.z > 0: the slope form
    /// multiplied through by cos⁴θm, finite down to m.z = 0.
    #[inline]
    fn d(&self, wm: Vec3) -> f32 {
        if wm.z <= 0.0 {
            return 0.0;
        }
        let (x, y) = (wm.x / self.alpha_x, wm.y / self.alpha_y);
        let t = x * x + y * y + wm.z * wm.z;
        FRAC_1_PI / (self.alpha_x * self.alpha_y * t * t)
    }

    #[inline]
    fn d64(&self, wm: DVec3) -> f64 {
        if wm.z <= 0.0 {
            return 0.0;
        }
        let (ax, ay) = (f64::from(self.alpha_x), f64::from(self.alpha_y));
        let (x, y) = (wm.x / ax, wm.y / ay);
        let t = x * x + y * y + wm.z * wm.z;
        core::f64::consts::FRAC_1_PI / (ax * ay * t * t)
    }

    /// The f32 form's cancellation-free q / (2z(z + √(z² + q))) in f64.
    #[inline]
    fn lambda64(&self, w: Vec3) -> f64 {
        let (x, y) = (f64::from(self.alpha_x) * f64::from(w.x), f64::from(self.alpha_y) * f64::from(w.y));
        let (q, z) = (x * x + y * y, f64::from(w.z).abs());
        let up = q / (2.0 * z * (z + (z * z + q).sqrt()));
        if w.z >= 0.0 { up } else { -1.0 - up }
    }

    /// The f32 forms of [`Self::projected_area`] in f64.
    #[inline]
    fn projected_area64(&self, w: Vec3) -> f64 {
        let (x, y) = (f64::from(self.alpha_x) * f64::from(w.x), f64::from(self.alpha_y) * f64::from(w.y));
        let (q, z) = (x * x + y * y, f64::from(w.z));
        let root = (z * z + q).sqrt();
        if z >= 0.0 { 0.5 * (z + root) } else { q / (2.0 * (root - z)) }
    }

    #[inline]
    fn lambda(&self, w: Vec3) -> f32 {
        let q = projected_roughness_sq(self.alpha_x, self.alpha_y, w);
        if w.z >= 0.0 { lambda_up(q, w.z) } else { -1.0 - lambda_up(q, -w.z) }
    }

    /// ½(cos θ + √(cos²θ + αᵢ² sin²θ)) above the horizon (supplement §2.3) and the
    /// equivalent αᵢ² sin²θ / (2(√(cos²θ + αᵢ² sin²θ) − cos θ)) below it, which has no
    /// cancellation there.
    #[inline]
    fn projected_area(&self, w: Vec3) -> f32 {
        let q = projected_roughness_sq(self.alpha_x, self.alpha_y, w);
        let root = (w.z * w.z + q).sqrt();
        if w.z >= 0.0 { 0.5 * (w.z + root) } else { q / (2.0 * (root - w.z)) }
    }

    /// Visible slopes at α = 1 from the spherical-cap sampler. Slopes of normals that round
    /// to cos θm = 0 are computed with cos θm = `f32::MIN_POSITIVE` (finite, probability 0).
    #[inline]
    fn sample_p22_11(&self, cos_theta: f32, sin_theta: f32, u1: f32, u2: f32) -> Vec2 {
        // slopes are invariant under scaling, so the unnormalized normal serves
        let m = sample_visible_hemisphere(Vec3::new(sin_theta, 0.0, cos_theta), 1.0, u1, u2);
        let z = m.z.max(MIN_SLOPE_COS * m.length());
        Vec2::new(-m.x / z, -m.y / z)
    }

    /// Exact for every ωi: stretch ωi to α = 1, sample the visible hemisphere with the
    /// spherical cap, unstretch (Dupuy and Benyoub 2023, with the cap z > −ωi.z, which is
    /// also valid for ωi.z < 0). The stretched ωi is not normalized: the cap is sampled at its
    /// scale (a square root, no division).
    #[inline]
    fn sample_d_wi(&self, wi: Vec3, u1: f32, u2: f32) -> Vec3 {
        let stretched = Vec3::new(self.alpha_x * wi.x, self.alpha_y * wi.y, wi.z);
        let len_sq = stretched.length_squared();
        let (v, len) = if len_sq > DIRECT_SCALE_RANGE.0 && len_sq < DIRECT_SCALE_RANGE.1 {
            (stretched, len_sq.sqrt())
        } else {
            (normalize_scaled(stretched, Vec3::Z), 1.0)
        };
        let h = sample_visible_hemisphere(v, len, u1, u2);
        ensure_visible(wi, normalize_fast(Vec3::new(self.alpha_x * h.x, self.alpha_y * h.y, h.z), Vec3::Z))
    }
}

/// Samples the normals of the unit upper hemisphere visible from the direction `v` of length
/// `len` > 0, with density ∝ max(0, v·m) on m.z ≥ 0; returns them **unnormalized** (`len`
/// times v̂ + c, of length in [0, 2 len]), since every caller rescales anyway.
///
/// normalize(v̂ + c) has density max(0, v̂·m)/π when c is uniform on the sphere (the map
/// c = reflect(v̂, m) has Jacobian 4 v̂·m); restricting m.z ≥ 0 restricts c to the cap
/// c.z ≥ −v̂.z, sampled uniformly by a uniform c.z. Everything is scaled by `len`, so that
/// v̂ = v/len is never formed. Returns 0 when v̂ = −z (empty cap).
#[inline(always)]
fn sample_visible_hemisphere(v: Vec3, len: f32, u1: f32, u2: f32) -> Vec3 {
    // len·(c.z + v̂.z) = (1 − u1)(len + v.z), and len²(1 − c.z²) = len² − (len c.z)², whose
    // factor len − len c.z is exactly u1 (len + v.z): both without cancellation
    // len + v.z written as (v.x² + v.y²)/(len − v.z) below the horizon: for a backfacing ωi
    // of a low-roughness surface v̂ ≈ −z and the direct sum cancels (GGX α = 1e-4 at θ = 2.3:
    // it rounded to 0 and every sample became the fallback horizontal normal)
    let top = if v.z >= 0.0 { len + v.z } else { (v.x * v.x + v.y * v.y) / (len - v.z) };
    let z_scaled = (1.0 - u1) * top - v.z;
    let r = (u1 * top * (len + z_scaled)).max(0.0).sqrt();
    let (sin_phi, cos_phi) = sin_cos_turns(u2);
    let h = Vec3::new(r * cos_phi + v.x, r * sin_phi + v.y, (1.0 - u1) * top);
    // v·h ≥ 0 exactly; near c = −v̂ (measure zero) rounding can make it negative: then return
    // a grazing visible normal (the horizontal normal along v's azimuth is visible and in the
    // upper hemisphere)
    if v.dot(h) < 0.0 { Vec3::new(v.x, v.y, 0.0) } else { h }
}
