//! Diffuse (Lambertian) microfacets.

use super::{Interaction, Material, PhaseSample, Side, g2_reflection};
use crate::basis::basis;
use crate::contract::is_direction;
use crate::error::Error;
use crate::rng::{uniform, uniform_pair};
use crate::sampling::{cosine_about, cosine_hemisphere};
use crate::slope::{MicrosurfaceSlope, normalize_fast};
use core::f32::consts::{FRAC_1_PI, PI};
use glam::Vec3;
use rand::Rng;

/// Lambertian microfacets with an RGB albedo (Heitz et al. 2016, supplement §3.3).
///
/// [`Diffuse::white`] has albedo 1 (the supplement's non-absorptive validation baseline).
///
/// Its [`Material`] terms, all 0 unless both directions are outside, with ωm drawn from
/// D_ωi where an integral over the visible normals is estimated:
/// - phase function p(ωi, ωo) = (a/π) ∫⟨ωo, ωm⟩ D_ωi(ωm) dωm, estimated with one ωm
///   (supplement §3.3, Algorithm 5): unbiased, stochastic;
/// - `pdf_phase`: an approximation of the exact density (1/π) ∫⟨ωo, ωm⟩⁺ D_ωi(ωm) dωm, which
///   has no closed form: 1/(8π) + cos θo/(2π) for ωo above the horizon, and below it
///   min(1/(8π), A(ωo)/(π A(ωi))) (A the projected area), the second term an upper bound of
///   the exact density, which is of order e^{−a²} there below a smooth surface unless ωi is as
///   far below. Positive on the whole sphere (up to f32 underflow), so that MIS weights built
///   on it exclude no path; its shape below the horizon keeps the bidirectional estimator's
///   weights off strategies that practically never sample a path;
/// - vertex term: (a/π) ⟨ωo, ωm⟩ A(ωi)/|cos θi|, an unbiased estimate of
///   (1/|cos θi|) ∫ (a/π) ⟨ωi, ωm⟩⟨ωo, ωm⟩ D(ωm) dωm;
/// - sampling: ωm from D_ωi, then ωo cosine-distributed about ωm; weight a;
/// - single scattering: see [`Material::eval_single_scattering`] below.
///
/// # Examples
/// ```
/// use microsurface::Diffuse;
/// use microsurface::glam::Vec3;
///
/// assert_eq!(Diffuse::white().albedo(), Vec3::ONE);
/// assert!(Diffuse::new(Vec3::new(0.5, 1.5, 0.2)).is_err());
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Diffuse {
    albedo: Vec3,
}

impl Diffuse {
    /// Diffuse facets with the given albedo per channel.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] if a component of `albedo` is NaN or outside [0, 1].
    pub fn new(albedo: Vec3) -> Result<Self, Error> {
        for a in albedo.to_array() {
            Error::check_unit_interval("albedo", a)?;
        }
        Ok(Self { albedo })
    }

    /// Non-absorptive facets, albedo 1.
    #[must_use]
    pub fn white() -> Self {
        Self { albedo: Vec3::ONE }
    }

    /// The albedo per channel.
    #[inline]
    #[must_use]
    pub fn albedo(&self) -> Vec3 {
        self.albedo
    }
}

impl Diffuse {
    /// A direction from the Lambertian lobe of the facet with normal `wm` (cosine-weighted
    /// about ωm), weighted by the albedo.
    #[inline(always)]
    pub(crate) fn sample_at_facet(&self, wm: Vec3, rng: &mut impl Rng) -> PhaseSample {
        let local = cosine_hemisphere(uniform(rng), uniform(rng));
        let (t, b) = basis(wm);
        let wo = normalize_fast(local.x * t + local.y * b + local.z * wm, wm);
        PhaseSample { wo, weight: self.albedo, side: Side::Outside }
    }

    /// [`Diffuse::sample_at_facet`] as the walks draw it: the same lobe as normalize(ωm + s),
    /// s uniform on the sphere ([`cosine_about`]: no frame about ωm), from one 64-bit draw.
    #[inline(always)]
    fn sample_at_facet_walk(&self, wm: Vec3, rng: &mut impl Rng) -> PhaseSample {
        let (u1, u2) = uniform_pair(rng);
        PhaseSample { wo: cosine_about(wm, u1, u2), weight: self.albedo, side: Side::Outside }
    }
}

/// ⟨ωo, ωm⟩⁺ = max(c, 0) with a +0 for c = ±0 in every build (`f32::max` may return either
/// zero for −0, and debug and release builds differ there).
#[inline(always)]
fn positive_part(c: f32) -> f32 {
    if c > 0.0 { c } else { 0.0 }
}

/// Below this projected area (f64) the bound of [`pdf_below_horizon`] is formed from logarithms.
const AREA_LOG_BELOW: f64 = 1e-280;

/// The approximate density of a diffuse phase function at an ωo below the horizon:
/// min(1/(8π), A(ωo)/(π A(ωi))), A the projected area. The second term is an upper bound of
/// the exact density: p(ωo | ωi) = K(ωi, ωo)/A(ωi) with the symmetric kernel
/// K = (1/π) ∫⟨ωi, ωm⟩⁺⟨ωo, ωm⟩⁺ D(ωm) dωm ≤ A(ωo)/π. Below a smooth surface A(ωo) ≈ e^{−a²}
/// (Beckmann, a = |cot θo|/α), and so is the exact density unless ωi is as far below; the
/// constant 1/(8π) alone overstated it by up to e^{a²}, and the bidirectional estimator's
/// balance weights gave the light sub-path's strategies a share of paths it practically never
/// samples (a bias, DESIGN.md, “Paths from below”). The ratio is formed
/// from ln Λ where an area underflows f64 (Beckmann, a > 26).
#[inline(never)]
fn pdf_below_horizon<S: MicrosurfaceSlope>(slope: &S, it: &Interaction) -> f32 {
    const FLOOR: f32 = 0.125 / PI;
    let (wi, wo) = (it.wi(), it.wo());
    let area_o = slope.projected_area64(wo);
    let area_i = it.incident_area().map_or_else(|| slope.projected_area64(wi), f64::from);
    let ratio = if area_o >= AREA_LOG_BELOW && area_i >= AREA_LOG_BELOW {
        area_o / area_i
    } else {
        // ln A(ω) = ln Λ(−ω) + ln|cos θ| below the horizon; above it A ≥ cos θ does not underflow
        let ln_area = |w: Vec3, area: f64| {
            if w.z < 0.0 { slope.ln_lambda(-w) + f64::from(-w.z).ln() } else { area.ln() }
        };
        let ln_i = ln_area(wi, area_i);
        if ln_i == f64::NEG_INFINITY {
            // ωi sees no facet: no bound
            return FLOOR;
        }
        (ln_area(wo, area_o) - ln_i).exp()
    };
    FLOOR.min((ratio * core::f64::consts::FRAC_1_PI) as f32)
}

impl Material for Diffuse {
    const TRANSMITS: bool = false;
    const EXACT_PHASE_PDF: bool = false;
    const VERTEX_HAS_INCIDENT_AREA: bool = true;

    #[inline]
    fn eval_phase_unchecked<S: MicrosurfaceSlope>(
        &self,
        slope: &S,
        it: &Interaction,
        rng: &mut impl Rng,
    ) -> Vec3 {
        if !it.is_outside_reflection() {
            return Vec3::ZERO;
        }
        let wm = slope.sample_d_wi_unchecked(it.wi(), uniform(rng), uniform(rng));
        self.albedo * (FRAC_1_PI * positive_part(it.wo().dot(wm)))
    }

    #[inline]
    fn pdf_phase_unchecked<S: MicrosurfaceSlope>(&self, slope: &S, it: &Interaction) -> f32 {
        if !it.is_outside_reflection() {
            return 0.0;
        }
        let wo = it.wo();
        if wo.z >= 0.0 {
            return 0.125 / PI + 0.5 * FRAC_1_PI * wo.z;
        }
        pdf_below_horizon(slope, it)
    }

    #[inline]
    fn vertex_unchecked<S: MicrosurfaceSlope>(
        &self,
        slope: &S,
        it: &Interaction,
        rng: &mut impl Rng,
    ) -> Vec3 {
        let wi = it.wi();
        if !it.is_outside_reflection() || wi.z == 0.0 {
            return Vec3::ZERO;
        }
        let wm = slope.sample_d_wi_unchecked(wi, uniform(rng), uniform(rng));
        self.albedo
            * (FRAC_1_PI * positive_part(it.wo().dot(wm)) * slope.projected_area_unchecked(wi) / wi.z.abs())
    }

    #[inline]
    fn sample_phase_unchecked<S: MicrosurfaceSlope>(
        &self,
        slope: &S,
        wi: Vec3,
        _side: Side,
        rng: &mut impl Rng,
    ) -> PhaseSample {
        let wm = slope.sample_d_wi_unchecked(wi, uniform(rng), uniform(rng));
        self.sample_at_facet(wm, rng)
    }

    /// Both pairs of uniforms (the visible normal's, the lobe's) from one 64-bit draw each,
    /// the lobe without a frame (the walks' stream).
    #[inline]
    fn sample_phase_walk_unchecked<S: MicrosurfaceSlope>(
        &self,
        slope: &S,
        wi: Vec3,
        _side: Side,
        rng: &mut impl Rng,
    ) -> PhaseSample {
        let (u1, u2) = uniform_pair(rng);
        let wm = slope.sample_d_wi_unchecked(wi, u1, u2);
        self.sample_at_facet_walk(wm, rng)
    }

    /// One visible facet ωm ~ D_ωi for both: the estimate (a/π)⟨ωo, ωm⟩⁺ of the phase function
    /// (unbiased given the walk so far, as in `eval_phase`) and the direction sampled from the
    /// same facet. Saves one visible-normal sample per bounce of the walk's `eval`; the walk's
    /// random stream differs from that of the separate calls.
    #[inline]
    fn eval_and_sample_phase_unchecked<S: MicrosurfaceSlope>(
        &self,
        slope: &S,
        it: &Interaction,
        rng: &mut impl Rng,
    ) -> (Vec3, PhaseSample) {
        let (u1, u2) = uniform_pair(rng);
        let wm = slope.sample_d_wi_unchecked(it.wi(), u1, u2);
        let phase = if it.is_outside_reflection() {
            self.albedo * (FRAC_1_PI * positive_part(it.wo().dot(wm)))
        } else {
            Vec3::ZERO
        };
        (phase, self.sample_at_facet_walk(wm, rng))
    }

    /// (a/π) ⟨ωo, ωm⟩ (1 + Λ(ωi))/(1 + Λ(ωi) + Λ(ωo)) with ωm drawn from D_ωi: the
    /// single-scattering BSDF times cos θo, estimated without bias (Heitz and Dupuy 2015,
    /// supplement §3.3).
    #[inline]
    fn eval_single_scattering<S: MicrosurfaceSlope>(
        &self,
        slope: &S,
        wi: Vec3,
        wo: Vec3,
        rng: &mut impl Rng,
    ) -> Vec3 {
        require!(is_direction(wi) && is_direction(wo), Vec3::ZERO; wi, wo);
        let g2 = g2_reflection(slope, wi, wo);
        if g2 == 0.0 {
            return Vec3::ZERO;
        }
        let wm = slope.sample_d_wi_unchecked(wi, uniform(rng), uniform(rng));
        // (1 + Λi)/(1 + Λi + Λo) in f64: the f32 factors saturate near grazing
        let k = 1.0 + slope.lambda64(wi);
        let g2_given_g1 = (k / (k + slope.lambda64(wo))) as f32;
        self.albedo * (FRAC_1_PI * positive_part(wo.dot(wm)) * g2_given_g1)
    }
}
