//! The V-cavity microsurface as an alternative masking model (Tokuyoshi, supplement §2).

use super::VisibleNormalSampler;
use super::disk::{half_space_band, sample_band};
use crate::slope::{
    Beckmann, Ggx, MicrosurfaceSlope, gaussian_slope, normal_from_slopes, visible_slope_x_above,
};
use crate::special::{erfc64, erfinv_from_both_ends};
use glam::{Vec2, Vec3};

/// 1/√π.
const INV_SQRT_PI: f64 = 0.564_189_583_547_756_3;
/// The V-cavity boundary between the two forms of the backfacing VNDF is the slope
/// 3 cot θ (Tokuyoshi, eq. 4).
const BOUNDARY_SLOPE_FACTOR: f32 = 3.0;

/// Slope distributions with the closed forms the V-cavity model needs: the hit probability
/// H(i) and restricted samplers (Tokuyoshi, supplement §2.2–2.3).
pub trait VCavitySlope: MicrosurfaceSlope {
    /// The hit probability H(i) = ∫ G(i, m) max(i·m, 0) D(m) dm / |i·n| (§2.2): 1 for
    /// i.z ≥ 0; for i.z < 0 in closed form.
    fn hit_probability(&self, wi: Vec3) -> f32;

    /// ∫_{x < boundary} P2(x) dx: the share of D(m) m.z on the side m·k > 0 of the plane with
    /// normal k (unit or not).
    fn frontfacing_proportion(&self, k: Vec3) -> f32;

    /// A normal distributed as D(m) m.z restricted to m·k > 0 (k = +z: unrestricted).
    fn sample_projected(&self, k: Vec3, u1: f32, u2: f32) -> Vec3;

    /// A normal distributed as the Smith VNDF of ωi restricted to m·k ≤ 0.
    fn sample_unmasked(&self, wi: Vec3, k: Vec3, u1: f32, u2: f32) -> Vec3;
}

/// Stretches a direction by the roughness: (αx x, αy y, z).
#[inline(always)]
fn stretch<S: MicrosurfaceSlope>(slope: &S, w: Vec3) -> Vec3 {
    Vec3::new(slope.alpha_x() * w.x, slope.alpha_y() * w.y, w.z)
}

/// The horizontal unit vector of the azimuth of `w` (x if vertical) and its perpendicular.
#[inline(always)]
fn azimuth_frame(w: Vec3) -> (Vec2, Vec2) {
    let len = (w.x * w.x + w.y * w.y).sqrt();
    let e = if len > 0.0 { Vec2::new(w.x / len, w.y / len) } else { Vec2::X };
    (e, e.perp())
}

impl VCavitySlope for Ggx {
    /// 1 + (√(q + 9 i_z²) − √(q + i_z²))/(2 i_z) below the horizon (q = αx² i_x² + αy² i_y²),
    /// evaluated as 1 + 4 i_z/(√(q + 9 i_z²) + √(q + i_z²)).
    fn hit_probability(&self, wi: Vec3) -> f32 {
        if wi.z >= 0.0 {
            return 1.0;
        }
        let q = stretch(self, wi).truncate().length_squared();
        let z2 = wi.z * wi.z;
        1.0 + 4.0 * wi.z / ((q + 9.0 * z2).sqrt() + (q + z2).sqrt())
    }

    /// ½ + k_z / (2√(αx² k_x² + αy² k_y² + k_z²)).
    fn frontfacing_proportion(&self, k: Vec3) -> f32 {
        let ks = stretch(self, k);
        0.5 + 0.5 * ks.z / ks.length()
    }

    /// In the stretched configuration D m.z is uniform on the projected disk; the plane
    /// m·k = 0 cuts it along the azimuth of k (Tokuyoshi, listing 2).
    fn sample_projected(&self, k: Vec3, u1: f32, u2: f32) -> Vec3 {
        let ks = stretch(self, k).normalize_or(Vec3::Z);
        let (e, f) = azimuth_frame(ks);
        let (lo, hi) = (-ks.z, 1.0);
        let (w, u) = sample_band(u1, u2, lo, hi);
        let z = (1.0 - u * u - w * w).max(0.0).sqrt();
        let (x, y) = (u * e.x + w * f.x, u * e.y + w * f.y);
        Vec3::new(self.alpha_x() * x, self.alpha_y() * y, z).normalize_or(Vec3::Z)
    }

    /// The disk method of Heitz 2018 with the band limited by both the horizon and the plane
    /// m·k = 0 (Tokuyoshi, listing 3).
    fn sample_unmasked(&self, wi: Vec3, k: Vec3, u1: f32, u2: f32) -> Vec3 {
        let v = stretch(self, wi).normalize_or(Vec3::Z);
        let ks = stretch(self, k).normalize_or(Vec3::Z);
        let len_xy = (v.x * v.x + v.y * v.y).sqrt();
        let (t1_axis, t2_axis) = if len_xy > 0.0 {
            let t1 = Vec3::new(-v.y / len_xy, v.x / len_xy, 0.0);
            (t1, v.cross(t1))
        } else {
            (Vec3::Y, Vec3::X)
        };
        let (lo_h, hi_h) = half_space_band(t2_axis.z, v.z, true);
        let (lo_k, hi_k) = half_space_band(t2_axis.dot(ks), v.dot(ks), false);
        let (lo, hi) = (lo_h.max(lo_k), hi_h.min(hi_k).max(lo_h.max(lo_k)));
        let (t1, t2) = sample_band(u1, u2, lo, hi);
        let t3 = (1.0 - t1 * t1 - t2 * t2).max(0.0).sqrt();
        let h = t1 * t1_axis + t2 * t2_axis + t3 * v;
        Vec3::new(self.alpha_x() * h.x, self.alpha_y() * h.y, h.z.max(0.0)).normalize_or(Vec3::Z)
    }
}

impl VCavitySlope for Beckmann {
    /// 1 + (e^{−9u²} − e^{−u²})/(2√π u) + (3 erf(3u) − erf(u))/2 below the horizon,
    /// u = i_z/√(αx² i_x² + αy² i_y²) (§2.2); evaluated with w = −u > 0 as
    /// (3 erfc(3w) − erfc(w))/2 − e^{−w²} expm1(−8w²)/(2√π w), without cancellation at w → 0.
    fn hit_probability(&self, wi: Vec3) -> f32 {
        if wi.z >= 0.0 {
            return 1.0;
        }
        let q = f64::from(stretch(self, wi).truncate().length_squared());
        if q == 0.0 {
            return 0.0;
        }
        let w = -f64::from(wi.z) / q.sqrt();
        let gauss = -(-w * w).exp() * (-8.0 * w * w).exp_m1() * 0.5 * INV_SQRT_PI / w;
        (0.5 * (3.0 * erfc64(3.0 * w) - erfc64(w)) + gauss).max(0.0) as f32
    }

    /// ½ erfc(−k_z/√(αx² k_x² + αy² k_y²)).
    fn frontfacing_proportion(&self, k: Vec3) -> f32 {
        let ks = stretch(self, k);
        let len = f64::from(ks.truncate().length());
        if len == 0.0 {
            return if ks.z > 0.0 { 1.0 } else { 0.0 };
        }
        (0.5 * erfc64(-f64::from(ks.z) / len)) as f32
    }

    /// Gaussian slopes, the one along the azimuth of k truncated to x̃ < k_z/|k_xy|
    /// (Tokuyoshi, listing 4), by inversion from the nearer end.
    fn sample_projected(&self, k: Vec3, u1: f32, u2: f32) -> Vec3 {
        let ks = stretch(self, k);
        let (e, f) = azimuth_frame(ks);
        let len = f64::from(ks.truncate().length());
        // share of N(0, ½) below the boundary, as a complement 2P = erfc(−boundary)
        let two_p = if len == 0.0 { 2.0 } else { erfc64(-f64::from(ks.z) / len) };
        let q = f64::from(u1) * two_p; // erfc(−x̃) = q
        let x = if q <= 1.0 {
            -erfinv_from_both_ends(1.0 - q, q.max(f64::MIN_POSITIVE))
        } else {
            erfinv_from_both_ends(q - 1.0, 2.0 - q)
        } as f32;
        let y = gaussian_slope(f64::from(u2)) as f32;
        let s = x * e + y * f;
        normal_from_slopes(self.alpha_x() * s.x, self.alpha_y() * s.y)
    }

    /// The exact visible-slope inversion limited to x̃ ∈ [3 cot θ, cot θ) (Tokuyoshi, listings
    /// 5–6, with the safeguarded log-space solver of [`Beckmann`]).
    fn sample_unmasked(&self, wi: Vec3, k: Vec3, u1: f32, u2: f32) -> Vec3 {
        let v = stretch(self, wi).normalize_or(Vec3::Z);
        let ks = stretch(self, k);
        let (e, f) = azimuth_frame(v);
        let sin_theta = f64::from(v.truncate().length());
        if sin_theta == 0.0 {
            return Vec3::Z;
        }
        let kappa = f64::from(v.z) / sin_theta;
        let lower = f64::from(ks.z) / f64::from(ks.truncate().length());
        let x = visible_slope_x_above(kappa, lower, f64::from(u1)) as f32;
        let y = gaussian_slope(f64::from(u2)) as f32;
        let s = x * e + y * f;
        normal_from_slopes(self.alpha_x() * s.x, self.alpha_y() * s.y)
    }
}

/// The V-cavity masking model over the slope distribution `S` (Tokuyoshi, supplement §2).
///
/// Masking G(i, m) = min(2 |m·n| |i·n| / |i·m|, 1) χ⁺(i·m) (eq. 3); single-sided facets,
/// so front-facing facets stay visible from below the horizon. The density of visible normals
/// is p(m; i) = G(i, m) max(i·m, 0) D(m) / (H(i) |i·n|) (eq. 4), which integrates to one on
/// the whole sphere of i.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VCavity<S>(pub S);

impl<S: VCavitySlope> VCavity<S> {
    /// The V-cavity masking function G(i, m) (eq. 3).
    #[inline]
    pub fn masking(&self, wi: Vec3, wm: Vec3) -> f32 {
        let cos_im = wi.dot(wm);
        if cos_im <= 0.0 {
            return 0.0;
        }
        (2.0 * wm.z.abs() * wi.z.abs() / cos_im).min(1.0)
    }

    /// The hit probability H(i) (§2.2).
    #[inline]
    pub fn hit_probability(&self, wi: Vec3) -> f32 {
        self.0.hit_probability(wi)
    }
}

impl<S: VCavitySlope> VisibleNormalSampler for VCavity<S> {
    /// Front-facing: a normal from D(m) m.z or its mirror image, chosen in proportion to their
    /// visible areas (Heitz and d'Eon 2014). Backfacing: with probability
    /// 2 ∫_{x<3cotθ} P2 / H(i) a normal from D(m) m.z limited to slopes below 3 cot θ, otherwise
    /// one from the Smith VNDF limited to [3 cot θ, cot θ) (Tokuyoshi, listing 1).
    fn sample(&self, wi: Vec3, u: [f32; 3]) -> Vec3 {
        if wi.z >= 0.0 {
            let m1 = self.0.sample_projected(Vec3::Z, u[0], u[1]);
            let m2 = Vec3::new(-m1.x, -m1.y, m1.z);
            let (a1, a2) = (wi.dot(m1).max(0.0), wi.dot(m2).max(0.0));
            return if a1 + a2 == 0.0 || u[2] * (a1 + a2) < a1 { m1 } else { m2 };
        }
        let boundary = Vec3::new(wi.x, wi.y, BOUNDARY_SLOPE_FACTOR * wi.z);
        let h = self.0.hit_probability(wi);
        if h <= 0.0 {
            return Vec3::Z;
        }
        let p = (2.0 * self.0.frontfacing_proportion(boundary) / h).min(1.0);
        if u[0] < p {
            self.0.sample_projected(boundary, u[0] / p, u[1])
        } else {
            self.0.sample_unmasked(wi, boundary, ((u[0] - p) / (1.0 - p)).min(1.0), u[1])
        }
    }

    /// G(i, m) max(i·m, 0) D(m) / (H(i) |i·n|); for i.z ≥ 0 (H = 1) written as
    /// 2 D(m) m.z (i·m)⁺ / ((i·m)⁺ + (i·m′)⁺) with m′ the mirror image of m, which stays finite at
    /// grazing incidence.
    fn pdf(&self, wi: Vec3, wm: Vec3) -> f32 {
        let cos_im = wi.dot(wm);
        if cos_im <= 0.0 || wm.z <= 0.0 {
            return 0.0;
        }
        if wi.z >= 0.0 {
            let mirrored = Vec3::new(-wm.x, -wm.y, wm.z);
            let total = cos_im + wi.dot(mirrored).max(0.0);
            return 2.0 * self.0.d(wm) * wm.z * cos_im / total;
        }
        let h = self.0.hit_probability(wi);
        if h <= 0.0 {
            return 0.0;
        }
        self.masking(wi, wm) * cos_im * self.0.d(wm) / (h * wi.z.abs())
    }
}
