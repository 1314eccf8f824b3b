//! Slope distributions of the microsurface (Heitz et al. 2016, supplement §2).
//!
//! Every function here is valid on the whole sphere of directions (θ ∈ [0, π]), because the
//! random walks query directions below the horizon. Directions are unit vectors in the local
//! frame (z up). Λ is the signed Smith function, with Λ(−ω) = −1 − Λ(ω).

mod beckmann;
mod elliptical;
mod ggx;
mod stretch;

pub use beckmann::Beckmann;
pub use elliptical::{AxisAlignedSlope, Elliptical};
pub use ggx::Ggx;

pub(crate) use beckmann::{gaussian_slope, visible_slope_x_above};
pub(crate) use ggx::{
    F32_DENSITY_MIN_SUM, bounded_area_of, cap_bound, d_of_sum, kappa_of, lambda_and_area_of,
    reflection_density_of, sample_bounded_cap, sample_cap_of, sample_cap_scaled_of,
};
// the spherical-cap kernels, for the tabulated slopes' tail (feature `data-driven`).
#[cfg(feature = "data-driven")]
pub(crate) use ggx::{sample_spherical_cap, sample_visible_hemisphere};
pub(crate) use stretch::{Azimuth, disk_frame, stretch, stretch64};

use crate::albedo::AlbedoTable;
pub(crate) use crate::contract::{is_direction, is_direction64, is_uniform};
use crate::error::Error;
use crate::lanes::Lanes;
// the materials' import path of the vector kernels (src/material is another branch's; the
// kernels live in `crate::vector`)
use crate::sealed::Sealed;
pub(crate) use crate::vector::{normalize_fast, renormalize};
use glam::{DVec3, Vec3};

/// A slope distribution P²²(x̃, ỹ) with roughness (αx, αy) and everything derived from it
/// (`MicrosurfaceSlope` in Heitz et al. 2016, supplement §2.1).
///
/// Sealed: implemented by the crate's distributions only ([`Ggx`], [`Beckmann`],
/// `&`[`TabulatedSlope`](crate::tabulated::TabulatedSlope), [`StretchedTabulated`](crate::tabulated::StretchedTabulated), `&`[`GridSlope`](crate::tabulated::GridSlope)). A distribution of one's
/// own goes through [`TabulatedSlope`](crate::tabulated::TabulatedSlope) (isotropic: from P²² or D values on rings, or a radial
/// function) or [`GridSlope`](crate::tabulated::GridSlope) (anisotropic: from a grid of slope densities), which check their
/// input, derive Λ, the projected area and D_ωi from it and sample it exactly, so that the
/// random walks, the position-free estimators and the samplers are valid for it unchanged.
/// Sealing lets the crate rely on the contract below (which its test suite checks for every
/// implementation) and add methods without a breaking change.
///
/// The contract of every implementation: `p22` integrates to 1 over the slope plane and `d`
/// is its change of variables to normals; `lambda`, `projected_area` and `d_wi` are the
/// Smith quantities of that density on the whole sphere (Λ(−ω) = −1 − Λ(ω), projected area
/// (1 + Λ(ω)) cos θ); `sample_d_wi` samples `d_wi` exactly (chi-square tested); the f64 forms
/// agree with the f32 ones to f32 rounding. (The stretched-space primitives `sample_p22_11`
/// are inherent methods of the axis-aligned slopes, not part of this contract: for a
/// correlated [`Elliptical`] the stretch by (αx, αy) does not sample D_ωi.)
///
/// Invalid input ([policy](crate#invalid-input)), the same for every method and every
/// implementation of the crate: a direction argument that is zero, has a NaN or ±∞ component,
/// or is not unit within [`DIRECTION_TOLERANCE`](crate::DIRECTION_TOLERANCE), a NaN slope, or
/// a uniform outside [0, 1] trips a debug assertion in debug builds; release builds return 0
/// from the densities (`p22`, `d`, `d64`, `d_wi`, `d_wi64`), NaN from `lambda`,
/// `projected_area` and `alpha_i`, and a NaN vector from `sample_d_wi`. Grazing and
/// below-horizon unit directions are valid everywhere.
pub trait MicrosurfaceSlope: Sealed + Copy + core::fmt::Debug + Send + Sync {
    /// Roughness along x.
    fn alpha_x(&self) -> f32;

    /// (αx, αy) if this is the axis-aligned GGX distribution, whose lane kernels the batch
    /// calls use ([`BatchBsdf`](crate::BatchBsdf)); `None` for every other distribution (their
    /// batch calls run the scalar ones lane by lane).
    #[doc(hidden)]
    #[inline]
    fn ggx_roughness(&self) -> Option<(f32, f32)> {
        None
    }

    /// The family's F = 1 single-scattering albedo table and the roughness it is read at,
    /// √(αx αy) (GGX, Beckmann and their elliptical rotations); `None` for every other
    /// distribution. The stochastic techniques' MIS density reads it
    /// ([`MicrofacetBsdf`](crate::MicrofacetBsdf)).
    #[doc(hidden)]
    #[inline]
    fn conductor_albedo(&self) -> Option<(AlbedoTable, f32)> {
        None
    }

    /// Roughness along y.
    fn alpha_y(&self) -> f32;

    /// The largest principal roughness α_max: the largest radius of the slopes' scale ellipse,
    /// invariant under a rotation of the tangent frame (unlike αx and αy, the marginals, which
    /// for a rotated ellipse lie in [α_max/√2, α_max]). The default is max(αx, αy), exact for
    /// axis-aligned distributions; [`Elliptical`] returns max(α₁, α₂) (Dupuy 2015, eqs.
    /// 2.32–2.33). [`MicrofacetBsdf`](crate::MicrofacetBsdf) compares it against its smooth and
    /// walk-length limits.
    #[inline]
    fn alpha_max(&self) -> f32 {
        self.alpha_x().max(self.alpha_y())
    }

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
    #[inline]
    fn lambda(&self, w: Vec3) -> f32 {
        require!(is_direction(w), f32::NAN; w);
        self.lambda_unchecked(w)
    }

    /// The projected area ∫⟨ω, ωm⟩ D(ωm) dωm = (1 + Λ(ω)) cos θ ≥ 0, for every ω
    /// (supplement §2.2–2.3), evaluated without forming 1 + Λ. It is cos θ at the zenith,
    /// 0 at the nadir and ½ αᵢ sin θ at the horizon.
    #[inline]
    fn projected_area(&self, w: Vec3) -> f32 {
        require!(is_direction(w), f32::NAN; w);
        self.projected_area_unchecked(w)
    }

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

    /// D for a normal given in double precision, evaluated in double precision. The default
    /// rounds the normal to f32; [`Ggx`] and [`Beckmann`] evaluate it in f64. The materials form
    /// their half vectors in f64 and call this: D amplifies the rounding of its argument in its
    /// tails and for small α (relative condition number up to 4(x̃/α)² for GGX, 2t for a
    /// Beckmann exponent t).
    #[inline]
    fn d64(&self, wm: DVec3) -> f64 {
        require!(is_direction64(wm), 0.0; wm);
        self.d64_unchecked(wm)
    }

    /// D_ωi(ωm) in double precision for ωm given in double precision (see [`Self::d64`]).
    #[inline]
    fn d_wi64(&self, wi: Vec3, wm: DVec3) -> f64 {
        require!(is_direction(wi) && is_direction64(wm), 0.0; wi, wm);
        self.d_wi64_unchecked(wi, wm)
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
    /// [0, 1) (supplement §2.1: stretch to α = 1, sample slopes, rotate, unstretch; each
    /// implementation in its own numerically robust form, see `src/vndf/`).
    ///
    /// Always returns a unit vector with ωm.z ≥ 0 and ⟨ωi, ωm⟩ > 0 as [`Self::d_wi`] evaluates
    /// it. For ωi = −z, which sees no microsurface, returns +z. The quantiles it inverts use
    /// u as clamp(u, 2⁻²⁴, 1 − 2⁻²⁴) (the crate's tail policy): no sample lies beyond the last
    /// 2⁻²⁴ of the model.
    #[inline]
    fn sample_d_wi(&self, wi: Vec3, u1: f32, u2: f32) -> Vec3 {
        require!(is_direction(wi) && is_uniform(u1) && is_uniform(u2), Vec3::NAN; wi, u1, u2);
        self.sample_d_wi_unchecked(wi, u1, u2)
    }

    // The cores of the checked methods above: each public method checks its arguments once
    // (the crate's input policy) and calls its core, which every implementation provides. The
    // crate's walks call the cores directly, once or more per bounce, with directions they
    // produced themselves (unit up to rounding).

    /// The core of [`Self::lambda`]: no argument check.
    #[doc(hidden)]
    fn lambda_unchecked(&self, w: Vec3) -> f32;

    /// The core of [`Self::projected_area`]: no argument check.
    #[doc(hidden)]
    fn projected_area_unchecked(&self, w: Vec3) -> f32;

    /// The core of [`Self::d64`]: no argument check. The default rounds the normal to f32 and
    /// widens [`Self::d`]; [`Ggx`] and [`Beckmann`] evaluate D in f64.
    #[doc(hidden)]
    #[inline(always)]
    fn d64_unchecked(&self, wm: DVec3) -> f64 {
        f64::from(self.d(wm.as_vec3()))
    }

    /// D(ωh) in double precision for the direction ωh = h/|h| of a vector `h` given
    /// unnormalized (D depends on the direction only), 0 for h.z ≤ 0: the materials pass the
    /// reflection half vector's sum ωi + ωo, exact in f64, and skip its normalization. No
    /// argument check (crate-internal hot path). The default normalizes and calls
    /// [`Self::d64_unchecked`]; [`Ggx`] evaluates its homogeneous form directly (the same
    /// accuracy: a few f64 ulps).
    #[doc(hidden)]
    #[inline(always)]
    fn d64_of_sum_unchecked(&self, h: DVec3) -> f64 {
        self.d64_unchecked(h.normalize_or_zero())
    }

    /// The reflection density D(ωh)/(4 A(ωi)) from the unnormalized half vector h = ωi + ωo
    /// (h.z > 0, the caller has tested the visibility) and A(ωi) = `area` > 0 known, in f64,
    /// rounded once: 0.25 [`Self::d64_of_sum_unchecked`](h)/A by default; [`Ggx`] folds the
    /// divisions into one. No argument check (crate-internal hot path).
    #[doc(hidden)]
    #[inline(always)]
    fn reflection_density_of_sum_unchecked(&self, h: DVec3, area: f32) -> f32 {
        (0.25 * self.d64_of_sum_unchecked(h) / f64::from(area)) as f32
    }

    /// D(ωh)/(|h|⁴ A) for the direction ωh = h/|h| of a vector `h` given unnormalized (0 for
    /// h.z ≤ 0) and A = `area` > 0, in double precision: the slope's factor of a transmission's
    /// density from the unnormalized refraction half vector, where |h|⁴ comes from the Jacobian
    /// (the dielectric walk's next-event estimate, A(ωi) known). No argument check
    /// (crate-internal hot path). The default divides [`Self::d64_of_sum_unchecked`] by |h|⁴A;
    /// [`Ggx`] and [`Beckmann`] evaluate their D forms of degree −4 in h directly (one
    /// division for GGX, two for Beckmann, no |h|).
    #[doc(hidden)]
    #[inline(always)]
    fn d64_over_len4_area_unchecked(&self, h: DVec3, area: f32) -> f64 {
        d64_over_len4_area(self, h, area)
    }

    /// The core of [`Self::d_wi64`]: no argument check. The default is the Smith form
    /// ⟨ωi, ωm⟩ D(ωm)/A(ωi) in f64.
    #[doc(hidden)]
    #[inline(always)]
    fn d_wi64_unchecked(&self, wi: Vec3, wm: DVec3) -> f64 {
        smith_d_wi64(self, wi, wm)
    }

    /// The core of [`Self::sample_d_wi`]: no argument check.
    #[doc(hidden)]
    fn sample_d_wi_unchecked(&self, wi: Vec3, u1: f32, u2: f32) -> Vec3;

    /// [`Self::sample_d_wi_unchecked`]'s normal up to a positive scale: (m, |m|²) with m/|m|
    /// that normal, for callers whose formulas are homogeneous in the normal (the dielectric's
    /// Fresnel term, reflection and refraction take ωi·m and |m|²). The default is the unit
    /// normal and 1; [`Ggx`] returns its unstretched cap point, without the normalization's
    /// square root and division. No argument check (crate-internal hot path).
    #[doc(hidden)]
    #[inline(always)]
    fn sample_d_wi_scaled_unchecked(&self, wi: Vec3, u1: f32, u2: f32) -> (Vec3, f32) {
        (self.sample_d_wi_unchecked(wi, u1, u2), 1.0)
    }

    /// The density D(ωh)/(4 A(ωi)) of a reflection off mirror facets from ωi to ωo, both unit
    /// and strictly above the horizon, ωh = (ωi + ωo)/|ωi + ωo| (the single-scattering density
    /// of a conductor, Heitz et al. 2016, supplement §3.2: D_ωi(ωh)/(4 ωi·ωh)). No argument
    /// check (crate-internal hot path). The default forms ωh and D in f64 and A(ωi) in f32
    /// (relative error a few f32 ulps, see [`Self::d64`]); [`Ggx`] evaluates D in f32 from the
    /// unnormalized sum where that keeps the same accuracy.
    #[doc(hidden)]
    #[inline(always)]
    fn reflection_density_unchecked(&self, wi: Vec3, wo: Vec3) -> f32 {
        reflection_density64(self, wi, wo)
    }

    /// D(ωh)/(4 `area`) for a reflection off mirror facets from ωi to ωo (as
    /// [`Self::reflection_density_unchecked`], which is this with `area` = A(ωi)): the density
    /// of a reflection sampler whose normals have the density ⟨ωi, ωm⟩ D(ωm)/`area` where they
    /// reflect above the horizon. No argument check (crate-internal hot path).
    #[doc(hidden)]
    #[inline(always)]
    fn reflection_density_over_unchecked(&self, wi: Vec3, wo: Vec3, area: f32) -> f32 {
        reflection_density64_over(self, wi, wo, area)
    }

    /// A facet normal for a reflection off mirror facets from a unit ωi above the horizon, from
    /// two uniforms, and the area A_s(ωi) = [`Self::mirror_sampling_area_unchecked`] of its
    /// sampler: the renderer layer's single scattering draws its reflections with it, and
    /// those above the horizon have the density D(ωh)/(4 A_s). By default D_ωi
    /// ([`Self::sample_d_wi_unchecked`], A_s = A); [`Ggx`] draws from the bounded cap (Eto and
    /// Tokuyoshi 2023, [`GgxBoundedCap`](crate::GgxBoundedCap)), which leaves out normals
    /// whose reflections all point into the surface (A_s = A_b ≤ A). No argument check
    /// (crate-internal hot path).
    #[doc(hidden)]
    #[inline(always)]
    fn sample_mirror_normal_unchecked(&self, wi: Vec3, u1: f32, u2: f32) -> (Vec3, f32) {
        (self.sample_d_wi_unchecked(wi, u1, u2), self.projected_area_unchecked(wi))
    }

    /// The area A_s(ωi) of [`Self::sample_mirror_normal_unchecked`] (the same bits): A(ωi) by
    /// default, GGX's bounded A_b. No argument check (crate-internal hot path).
    #[doc(hidden)]
    #[inline(always)]
    fn mirror_sampling_area_unchecked(&self, wi: Vec3) -> f32 {
        self.projected_area_unchecked(wi)
    }
}

/// The default [`MicrosurfaceSlope::d64_over_len4_area_unchecked`]:
/// [`MicrosurfaceSlope::d64_of_sum_unchecked`]/(|h|⁴ A) in f64.
#[inline(always)]
pub(crate) fn d64_over_len4_area<S: MicrosurfaceSlope>(slope: &S, h: DVec3, area: f32) -> f64 {
    let len_sq = h.length_squared();
    slope.d64_of_sum_unchecked(h) / (len_sq * len_sq * f64::from(area))
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

/// The default [`MicrosurfaceSlope::reflection_density_unchecked`]: ωh and D in f64, A(ωi) in
/// f32, 0.25 D/A in f64 rounded once (ωi and ωo strictly above the horizon, so ωh.z > 0 and
/// ωi·ωh > 0).
#[inline(always)]
pub(crate) fn reflection_density64<S: MicrosurfaceSlope>(slope: &S, wi: Vec3, wo: Vec3) -> f32 {
    reflection_density64_over(slope, wi, wo, slope.projected_area_unchecked(wi))
}

/// [`reflection_density64`] with the area given: 0.25 D(ωh)/`area` in f64 rounded once.
#[inline(always)]
pub(crate) fn reflection_density64_over<S: MicrosurfaceSlope>(
    slope: &S,
    wi: Vec3,
    wo: Vec3,
    area: f32,
) -> f32 {
    let wh = (wi.as_dvec3() + wo.as_dvec3()).normalize_or_zero();
    let area = f64::from(area);
    if area <= 0.0 { 0.0 } else { (0.25 * slope.d64_unchecked(wh) / area) as f32 }
}

/// q = αx² ω.x² + αy² ω.y² = (αᵢ sin θ)², the squared stretched horizontal extent of ω.
#[inline(always)]
pub(crate) fn projected_roughness_sq(alpha_x: f32, alpha_y: f32, w: Vec3) -> f32 {
    projected_roughness_sq_of(alpha_x, alpha_y, w.x, w.y)
}

/// [`projected_roughness_sq`] for every lane type.
#[inline(always)]
pub(crate) fn projected_roughness_sq_of<L: Lanes>(alpha_x: L, alpha_y: L, wx: L, wy: L) -> L {
    let (x, y) = (alpha_x * wx, alpha_y * wy);
    x * x + y * y
}

/// Validates a roughness pair: both finite and > 0.
pub(crate) fn check_roughness(alpha_x: f32, alpha_y: f32) -> Result<(f32, f32), Error> {
    Ok((Error::check_positive("alpha_x", alpha_x)?, Error::check_positive("alpha_y", alpha_y)?))
}
