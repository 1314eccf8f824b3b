//! Slope distributions of the microsurface (Heitz et al. 2016, supplement §2).
//!
//! Every function here is valid on the whole sphere of directions (θ ∈ [0, π]), because the
//! random walks query directions below the horizon. Directions are unit vectors in the local
//! frame (z up). Λ is the signed Smith function, with Λ(−ω) = −1 − Λ(ω).

mod beckmann;
mod elliptical;
mod extract;
mod ggx;
mod grid;
mod noncentral;
mod tabulated;

pub use beckmann::Beckmann;
pub(crate) use beckmann::{gaussian_slope, one_minus_scaled_erfcx, visible_slope_x_above};
pub use elliptical::{AxisAlignedSlope, Elliptical};
pub use extract::{
    BackscatterShadowing, Extraction, GridExtraction, extract_anisotropic, extract_anisotropic_fn,
    extract_fresnel, extract_isotropic, extract_isotropic_fn,
};
pub use ggx::Ggx;
pub use grid::GridSlope;
pub use noncentral::Noncentral;
pub use tabulated::{MAX_RINGS, StretchedTabulated, TabulatedSlope};

pub(crate) use crate::contract::{is_direction, is_direction64, is_uniform};
use crate::error::Error;
use glam::{DVec3, Vec2, Vec3};

/// A slope distribution P²²(x̃, ỹ) with roughness (αx, αy) and everything derived from it
/// (`MicrosurfaceSlope` in Heitz et al. 2016, supplement §2.1).
///
/// Implementors provide the primitives `p22`, `d`, `lambda`, `projected_area` and
/// `sample_p22_11`; `alpha_i`, `d_wi` and `sample_d_wi` are derived (and may be overridden
/// with faster or more accurate forms).
///
/// Invalid input ([policy](crate#invalid-input)), the same for every method and every
/// implementation of the crate: a direction argument that is zero, has a NaN or ±∞ component,
/// or is not unit within [`DIRECTION_TOLERANCE`](crate::DIRECTION_TOLERANCE), a NaN slope, or
/// a uniform outside [0, 1] trips a debug assertion in debug builds; release builds return 0
/// from the densities (`p22`, `d`, `d64`, `d_wi`, `d_wi64`), NaN from `lambda`,
/// `projected_area` and `alpha_i`, and a NaN vector from the samplers (`sample_p22_11`,
/// `sample_d_wi`). Grazing and below-horizon unit directions are valid everywhere.
pub trait MicrosurfaceSlope: Copy + core::fmt::Debug + Send + Sync {
    /// Roughness along x.
    fn alpha_x(&self) -> f32;

    /// Roughness along y.
    fn alpha_y(&self) -> f32;

    /// The slope density P²²(x̃, ỹ), with slopes x̃ = −m.x/m.z and ỹ = −m.y/m.z.
    fn p22(&self, slope_x: f32, slope_y: f32) -> f32;

    /// The distribution of normals D(ωm) = P²²(x̃m, ỹm)/cos⁴θm for ωm.z > 0, and 0 otherwise
    /// (supplement §2.1). Implemented in a form that stays finite as ωm.z → 0.
    fn d(&self, wm: Vec3) -> f32;

    /// Smith's Λ(ω) on the whole sphere (supplement §2.2–2.3, with the sign of a kept).
    ///
    /// Λ ≥ 0 for ω.z > 0 (0 at the zenith), Λ(−ω) = −1 − Λ(ω) below the horizon (−1 at the
    /// nadir). At exactly grazing ω.z = ±0 (both signs of zero are the horizon seen from
    /// above) the exact value is +∞; the result saturates to `f32::MAX` there (and to
    /// −`f32::MAX` just below it), never leaving the finite numbers.
    fn lambda(&self, w: Vec3) -> f32;

    /// The projected area ∫⟨ω, ωm⟩ D(ωm) dωm = (1 + Λ(ω)) cos θ ≥ 0, for every ω
    /// (supplement §2.2–2.3), evaluated without forming 1 + Λ. It is cos θ at the zenith,
    /// 0 at the nadir and ½ αᵢ sin θ at the horizon.
    fn projected_area(&self, w: Vec3) -> f32;

    /// Λ(ω) in double precision, unsaturated: ±∞ at exactly grazing ω.z = ±0 (see
    /// [`Self::lambda`] for the rest of the contract).
    ///
    /// Below the horizon the masking of a backfacing direction is G1(ω) = 1/|1 + Λ(ω)| =
    /// 1/Λ(−ω), and Λ(−ω) is tiny there for small α (Beckmann: e^{−a²}, a = |cot θ|/αᵢ, an
    /// f32 subnormal from a ≈ 9.6 on); its f32 rounding loses all precision long before it
    /// reaches 0. The default widens [`Self::lambda`]; [`Ggx`] and [`Beckmann`] evaluate it in
    /// f64 (GGX's Λ ≥ 1e-106 for every f32 direction and α, so it never underflows; Beckmann's
    /// underflows f64 from a ≈ 26.6 on, see [`Self::ln_lambda`]).
    /// A precision primitive of the crate's walks and single scattering: no argument check
    /// (callers pass unit directions), hence hidden.
    #[doc(hidden)]
    #[inline]
    fn lambda64(&self, w: Vec3) -> f64 {
        f64::from(self.lambda_unchecked(w))
    }

    /// ln Λ(ω) for ω on or above the horizon (ω.z ≥ 0): −∞ at the zenith, +∞ at ω.z = 0;
    /// NaN below the horizon (outside the domain).
    ///
    /// The masking ratio Λ(ω′)/Λ(−ω) of a backfacing vertex (both factors tiny) is formed as
    /// exp(ln Λ(ω′) − ln Λ(−ω)) where Λ underflows in f64. The default is `lambda64(w).ln()`;
    /// [`Beckmann`] evaluates −a² + ln(r(a)/(2a√π)) directly, finite for every a > 0.
    /// A precision primitive of the crate's walks and single scattering: no argument check
    /// (callers pass unit directions), hence hidden.
    #[doc(hidden)]
    #[inline]
    fn ln_lambda(&self, w: Vec3) -> f64 {
        if w.z < 0.0 { f64::NAN } else { self.lambda64(w).ln() }
    }

    /// The projected area in double precision (see [`Self::projected_area`]): below the
    /// horizon it is Λ(−ω)|cos θ|, which underflows f32 far earlier than f64. The default
    /// widens [`Self::projected_area`]; [`Ggx`] and [`Beckmann`] evaluate it in f64.
    /// A precision primitive of the crate's walks and single scattering: no argument check
    /// (callers pass unit directions), hence hidden.
    #[doc(hidden)]
    #[inline]
    fn projected_area64(&self, w: Vec3) -> f64 {
        f64::from(self.projected_area_unchecked(w))
    }

    /// Samples visible slopes of the distribution stretched to α = 1, seen from the direction
    /// (sin θ, 0, cos θ), θ ∈ [0, π] (supplement §2.1, `sampleP22_11`).
    ///
    /// Takes cos θ and sin θ ≥ 0 rather than θ (either may be ±0, treated alike), and two
    /// uniforms in [0, 1). Implementations cut the tails of the quantiles they invert at 2⁻²⁴
    /// (u is used as clamp(u, 2⁻²⁴, 1 − 2⁻²⁴); the crate's tail policy): no sample lies
    /// beyond the last 2⁻²⁴ of the model.
    fn sample_p22_11(&self, cos_theta: f32, sin_theta: f32, u1: f32, u2: f32) -> Vec2;

    /// D for a normal given in double precision, evaluated in double precision. The default
    /// rounds the normal to f32; [`Ggx`] and [`Beckmann`] evaluate it in f64. The materials form
    /// their half vectors in f64 and call this: D amplifies the rounding of its argument in its
    /// tails and for small α (relative condition number up to 4(x̃/α)² for GGX, 2t for a
    /// Beckmann exponent t).
    #[inline]
    fn d64(&self, wm: DVec3) -> f64 {
        require!(is_direction64(wm), 0.0; wm);
        f64::from(self.d(wm.as_vec3()))
    }

    /// D_ωi(ωm) in double precision for ωm given in double precision (see [`Self::d64`]).
    #[inline]
    fn d_wi64(&self, wi: Vec3, wm: DVec3) -> f64 {
        require!(is_direction(wi) && is_direction64(wm), 0.0; wi, wm);
        smith_d_wi64(self, wi, wm)
    }

    /// The projected roughness αᵢ = √(cos²φ αx² + sin²φ αy²) in the azimuth of ω
    /// (supplement §2.1). At ω = ±z, where φ is undefined, returns αx.
    #[inline]
    fn alpha_i(&self, w: Vec3) -> f32 {
        require!(is_direction(w), f32::NAN; w);
        // scaled by the larger horizontal component so that x² + y² cannot underflow
        let scale = w.x.abs().max(w.y.abs());
        if scale == 0.0 {
            return self.alpha_x();
        }
        let (x, y) = (w.x / scale, w.y / scale);
        let (ax, ay) = (self.alpha_x() * x, self.alpha_y() * y);
        ((ax * ax + ay * ay) / (x * x + y * y)).sqrt()
    }

    /// The distribution of visible normals D_ωi(ωm) = ⟨ωi, ωm⟩ D(ωm) / projected_area(ωi)
    /// (supplement §2.1), for any ωi. Zero where ωi sees no microsurface (projected area 0,
    /// i.e. ωi = −z).
    ///
    /// ⟨ωi, ωm⟩ is evaluated in f64 from the f32 vectors, the visibility test that the samplers
    /// guarantee for their normals (`ensure_visible`): in f32 it rounds to ≤ 0 for normals
    /// within ~1e-7 of grazing, which the samplers do return (at the bottom of the spherical
    /// cap, u1 = 1 − 2⁻²⁴).
    #[inline]
    fn d_wi(&self, wi: Vec3, wm: Vec3) -> f32 {
        require!(is_direction(wi) && is_direction(wm), 0.0; wi, wm);
        let cos_im = wi.as_dvec3().dot(wm.as_dvec3());
        if cos_im <= 0.0 || wm.z <= 0.0 {
            return 0.0;
        }
        let area = self.projected_area(wi);
        if area <= 0.0 {
            return 0.0;
        }
        cos_im as f32 * self.d(wm) / area
    }

    /// Samples a normal ωm from D_ωi exactly, for any ωi on the sphere, from two uniforms in
    /// [0, 1) (supplement §2.1: stretch to α = 1, sample slopes, rotate, unstretch).
    ///
    /// Always returns a unit vector with ωm.z ≥ 0. For ωi = −z, which sees no microsurface,
    /// returns +z. Tails are cut at 2⁻²⁴ as in [`Self::sample_p22_11`].
    #[inline]
    fn sample_d_wi(&self, wi: Vec3, u1: f32, u2: f32) -> Vec3 {
        require!(is_direction(wi) && is_uniform(u1) && is_uniform(u2), Vec3::NAN; wi, u1, u2);
        let (ax, ay) = (self.alpha_x(), self.alpha_y());
        let stretched = Vec3::new(ax * wi.x, ay * wi.y, wi.z).normalize_or(Vec3::Z);
        let sin_theta = (stretched.x * stretched.x + stretched.y * stretched.y).sqrt();
        let (cos_phi, sin_phi) =
            if sin_theta > 0.0 { (stretched.x / sin_theta, stretched.y / sin_theta) } else { (1.0, 0.0) };
        let s = self.sample_p22_11(stretched.z, sin_theta, u1, u2);
        let slope_x = ax * (cos_phi * s.x - sin_phi * s.y);
        let slope_y = ay * (sin_phi * s.x + cos_phi * s.y);
        ensure_visible(wi, normal_from_slopes(slope_x, slope_y))
    }

    // The same quantities without the argument check, for the crate's walks, which call them
    // once or more per bounce with directions they produced themselves (unit up to rounding).
    // Each defaults to the checked method, so that an implementation outside the crate keeps
    // its own overrides; the crate's slopes override them with the unchecked bodies.

    /// [`Self::lambda`] without the argument check (crate-internal hot path).
    #[doc(hidden)]
    #[inline(always)]
    fn lambda_unchecked(&self, w: Vec3) -> f32 {
        self.lambda(w)
    }

    /// [`Self::projected_area`] without the argument check (crate-internal hot path).
    #[doc(hidden)]
    #[inline(always)]
    fn projected_area_unchecked(&self, w: Vec3) -> f32 {
        self.projected_area(w)
    }

    /// [`Self::d64`] without the argument check (crate-internal hot path).
    #[doc(hidden)]
    #[inline(always)]
    fn d64_unchecked(&self, wm: DVec3) -> f64 {
        self.d64(wm)
    }

    /// [`Self::d_wi64`] without the argument check (crate-internal hot path).
    #[doc(hidden)]
    #[inline(always)]
    fn d_wi64_unchecked(&self, wi: Vec3, wm: DVec3) -> f64 {
        self.d_wi64(wi, wm)
    }

    /// [`Self::sample_d_wi`] without the argument check (crate-internal hot path).
    #[doc(hidden)]
    #[inline(always)]
    fn sample_d_wi_unchecked(&self, wi: Vec3, u1: f32, u2: f32) -> Vec3 {
        self.sample_d_wi(wi, u1, u2)
    }
}

/// The default D_ωi(ωm) in double precision, cos⟨ωi, ωm⟩ D(ωm)/A(ωi), without the argument check.
#[inline(always)]
pub(crate) fn smith_d_wi64<S: MicrosurfaceSlope>(slope: &S, wi: Vec3, wm: DVec3) -> f64 {
    let cos_im = wi.as_dvec3().dot(wm);
    if cos_im <= 0.0 || wm.z <= 0.0 {
        return 0.0;
    }
    let area = slope.projected_area64(wi);
    if area <= 0.0 { 0.0 } else { cos_im * slope.d64_unchecked(wm) / area }
}

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

/// q = αx² ω.x² + αy² ω.y² = (αᵢ sin θ)², the squared stretched horizontal extent of ω.
#[inline(always)]
pub(crate) fn projected_roughness_sq(alpha_x: f32, alpha_y: f32, w: Vec3) -> f32 {
    let (x, y) = (alpha_x * w.x, alpha_y * w.y);
    x * x + y * y
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

/// Validates a roughness pair: both finite and > 0.
pub(crate) fn check_roughness(alpha_x: f32, alpha_y: f32) -> Result<(f32, f32), Error> {
    Ok((Error::check_positive("alpha_x", alpha_x)?, Error::check_positive("alpha_y", alpha_y)?))
}
