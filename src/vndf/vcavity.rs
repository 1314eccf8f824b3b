//! The V-cavity microsurface as an alternative masking model (Tokuyoshi, supplement §2).

use super::VisibleNormalSampler;
use super::disk_band::{half_space_band, sample_band};
use crate::constants::INV_SQRT_PI;
use crate::contract::{are_uniform, is_direction, is_plane_normal};
use crate::rng::cut_tails64;
use crate::slope::{
    Azimuth, Beckmann, Ggx, MicrosurfaceSlope, disk_frame, gaussian_slope, stretch, stretch64,
    visible_slope_x_above,
};
use crate::special::{erfc64, erfcx64, erfinv_from_both_ends, one_minus_scaled_erfcx};
use glam::Vec3;
/// From this w = |i_z|/√q on, the Beckmann hit probability is evaluated in log space (its
/// direct form cancels and then underflows).
const LOG_SPACE_FROM: f64 = 8.0;
/// The V-cavity boundary between the two forms of the backfacing VNDF is the slope
/// 3 cot θ (Tokuyoshi, eq. 4).
const BOUNDARY_SLOPE_FACTOR: f32 = 3.0;

/// Slope distributions with the closed forms the V-cavity model needs: the hit probability
/// H(i) and restricted samplers (Tokuyoshi, supplement §2.2–2.3).
///
/// Sealed through [`MicrosurfaceSlope`]: implemented for [`Ggx`] and [`Beckmann`], the two
/// distributions with the closed forms; the tabulated distributions have no V-cavity model.
///
/// Invalid input ([policy](crate#invalid-input)): a `wi` or `wm` that is not a unit direction,
/// a plane normal `k` whose squared length is not a normal finite f32 (zero, NaN, ∞, or so
/// short or long that it under- or overflows; its length is otherwise free), or a uniform outside
/// [0, 1] trips a debug assertion in debug builds; release builds return NaN from the
/// probabilities, −∞ from `ln_d` (the logarithm of the density's nothing, 0) and a NaN normal
/// from the samplers.
pub trait VCavitySlope: MicrosurfaceSlope {
    /// The hit probability H(i) = ∫ G(i, m) max(i·m, 0) D(m) dm / |i·n| (§2.2): 1 for
    /// i.z ≥ 0; for i.z < 0 in closed form.
    fn hit_probability(&self, wi: Vec3) -> f32;

    /// ∫_{x < boundary} P2(x) dx: the share of D(m) m.z on the side m·k > 0 of the plane with
    /// normal k (unit or not).
    fn frontfacing_proportion(&self, k: Vec3) -> f32;

    /// ln H(i) in double precision (finite where H underflows in f32).
    fn ln_hit_probability(&self, wi: Vec3) -> f64 {
        require!(is_direction(wi), f64::NAN; wi);
        f64::from(self.hit_probability(wi)).ln()
    }

    /// For a backfacing i: the probability 2 ∫_{x<3cotθ} P2 / H(i) of the branch that samples
    /// D(m) m.z below the boundary slope (Tokuyoshi, eq. 5), in [0, 1].
    ///
    /// Invalid input ([policy](crate#invalid-input)): a `wi` that is not a unit direction, or
    /// is above the horizon (wi.z > 0, where the sampler has no such branch), gives NaN (a debug
    /// assertion in debug builds).
    fn projected_branch_probability(&self, wi: Vec3) -> f64 {
        require!(is_direction(wi) && wi.z <= 0.0, f64::NAN; wi);
        let boundary = Vec3::new(wi.x, wi.y, BOUNDARY_SLOPE_FACTOR * wi.z);
        let h = self.hit_probability(wi);
        if h <= 0.0 {
            0.0
        } else {
            (2.0 * f64::from(self.frontfacing_proportion(boundary)) / f64::from(h)).min(1.0)
        }
    }

    /// ln D(m) in double precision (−∞ where D is 0).
    fn ln_d(&self, wm: Vec3) -> f64 {
        require!(is_direction(wm), f64::NEG_INFINITY; wm);
        self.d64(wm.as_dvec3()).ln()
    }

    /// A normal distributed as D(m) m.z restricted to m·k > 0 (k = +z: unrestricted), from
    /// uniforms in [0, 1) whose quantiles' tails are cut at 2⁻²⁴ (the crate's tail policy).
    fn sample_projected(&self, k: Vec3, u1: f32, u2: f32) -> Vec3;

    /// A normal distributed as the Smith VNDF of ωi restricted to m·k ≤ 0, with tails cut at
    /// 2⁻²⁴ like [`Self::sample_projected`].
    fn sample_unmasked(&self, wi: Vec3, k: Vec3, u1: f32, u2: f32) -> Vec3;
}

impl VCavitySlope for Ggx {
    /// 1 + (√(q + 9 i_z²) − √(q + i_z²))/(2 i_z) below the horizon (q = αx² i_x² + αy² i_y²),
    /// evaluated without cancellation as q (1/(A + 3|i_z|) + 1/(B + |i_z|))/(A + B) with
    /// A = √(q + 9 i_z²), B = √(q + i_z²).
    fn hit_probability(&self, wi: Vec3) -> f32 {
        require!(is_direction(wi), f32::NAN; wi);
        if wi.z >= 0.0 {
            return 1.0;
        }
        let v = stretch64(self, wi);
        let q = v.x * v.x + v.y * v.y;
        let z = v.z.abs();
        let (a, b) = ((q + 9.0 * z * z).sqrt(), (q + z * z).sqrt());
        (q * (1.0 / (a + 3.0 * z) + 1.0 / (b + z)) / (a + b)) as f32
    }

    /// ½ + k_z / (2√(αx² k_x² + αy² k_y² + k_z²)).
    fn frontfacing_proportion(&self, k: Vec3) -> f32 {
        require!(is_plane_normal(k), f32::NAN; k);
        let ks = stretch(self, k);
        0.5 + 0.5 * ks.z / ks.length()
    }

    /// In the stretched configuration D m.z is uniform on the projected disk; the plane
    /// m·k = 0 cuts it along the azimuth of k (Tokuyoshi, listing 2).
    fn sample_projected(&self, k: Vec3, u1: f32, u2: f32) -> Vec3 {
        require!(is_plane_normal(k) && are_uniform(&[u1, u2]), Vec3::NAN; k, u1, u2);
        let ks = stretch(self, k).normalize_or(Vec3::Z);
        let azimuth = Azimuth::of(ks.x, ks.y);
        let (lo, hi) = (-ks.z, 1.0);
        let p = sample_band(u1, u2, lo, hi);
        let (w, u, z) = (p.t1, p.t2, p.t3);
        // the disk point (u along the azimuth of k, w across it) rotated and unstretched
        let h = azimuth.unstretch(self.alpha_x(), self.alpha_y(), u, w);
        Vec3::new(h.x, h.y, z).normalize_or(Vec3::Z)
    }

    /// The disk method of Heitz 2018 with the band limited by both the horizon and the plane
    /// m·k = 0 (Tokuyoshi, listing 3).
    fn sample_unmasked(&self, wi: Vec3, k: Vec3, u1: f32, u2: f32) -> Vec3 {
        require!(is_direction(wi) && is_plane_normal(k) && are_uniform(&[u1, u2]), Vec3::NAN; wi, k, u1, u2);
        let v = stretch(self, wi).normalize_or(Vec3::Z);
        let ks = stretch(self, k).normalize_or(Vec3::Z);
        let (t1_axis, t2_axis) = disk_frame(v);
        let (lo_h, hi_h) = half_space_band(t2_axis.z, v.z, true);
        let (lo_k, hi_k) = half_space_band(t2_axis.dot(ks), v.dot(ks), false);
        let (lo, hi) = (lo_h.max(lo_k), hi_h.min(hi_k).max(lo_h.max(lo_k)));
        let p = sample_band(u1, u2, lo, hi);
        let (t1, t2, t3) = (p.t1, p.t2, p.t3);
        let h = t1 * t1_axis + t2 * t2_axis + t3 * v;
        Vec3::new(self.alpha_x() * h.x, self.alpha_y() * h.y, h.z.max(0.0)).normalize_or(Vec3::Z)
    }
}

impl VCavitySlope for Beckmann {
    /// 1 + (e^{−9u²} − e^{−u²})/(2√π u) + (3 erf(3u) − erf(u))/2 below the horizon,
    /// u = i_z/√(αx² i_x² + αy² i_y²) (§2.2); evaluated with w = −u > 0 as
    /// (3 erfc(3w) − erfc(w))/2 − e^{−w²} expm1(−8w²)/(2√π w), without cancellation at w → 0.
    fn hit_probability(&self, wi: Vec3) -> f32 {
        require!(is_direction(wi), f32::NAN; wi);
        if wi.z >= 0.0 {
            return 1.0;
        }
        let q = f64::from(stretch(self, wi).truncate().length_squared());
        if q == 0.0 {
            return 0.0;
        }
        self.ln_hit_probability(wi).exp() as f32
    }

    /// ln H: directly for w < `LOG_SPACE_FROM`, otherwise
    /// −w² + ln(r(w)/(2√π w) + e^{−8w²}(3 erfcx(3w)/2 − 1/(2√π w))) with
    /// r(w) = 1 − √π w erfcx(w) from its asymptotic series (no underflow, no cancellation).
    fn ln_hit_probability(&self, wi: Vec3) -> f64 {
        require!(is_direction(wi), f64::NAN; wi);
        if wi.z >= 0.0 {
            return 0.0;
        }
        let v = stretch64(self, wi);
        let q = v.x * v.x + v.y * v.y;
        if q == 0.0 {
            return f64::NEG_INFINITY;
        }
        let w = -v.z / q.sqrt();
        if w < LOG_SPACE_FROM {
            let gauss = -(-w * w).exp() * (-8.0 * w * w).exp_m1() * 0.5 * INV_SQRT_PI / w;
            return (0.5 * (3.0 * erfc64(3.0 * w) - erfc64(w)) + gauss).max(0.0).ln();
        }
        let tail = one_minus_scaled_erfcx(w) * 0.5 * INV_SQRT_PI / w
            + (-8.0 * w * w).exp() * (1.5 * erfcx64(3.0 * w) - 0.5 * INV_SQRT_PI / w);
        -w * w + tail.ln()
    }

    /// erfc(3w)/H(i) in log space: −9w² + ln erfcx(3w) − ln H.
    fn projected_branch_probability(&self, wi: Vec3) -> f64 {
        // w = −v.z/√q ≥ 0 on and below the horizon: erfcx64 is evaluated on its domain u ≥ 0
        require!(is_direction(wi) && wi.z <= 0.0, f64::NAN; wi);
        let v = stretch64(self, wi);
        let q = v.x * v.x + v.y * v.y;
        if q == 0.0 {
            return 0.0;
        }
        let w = -v.z / q.sqrt();
        let ln_front = -9.0 * w * w + erfcx64(3.0 * w).ln();
        (ln_front - self.ln_hit_probability(wi)).exp().min(1.0)
    }

    /// −t − ln(π αx αy m.z⁴), t = (m.x²/αx² + m.y²/αy²)/m.z².
    fn ln_d(&self, wm: Vec3) -> f64 {
        require!(is_direction(wm), f64::NEG_INFINITY; wm);
        if wm.z <= 0.0 {
            return f64::NEG_INFINITY;
        }
        let (ax, ay) = (f64::from(self.alpha_x()), f64::from(self.alpha_y()));
        let m = wm.as_dvec3();
        let (x, y, z2) = (m.x / ax, m.y / ay, m.z * m.z);
        -(x * x + y * y) / z2 - (core::f64::consts::PI * ax * ay * z2 * z2).ln()
    }

    /// ½ erfc(−k_z/√(αx² k_x² + αy² k_y²)).
    fn frontfacing_proportion(&self, k: Vec3) -> f32 {
        require!(is_plane_normal(k), f32::NAN; k);
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
        require!(is_plane_normal(k) && are_uniform(&[u1, u2]), Vec3::NAN; k, u1, u2);
        let ks = stretch(self, k);
        let azimuth = Azimuth::of(ks.x, ks.y);
        let len = f64::from(ks.truncate().length());
        // share of N(0, ½) below the boundary, as a complement 2P = erfc(−boundary)
        let two_p = if len == 0.0 { 2.0 } else { erfc64(-f64::from(ks.z) / len) };
        // tails cut at 2⁻²⁴ (the crate's tail policy): u1 = 0 would give x̃ = −26.5
        let q = cut_tails64(f64::from(u1)) * two_p; // erfc(−x̃) = q
        let x = if q <= 1.0 {
            -erfinv_from_both_ends(1.0 - q, q.max(f64::MIN_POSITIVE))
        } else {
            erfinv_from_both_ends(q - 1.0, 2.0 - q)
        } as f32;
        let y = gaussian_slope(f64::from(u2)) as f32;
        azimuth.unstretched_normal(self.alpha_x(), self.alpha_y(), x, y)
    }

    /// The exact visible-slope inversion limited to x̃ ∈ [3 cot θ, cot θ) (Tokuyoshi, listings
    /// 5–6, with the safeguarded log-space solver of [`Beckmann`]).
    fn sample_unmasked(&self, wi: Vec3, k: Vec3, u1: f32, u2: f32) -> Vec3 {
        require!(is_direction(wi) && is_plane_normal(k) && are_uniform(&[u1, u2]), Vec3::NAN; wi, k, u1, u2);
        let v = stretch64(self, wi);
        let ks = stretch64(self, k);
        let azimuth = Azimuth::of(v.x as f32, v.y as f32);
        let len_xy = v.truncate().length();
        if len_xy == 0.0 {
            return Vec3::Z;
        }
        // cot θ in f64 (see `stretch64`)
        let kappa = v.z / len_xy;
        let lower = ks.z / ks.truncate().length();
        let x = visible_slope_x_above(kappa, lower, f64::from(u1)) as f32;
        let y = gaussian_slope(f64::from(u2)) as f32;
        azimuth.unstretched_normal(self.alpha_x(), self.alpha_y(), x, y)
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
    ///
    /// Invalid input ([policy](crate#invalid-input)): a `wi` or `wm` that is not a unit
    /// direction gives NaN (a debug assertion in debug builds).
    #[must_use]
    #[inline]
    pub fn masking(&self, wi: Vec3, wm: Vec3) -> f32 {
        require!(is_direction(wi) && is_direction(wm), f32::NAN; wi, wm);
        let cos_im = wi.dot(wm);
        if cos_im <= 0.0 {
            return 0.0;
        }
        (2.0 * wm.z.abs() * wi.z.abs() / cos_im).min(1.0)
    }

    /// The hit probability H(i) (§2.2).
    ///
    /// Invalid input ([policy](crate#invalid-input)): a `wi` that is not a unit direction gives
    /// NaN (a debug assertion in debug builds).
    #[must_use]
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
        require!(is_direction(wi) && are_uniform(&u), Vec3::NAN; wi, u);
        if wi.z >= 0.0 {
            let m1 = self.0.sample_projected(Vec3::Z, u[0], u[1]);
            let m2 = Vec3::new(-m1.x, -m1.y, m1.z);
            let (a1, a2) = (wi.dot(m1).max(0.0), wi.dot(m2).max(0.0));
            return if a1 + a2 == 0.0 || u[2] * (a1 + a2) < a1 { m1 } else { m2 };
        }
        let boundary = Vec3::new(wi.x, wi.y, BOUNDARY_SLOPE_FACTOR * wi.z);
        if self.0.ln_hit_probability(wi) == f64::NEG_INFINITY {
            return Vec3::Z;
        }
        let p = self.0.projected_branch_probability(wi) as f32;
        if !p.is_finite() {
            return Vec3::Z;
        }
        let m = if u[0] < p {
            self.0.sample_projected(boundary, u[0] / p, u[1])
        } else {
            self.0.sample_unmasked(wi, boundary, ((u[0] - p) / (1.0 - p)).min(1.0), u[1])
        };
        // straight from below (|i_xy| ~ 1e-38) the slopes overflow: nothing is visible there
        if m.is_finite() { m } else { Vec3::Z }
    }

    /// G(i, m) max(i·m, 0) D(m) / (H(i) |i·n|); for i.z ≥ 0 (H = 1) written as
    /// 2 D(m) m.z (i·m)⁺ / ((i·m)⁺ + (i·m′)⁺) with m′ the mirror image of m, which stays finite at
    /// grazing incidence.
    fn pdf(&self, wi: Vec3, wm: Vec3) -> f32 {
        require!(is_direction(wi) && is_direction(wm), 0.0; wi, wm);
        // the visibility test in f64, like the Smith densities (near the nadir ⟨i, m⟩ is tiny)
        if wi.as_dvec3().dot(wm.as_dvec3()) <= 0.0 || wm.z <= 0.0 {
            return 0.0;
        }
        let cos_im = wi.dot(wm);
        if wi.z >= 0.0 {
            let mirrored = Vec3::new(-wm.x, -wm.y, wm.z);
            let total = cos_im + wi.dot(mirrored).max(0.0);
            return 2.0 * self.0.d(wm) * wm.z * cos_im / total;
        }
        // G ⟨i, m⟩ D / (H |i_z|) with D/H in log space (both underflow far below the horizon)
        let ln_h = self.0.ln_hit_probability(wi);
        if ln_h == f64::NEG_INFINITY {
            return 0.0;
        }
        // the cosine and the masking in f64: near the nadir ⟨i, m⟩ is a small difference
        let cos_im = wi.as_dvec3().dot(wm.as_dvec3());
        if cos_im <= 0.0 {
            return 0.0;
        }
        let (mz, iz) = (f64::from(wm.z.abs()), f64::from(wi.z.abs()));
        let masking = (2.0 * mz * iz / cos_im).min(1.0);
        let value = masking * cos_im / iz * (self.0.ln_d(wm) - ln_h).exp();
        if value.is_finite() { value as f32 } else { 0.0 }
    }
}
