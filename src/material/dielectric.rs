//! Dielectric microfacets.

use super::{
    HalfSum, Interaction, LaneMaterial, Material, PhaseSample, Side, g2_reflection, phase_reflection,
    reflect_scaled, reflection_half_vector,
};
use crate::contract::is_direction;
use crate::error::Error;
use crate::fresnel::{dielectric_reflectance, fresnel_dielectric, transmittance_dielectric_cosines_of};
use crate::lanes::Lanes;
use crate::rng::{uniform, uniform_pair};
use crate::slope::{MicrosurfaceSlope, renormalize};
use crate::special::beta;
use glam::{DVec3, Vec3};
use rand::Rng;

/// Below this |ωi + η ωo| (relative to max(1, η)) a transmission is treated as the Dirac of
/// an η = 1 interface and has no density.
const REFRACTION_DEGENERATE: f64 = 1e-6;

/// A valid refraction ωi → ωo through the facet ωh, with its cosines in double precision.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Refraction {
    /// The refraction half vector (upper hemisphere, unit).
    pub(crate) wh: DVec3,
    /// ωi·ωh > 0.
    pub(crate) cos_ih: f64,
    /// ωo·ωh < 0.
    pub(crate) cos_oh: f64,
    /// (ωi·ωh + η ωo·ωh)², the Jacobian's denominator.
    pub(crate) denom_sq: f64,
    /// 1 − F from cos θi and the exact cos θt = −ωo·ωh
    /// ([`transmittance_dielectric_cosines_of`]: no cancellation where F is close to 1).
    pub(crate) transmittance: f64,
}

/// Dielectric microfacets separating an outside (z > 0) from an inside medium with relative
/// index η = η_inside/η_outside (Heitz et al. 2016, supplement §3.4).
///
/// Non-absorptive by construction: every facet interaction either reflects or refracts, with
/// the Fresnel term choosing. Configurations seen from inside are evaluated as the vertically
/// flipped configuration with η ↦ 1/η.
///
/// Its [`Material`] terms, for ωi outside (the inside configuration is flipped), with ωh the
/// reflection or refraction half vector:
/// - phase function (= `pdf_phase`, the sample weight being 1): reflection
///   F(ωi·ωh) D_ωi(ωh)/(4 ωi·ωh); transmission η² (1 − F(ωi·ωh)) D_ωi(ωh) |ωo·ωh| /
///   (ωi·ωh + η ωo·ωh)² (supplement §3.4);
/// - vertex term: reflection F D/(4|cos θi|); transmission
///   |ωi·ωh| |ωo·ωh| η² (1 − F) D / (|cos θi| (ωi·ωh + η ωo·ωh)²) (Wang et al. 2022,
///   eqs. 2–3, every refraction included, see DESIGN.md);
/// - sampling: ωm from D_ωi, reflect with probability F(ωi·ωm), refract otherwise; weight 1
///   (supplement §3.4, Algorithm 7), the side of ωo always returned explicitly. The bounded
///   cap of Eto and Tokuyoshi 2023 ([`GgxBoundedCap`](crate::vndf::GgxBoundedCap)), which the
///   conductors' single scattering uses, does not apply: the one normal serves both events,
///   and the normals it leaves out (all of whose reflections point into the surface) refract
///   validly, so dropping them would lose transmission;
/// - single scattering: reflection F D G2/(4 cos θi); transmission
///   |ωi·ωh| |ωo·ωh| η² (1 − F) D B(1 + Λ(ωi), 1 + Λ(−ωo)) / (cos θi (ωi·ωh + η ωo·ωh)²)
///   (supplement §3.4).
///
/// # Examples
/// ```
/// use microsurface::Dielectric;
///
/// let glass = Dielectric::new(1.5).unwrap();
/// assert_eq!(glass.flipped().eta(), 1.0 / 1.5);
/// assert!(Dielectric::new(0.0).is_err());
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Dielectric {
    eta: f32,
    /// 1/η, kept so that the inside view ([`Dielectric::flipped`]) and the refraction need no
    /// division.
    inv_eta: f32,
}

impl Dielectric {
    /// A dielectric interface with relative index `eta` (η = 1 is legal: a transparent
    /// interface whose transmission is a Dirac).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] if `eta` is NaN, infinite or ≤ 0.
    pub fn new(eta: f32) -> Result<Self, Error> {
        let eta = Error::check_positive("eta", eta)?;
        Ok(Self { eta, inv_eta: 1.0 / eta })
    }

    /// The relative index η = η_inside/η_outside.
    #[inline]
    #[must_use]
    pub fn eta(&self) -> f32 {
        self.eta
    }

    /// This interface as seen from ωi's side: itself from outside, [`Dielectric::flipped`]
    /// from inside (Heitz et al. 2016, §3.4; the directions flip with
    /// `Interaction::seen_from_outside`).
    #[inline(always)]
    pub(crate) fn seen_from(&self, side: Side) -> Self {
        match side {
            Side::Outside => *self,
            Side::Inside => self.flipped(),
        }
    }

    /// The same interface seen from inside: η ↦ 1/η (1/η rounded once, as
    /// `Dielectric::new(1.0 / eta)` gives it; flipping twice gives back η itself).
    #[inline]
    #[must_use]
    pub fn flipped(&self) -> Self {
        Self { eta: self.inv_eta, inv_eta: self.eta }
    }

    /// The refraction half vector −(ωi + η ωo), normalized and turned to the upper hemisphere,
    /// or `None` when it is undefined or the pair is not a valid refraction through it
    /// (ωi·ωh > 0 > ωo·ωh).
    ///
    /// Computed in double precision: −(ωi + η ωo) cancels strongly near η = 1 and near the
    /// critical angle. Returns `None` when |ωi + η ωo| < `REFRACTION_DEGENERATE`·max(1, η): at
    /// η = 1 and ωo = −ωi the transmission is a Dirac with no density to evaluate, and
    /// elsewhere this leaves out about 1e-12 sr.
    #[inline(always)]
    pub(crate) fn refraction(&self, wi: Vec3, wo: Vec3) -> Option<Refraction> {
        let (i, o, eta) = (wi.as_dvec3(), wo.as_dvec3(), f64::from(self.eta));
        let sum = i + eta * o;
        let len = sum.length();
        if len.is_nan() || len <= REFRACTION_DEGENERATE * eta.max(1.0) {
            return None;
        }
        let h = if sum.z > 0.0 { sum / len } else { -sum / len };
        let (cos_ih, cos_oh) = (i.dot(h), o.dot(h));
        if !(h.z > 0.0 && cos_ih > 0.0 && cos_oh < 0.0) {
            return None;
        }
        // cos θt = −ωo·ωh exactly for a valid refraction: no square root, no TIR branch
        let transmittance = transmittance_dielectric_cosines_of(cos_ih, -cos_oh, eta);
        // ωi·ωh + η ωo·ωh = (ωi + η ωo)·ωh = ±len
        Some(Refraction { wh: h, cos_ih, cos_oh, denom_sq: len * len, transmittance })
    }

    /// The transmission density of the phase function for ωi outside and ωo inside with
    /// A(ωi) = `area` known (the walk's next-event estimation), from the refraction half vector
    /// unnormalized: h = ±(ωi + η ωo) with h.z > 0, valid where ωi·h > 0 > ωo·h (the signs of
    /// [`Self::refraction`]'s tests, and its degenerate pairs, |h| ≤ `REFRACTION_DEGENERATE`
    /// max(1, η), excluded alike). With kᵢ = ωi·h and kₒ = −ωo·h, cos θi = kᵢ/|h| and
    /// cos θt = kₒ/|h|, and ωi·ωh + η ωo·ωh = ±|h|, so
    ///
    /// η² (1 − F) D(ωh) (ωi·ωh)(−ωo·ωh) / (A(ωi) (ωi·ωh + η ωo·ωh)²) = η² (1 − F) kᵢ kₒ D(ωh)/(|h|⁴ A),
    ///
    /// 1 − F = [`transmittance_dielectric_cosines_of`](kᵢ, kₒ, η) (homogeneous in the cosines)
    /// and D(ωh)/(|h|⁴ A) from h directly
    /// ([`MicrosurfaceSlope::d64_over_len4_area_unchecked`]): no square root, no normalization
    /// and, for GGX, two divisions independent of one another (the transmittance's and D's).
    /// In f64, rounded once.
    #[inline(always)]
    fn transmission_density_of_sum<S: MicrosurfaceSlope>(
        &self,
        slope: &S,
        wi: Vec3,
        wo: Vec3,
        area: f32,
    ) -> f32 {
        let (i, o, eta) = (wi.as_dvec3(), wo.as_dvec3(), f64::from(self.eta));
        let sum = i + eta * o;
        let len_sq = sum.length_squared();
        let degenerate = REFRACTION_DEGENERATE * eta.max(1.0);
        if len_sq.is_nan() || len_sq <= degenerate * degenerate {
            return 0.0;
        }
        // turned up by an exact ±1 factor (a select cost 8 instructions); h.z = ±0 fails below
        let h = sum * 1.0f64.copysign(sum.z);
        let (k_i, k_o) = (i.dot(h), -o.dot(h));
        if !(h.z > 0.0 && k_i > 0.0 && k_o > 0.0) {
            return 0.0;
        }
        let transmittance = transmittance_dielectric_cosines_of(k_i, k_o, eta);
        (eta * eta * transmittance * (k_i * k_o) * slope.d64_over_len4_area_unchecked(h, area)) as f32
    }

    /// The phase function for ωi outside, `it` in that frame.
    #[inline(always)]
    fn eval_phase_outside<S: MicrosurfaceSlope>(&self, slope: &S, it: &Interaction) -> f32 {
        let (wi, wo) = (it.wi(), it.wo());
        match it.wo_side() {
            Side::Outside => {
                if let Some(area) = it.incident_area() {
                    // the walk's next-event estimation: A(ωi) known, the half vector unnormalized
                    let Some(sum) = HalfSum::visible(wi, wo) else { return 0.0 };
                    let (f, _) = self.reflectance_scaled(sum.wi_dot_h(), sum.length_sq());
                    return f as f32 * sum.density(slope, area);
                }
                let Some(wh) = reflection_half_vector(wi, wo) else { return 0.0 };
                dielectric_reflectance(wi.as_dvec3().dot(wh) as f32, self.eta)
                    * phase_reflection(slope, wi, wh, it.incident_area())
            }
            Side::Inside => {
                if let Some(area) = it.incident_area() {
                    // the walk's next-event estimation: A(ωi) known, the half vector unnormalized
                    return self.transmission_density_of_sum(slope, wi, wo, area);
                }
                let Some(r) = self.refraction(wi, wo) else { return 0.0 };
                let eta = f64::from(self.eta);
                let d_wi = slope.d_wi64_unchecked(wi, r.wh);
                (eta * eta * r.transmittance * d_wi * (-r.cos_oh) / r.denom_sq) as f32
            }
        }
    }

    /// The vertex term for ωi outside, `it` in that frame (Wang et al. 2022, eqs. 2–3).
    #[inline(always)]
    fn vertex_outside<S: MicrosurfaceSlope>(&self, slope: &S, it: &Interaction) -> f32 {
        let (wi, wo) = (it.wi(), it.wo());
        if wi.z == 0.0 {
            return 0.0;
        }
        match it.wo_side() {
            Side::Outside => {
                let Some(wh) = reflection_half_vector(wi, wo) else { return 0.0 };
                dielectric_reflectance(wi.as_dvec3().dot(wh) as f32, self.eta)
                    * (slope.d64_unchecked(wh) / (4.0 * f64::from(wi.z.abs()))) as f32
            }
            Side::Inside => {
                let Some(r) = self.refraction(wi, wo) else { return 0.0 };
                let eta = f64::from(self.eta);
                (r.cos_ih * (-r.cos_oh) * eta * eta * r.transmittance * slope.d64_unchecked(r.wh)
                    / (f64::from(wi.z.abs()) * r.denom_sq)) as f32
            }
        }
    }

    /// The Fresnel reflectance F for cos θi = k/l with l = √`l_sq` (k ≥ 0), and s = l η cos θt
    /// (0 under total internal reflection, where F = 1), in f64: `fresnel_dielectric_cosines`
    /// with its terms multiplied through by l (and Rp's by η), s = √(k² + (η − 1)(η + 1) l²),
    /// Rs = (k − s)/(k + s), Rp = (η²k − s)/(η²k + s), F = (Rs² + Rp²)/2. The same quantities
    /// without cancellation near grazing or near η = 1, but one square root and one (paired)
    /// division in all: neither cos θi = k/l nor cos θt = s/(lη) is formed. The walks' next-event
    /// estimate passes the half vector's unnormalized ωi·h and |h|², the sampler a facet's
    /// cosine with l = 1.
    #[inline(always)]
    pub(crate) fn reflectance_scaled(&self, k: f64, l_sq: f64) -> (f64, f64) {
        reflectance_scaled_of(f64::from(self.eta), k, l_sq)
    }

    /// The refraction of ωi through the facet of the normal m = l ωm of any length l, given
    /// 1/l² = `inv_len_sq`, with k = ωi·m = l cos θi ≥ 0 and s = l η cos θt (no total internal
    /// reflection; s from [`Self::reflectance_scaled`] with that l):
    /// ((c − s/l) ωm − ωi)/η = ((k − s)/l² m − ωi)/η with c = cos θi. Unit in exact arithmetic
    /// (its squared length is ((c − s/l)² − 2c(c − s/l) + 1)/η² = (s²/l² − c² + 1)/η² =
    /// sin²θt + cos²θt), so the rounding is corrected by one Newton step ([`renormalize`]: no
    /// square root or division on the walk's critical path), with a full normalization where it
    /// is off by more than 2⁻¹². k − s is formed in f64 (it cancels near η = 1), and so is its
    /// product with 1/l² (exact for a unit normal, l² = 1).
    #[inline(always)]
    pub(crate) fn refract(&self, wi: Vec3, m: Vec3, k: f64, s: f64, inv_len_sq: f32) -> Vec3 {
        renormalize((refraction_scale(k, s, inv_len_sq) * m - wi) * self.inv_eta, -m * inv_len_sq.sqrt())
    }

    /// A sample of the phase function from ωi on `side` with the visible normal drawn from
    /// the uniforms (u1, u2) (supplement §3.4, Algorithm 7): ωm ~ D_ωi, reflect with
    /// probability F(ωi·ωm) (a third uniform), refract otherwise. The normal is taken up to its
    /// scale ([`MicrosurfaceSlope::sample_d_wi_scaled_unchecked`]: m = l ωm): the Fresnel term
    /// from ωi·m and l² ([`Self::reflectance_scaled`]), the reflection and the refraction with
    /// 1/l², whose division runs beside the Fresnel term's instead of a normalization ahead of it.
    #[inline(always)]
    fn sample_at_facet<S: MicrosurfaceSlope>(
        &self,
        slope: &S,
        wi: Vec3,
        side: Side,
        u1: f32,
        u2: f32,
        rng: &mut impl Rng,
    ) -> PhaseSample {
        let this = self.seen_from(side);
        let wi_local = side.frame(wi);
        let (m, len_sq) = slope.sample_d_wi_scaled_unchecked(wi_local, u1, u2);
        let inv_len_sq = 1.0 / len_sq;
        let k = f64::from(wi_local.dot(m).abs());
        let (f, s) = this.reflectance_scaled(k, f64::from(len_sq));
        let (wo_local, wo_side) = if uniform(rng) < f as f32 {
            (renormalize(reflect_scaled(wi_local, m, inv_len_sq), m * inv_len_sq.sqrt()), side)
        } else {
            (this.refract(wi_local, m, k, s, inv_len_sq), side.flipped())
        };
        PhaseSample { wo: side.frame(wo_local), weight: Vec3::ONE, side: wo_side }
    }
}

/// The factor (k − s)/l² of the normal m in [`Dielectric::refract`] (k = ωi·m, s = l η cos θt,
/// `inv_len_sq` = 1/l²): the difference in f64 (it cancels near η = 1), times 1/l², rounded
/// once to f32.
#[inline(always)]
pub(crate) fn refraction_scale(k: f64, s: f64, inv_len_sq: f32) -> f32 {
    ((k - s) * f64::from(inv_len_sq)) as f32
}

/// [`Dielectric`]'s `reflectance_scaled` for every lane type, with η = `eta`: (F, s) for
/// cos θi = k/l, l² = `l_sq`, s = l η cos θt (F = 1, s = 0 under total internal reflection).
#[inline(always)]
pub(crate) fn reflectance_scaled_of<L: Lanes>(eta: L, k: L, l_sq: L) -> (L, L) {
    let (zero, one) = (L::lit(0.0), L::lit(1.0));
    let s_sq = k * k + (eta - one) * (eta + one) * l_sq;
    let total = s_sq.le(zero);
    let s = L::select(total, zero, s_sq.sqrt());
    let eta2_k = eta * eta * k;
    let (den_s, den_p) = (k + s, eta2_k + s);
    let (rs, rp) = ((k - s) / den_s, (eta2_k - s) / den_p);
    let f = L::select(total | den_s.le(zero) | den_p.le(zero), one, L::lit(0.5) * (rs * rs + rp * rp));
    (f, s)
}

impl Material for Dielectric {
    const TRANSMITS: bool = true;
    const EXACT_PHASE_PDF: bool = true;

    #[inline]
    fn lane_material(&self) -> LaneMaterial {
        LaneMaterial::Dielectric(self.eta, self.inv_eta)
    }

    /// η = 1 exactly. A nearly index-matched interface (|η − 1| of a few f32 ulps) is not
    /// transparent: from the denser side a ray below the critical angle, cos θ < √(2|η − 1|),
    /// is totally reflected, and elsewhere the walk's many crossings do bend it (see
    /// [`crate::research::MAX_BOUNCES`]).
    #[inline]
    fn is_transparent(&self) -> bool {
        self.eta == 1.0
    }

    #[inline]
    fn relative_eta_sq(&self, from: Side, to: Side) -> f32 {
        match (from, to) {
            (Side::Outside, Side::Inside) => self.eta * self.eta,
            (Side::Inside, Side::Outside) => 1.0 / (self.eta * self.eta),
            _ => 1.0,
        }
    }

    #[inline]
    fn eval_phase_unchecked<S: MicrosurfaceSlope>(
        &self,
        slope: &S,
        it: &Interaction,
        _rng: &mut impl Rng,
    ) -> Vec3 {
        Vec3::splat(self.pdf_phase_unchecked(slope, it))
    }

    #[inline(always)]
    fn pdf_phase_unchecked<S: MicrosurfaceSlope>(&self, slope: &S, it: &Interaction) -> f32 {
        self.seen_from(it.wi_side()).eval_phase_outside(slope, &it.seen_from_outside())
    }

    #[inline(always)]
    fn vertex_unchecked<S: MicrosurfaceSlope>(
        &self,
        slope: &S,
        it: &Interaction,
        _rng: &mut impl Rng,
    ) -> Vec3 {
        Vec3::splat(self.seen_from(it.wi_side()).vertex_outside(slope, &it.seen_from_outside()))
    }

    // out of line: the walk instantiated with the renderer layer's primed generator inlined
    // it and ran 25 % slower than with the research layer's generator, which does not
    // (DESIGN.md, “Speed against the research calls”)
    #[inline(never)]
    fn sample_phase_unchecked<S: MicrosurfaceSlope>(
        &self,
        slope: &S,
        wi: Vec3,
        side: Side,
        rng: &mut impl Rng,
    ) -> PhaseSample {
        let (u1, u2) = (uniform(rng), uniform(rng));
        self.sample_at_facet(slope, wi, side, u1, u2, rng)
    }

    /// The visible normal's two uniforms from one 64-bit draw (the walks' stream). Out of
    /// line: inlined with the GGX visible normal into the walk's loop, the listing's GGX
    /// `sample` took 80 ns against 65 ns (Beckmann 127 against 135 ns; DESIGN.md, “Speed against
    /// the research calls”).
    #[inline(never)]
    fn sample_phase_walk_unchecked<S: MicrosurfaceSlope>(
        &self,
        slope: &S,
        wi: Vec3,
        side: Side,
        rng: &mut impl Rng,
    ) -> PhaseSample {
        let (u1, u2) = uniform_pair(rng);
        self.sample_at_facet(slope, wi, side, u1, u2, rng)
    }

    /// The walk's next-event phase function and next direction in one call, with the results
    /// of the default's two calls (the phase function draws no uniform): the visible normal's
    /// uniforms are drawn first, as [`Material::sample_phase_walk_unchecked`] draws them, then
    /// the phase function at `it` is formed, then the sample. The phase function's long f64
    /// chain (Fresnel, density) so starts ahead of the sampler's instead of after its call
    /// returns: measured −5 % (GGX, ωo above) and −10 % (ωo inside) per walk `eval`; the
    /// conductor, whose next-event density is short, keeps the two calls (its phase function
    /// first measured +19 %).
    #[inline(never)]
    fn eval_and_sample_phase_unchecked<S: MicrosurfaceSlope>(
        &self,
        slope: &S,
        it: &Interaction,
        rng: &mut impl Rng,
    ) -> (Vec3, PhaseSample) {
        let (u1, u2) = uniform_pair(rng);
        let phase = self.pdf_phase_unchecked(slope, it);
        (Vec3::splat(phase), self.sample_at_facet(slope, it.wi(), it.wi_side(), u1, u2, rng))
    }

    /// The single-scattering terms of the type's documentation; for ωi below the surface, the
    /// flipped configuration.
    #[inline]
    fn eval_single_scattering<S: MicrosurfaceSlope>(
        &self,
        slope: &S,
        wi: Vec3,
        wo: Vec3,
        rng: &mut impl Rng,
    ) -> Vec3 {
        require!(is_direction(wi) && is_direction(wo), Vec3::ZERO; wi, wo);
        if wi.z < 0.0 {
            return self.flipped().eval_single_scattering(slope, -wi, -wo, rng);
        }
        if wi.z == 0.0 || wo.z == 0.0 {
            return Vec3::ZERO;
        }
        let value = if wo.z > 0.0 {
            let g2 = g2_reflection(slope, wi, wo);
            let wh = (wi.as_dvec3() + wo.as_dvec3()).normalize_or_zero();
            fresnel_dielectric(wi.as_dvec3().dot(wh) as f32, self.eta)
                * (slope.d64_unchecked(wh) * f64::from(g2) / (4.0 * f64::from(wi.z))) as f32
        } else {
            let Some(r) = self.refraction(wi, wo) else { return Vec3::ZERO };
            let g2 = beta(1.0 + slope.lambda64(wi), 1.0 + slope.lambda64(-wo));
            let eta = f64::from(self.eta);
            (r.cos_ih * (-r.cos_oh) * eta * eta * r.transmittance * slope.d64_unchecked(r.wh) * g2
                / (f64::from(wi.z) * r.denom_sq)) as f32
        };
        Vec3::splat(value)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fresnel::fresnel_dielectric_cosines_of;

    /// `reflectance_scaled` is `fresnel_dielectric_cosines` for cos θi = k/l: F within 1e-13
    /// (absolute, F ∈ [0, 1]) of the f64 form with cos θt = √(c² + (η − 1)(η + 1))/η, and
    /// s = l η cos θt within 1e-13 relative, for η from 1/2.4 to 2.4 (total internal reflection
    /// included: F = 1, s = 0), η within 1e-6 of 1, cosines from 1e-6 to 1 and scales l from
    /// 1e-3 to 2 (the half vector's length).
    #[test]
    fn scaled_reflectance_is_the_fresnel_term() {
        let (mut compared, mut reflected) = (0, 0);
        for eta in [1.0 / 2.4f32, 1.0 / 1.5, 1.0 - 1e-6, 1.0 + 1e-6, 1.33, 1.5, 2.4] {
            let glass = Dielectric::new(eta).expect("valid index");
            let eta = f64::from(eta);
            for c in [1e-6f64, 1e-3, 0.05, 0.3, 0.5, 0.7453, 0.9, 0.999, 1.0] {
                for l in [1e-3f64, 0.5, 1.0, 1.7, 2.0] {
                    let (f, s) = glass.reflectance_scaled(c * l, l * l);
                    let e2 = c * c + (eta - 1.0) * (eta + 1.0);
                    if e2 <= 0.0 {
                        assert_eq!((f, s), (1.0, 0.0), "η = {eta}, c = {c}: total internal reflection");
                        reflected += 1;
                        continue;
                    }
                    let cos_t = e2.sqrt() / eta;
                    let reference = fresnel_dielectric_cosines_of(c, cos_t, eta);
                    assert!(
                        (f - reference).abs() <= 1e-13,
                        "η = {eta}, c = {c}, l = {l}: {f} vs {reference}"
                    );
                    let rel = (s / (l * eta) - cos_t).abs() / cos_t;
                    assert!(rel <= 1e-13, "η = {eta}, c = {c}, l = {l}: cos θt {} vs {cos_t}", s / (l * eta));
                    compared += 1;
                }
            }
        }
        assert!(compared > 200 && reflected > 50, "{compared} cases compared, {reflected} totally reflected");
    }
}
