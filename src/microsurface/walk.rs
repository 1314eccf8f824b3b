//! The random walk on the microsurface: stochastic evaluation and sampling of the
//! multiple-scattering BSDF (Heitz et al. 2016, supplement §3.1 Algorithms 2–3 and §3.4).

use super::Microsurface;
use super::geometry::{first_ln_c1_from_below, flip_ln_c1, next_ln_c1};
use crate::contract::is_direction;
use crate::height::MicrosurfaceHeight;
use crate::material::{Interaction, Material, Side};
use crate::rng::uniform;
use crate::slope::MicrosurfaceSlope;
use core::num::NonZeroU32;
use glam::Vec3;
use rand::Rng;

/// The hard cap on the number of bounces of one walk: 2¹⁶.
///
/// Walks end with probability one; the cap only guards against non-termination. A walk that
/// reaches it is dropped (its energy is lost). The longest walks the model produces are those
/// of a grazing ray through a dielectric with η within a few f32 ulps of 1: the ray crosses
/// the nearly index-matched interface about Λ(ωi) ≈ αᵢ tan θi/2 times before refraction turns
/// it, up to a saturation set by |η − 1| (measured with GGX α = 2: η = 1 − 2⁻²⁴ from inside at
/// cos θi = 1e-6 … 1e-20, the worst case over the f32 values of η ≠ 1, a mean of 9 500
/// bounces and at most 9 963 in 2 000 walks; η = 1 ± 2e-6 at most 2 800; η = 1 ± 1e-4 at most
/// 630). The former cap of 1024 dropped up to 100 % of those walks (GGX α = 1, η = 1 − 1e-7,
/// cos θi = 1e-3: 85 %). η = 1 exactly, where the count grows without bound as cos θi → 0, is
/// the transparent interface it is ([`crate::Material::is_transparent`]). Such walks cost
/// about 0.5 ms.
///
/// Measured loss (`tests/walk_cap.rs`, Clopper–Pearson upper bounds at 99 % family-wise
/// confidence): below 1e-4 of the albedo for every material at α = 2 (1e5 walks per
/// configuration); for η ∈ {1 ± 1e-7, 1 ± 2e-6, 1 ± 1e-4} at cos θi ∈ {1e-3, 1e-2} none of
/// 1e4 walks per configuration is capped (bound 7e-4, the resolution of that sample; 2e4
/// walks each gave none either), for the worst case above none of 1e3, and the longest stays
/// below a quarter of the cap.
pub const MAX_BOUNCES: u32 = 1 << 16;

/// Which scattering orders an evaluation counts.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ScatteringOrder {
    /// Every order: the full multiple-scattering BSDF.
    #[default]
    All,
    /// Exactly the n-th bounce (n = 1: single scattering).
    Only(NonZeroU32),
    /// Orders 1 to n: the BSDF truncated after n bounces.
    UpTo(NonZeroU32),
}

impl ScatteringOrder {
    /// Exactly the n-th bounce; `None` for n = 0.
    pub fn only(n: u32) -> Option<Self> {
        NonZeroU32::new(n).map(Self::Only)
    }

    /// Orders 1 to n; `None` for n = 0.
    pub fn up_to(n: u32) -> Option<Self> {
        NonZeroU32::new(n).map(Self::UpTo)
    }

    /// The last bounce the walk needs to simulate.
    #[inline(always)]
    pub(crate) fn last(self) -> u32 {
        match self {
            Self::All => MAX_BOUNCES,
            Self::Only(n) | Self::UpTo(n) => n.get().min(MAX_BOUNCES),
        }
    }

    /// Whether bounce `k` contributes.
    #[inline(always)]
    pub(crate) fn includes(self, k: u32) -> bool {
        match self {
            Self::All => true,
            Self::Only(n) => k == n.get(),
            Self::UpTo(n) => k <= n.get(),
        }
    }
}

/// An outgoing direction sampled by the random walk.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WalkSample {
    /// The direction in which the walk left the microsurface (unit; below the horizon for a
    /// transmission).
    pub wo: Vec3,
    /// The path throughput per channel: f·|cos θo|/pdf. 1 for non-absorptive materials.
    pub weight: Vec3,
    /// The number of bounces of the walk (≥ 1).
    pub bounces: u32,
}

impl<H: MicrosurfaceHeight, S: MicrosurfaceSlope, M: Material> Microsurface<H, S, M> {
    /// The side of the interface a walk for the incident direction `wi` starts on, or `None`
    /// if the ordinary walk cannot start there (an opaque material lit from below starts in
    /// [`Microsurface::eval_from_below`] / [`Microsurface::sample_from_below`] instead).
    #[inline(always)]
    fn starting_side(wi: Vec3) -> Option<Side> {
        Side::of(wi.z).filter(|&side| M::TRANSMITS || side == Side::Outside)
    }

    /// Evaluates the multiple-scattering BSDF times |cos θo| by a random walk with next-event
    /// estimation (supplement §3.1 Algorithm 2; §3.4 for the dielectric). Stochastic and
    /// unbiased: average several calls.
    ///
    /// `order` selects all bounces, exactly the n-th, or the first n. Returns 0 when ωi or ωo
    /// lies on the horizon, and for opaque materials when ωo is below it. A dielectric lit
    /// from inside (ωi.z < 0) is evaluated as the flipped configuration, η ↦ 1/η. An opaque
    /// material lit from below the macrosurface (ωi.z < 0: a backfacing view under a normal
    /// map) starts with the full-spherical first intersection of
    /// [`Microsurface::eval_from_below`].
    ///
    /// Invalid input ([policy](crate#invalid-input)): a `wi` or `wo` that is not a unit
    /// direction gives 0 (a debug assertion in debug builds).
    pub fn eval(&self, wi: Vec3, wo: Vec3, order: ScatteringOrder, rng: &mut impl Rng) -> Vec3 {
        require!(is_direction(wi) && is_direction(wo), Vec3::ZERO; wi, wo);
        let Some(mut side) = Self::starting_side(wi) else {
            return if !M::TRANSMITS && wi.z < 0.0 {
                self.eval_from_below(wi, wo, order, rng)
            } else {
                Vec3::ZERO
            };
        };
        if wo.z == 0.0 || (!M::TRANSMITS && wo.z < 0.0) || self.material.is_transparent() {
            // a transparent interface scatters into the Dirac of ωo = −ωi only: no density
            return Vec3::ZERO;
        }
        let slope = self.geometry.slope();
        let wo_side = Side::above_or_inside(wo.z);
        // Λ of ωo seen from its own side, constant along the walk
        let lambda_o = slope.lambda_unchecked(wo_side.frame(wo));
        let last = order.last();

        let mut wr = -wi;
        // ln C¹ of the current height in the frame of the current side (0: above the surface)
        let mut ln_c1 = 0.0;
        let mut throughput = Vec3::ONE;
        let mut sum = Vec3::ZERO;
        for bounce in 1..=last {
            let Some(hit) = self.next_hit(wr, ln_c1, side, rng) else { break };
            ln_c1 = hit.ln_c1;
            if order.includes(bounce) {
                let it = Interaction::new(-wr, wo, side, wo_side).with_incident_area(hit.incident_area);
                let phase = self.material.eval_phase_unchecked(slope, &it, rng);
                if phase != Vec3::ZERO {
                    let ln_c1_o = if side == wo_side { ln_c1 } else { flip_ln_c1(ln_c1) };
                    sum += throughput * phase * (lambda_o * ln_c1_o).exp();
                }
            }
            if bounce == last {
                break;
            }
            let s = self.material.sample_phase_unchecked(slope, -wr, side, rng);
            if s.side != side {
                ln_c1 = flip_ln_c1(ln_c1);
            }
            wr = s.wo;
            side = s.side;
            throughput *= s.weight;
            if throughput == Vec3::ZERO {
                break;
            }
        }
        sum
    }

    /// Samples the multiple-scattering BSDF by a random walk (supplement §3.1 Algorithm 3;
    /// §3.4 for the dielectric).
    ///
    /// Returns the exit direction, the path weight f·|cos θo|/pdf and the number of bounces;
    /// `None` if ωi cannot light the material (on the horizon, or at the nadir for an opaque
    /// material), if the path was fully absorbed, or if it reached [`MAX_BOUNCES`]. An opaque
    /// material lit from below the macrosurface (ωi.z < 0) is sampled by
    /// [`Microsurface::sample_from_below`].
    ///
    /// A transparent material ([`Material::is_transparent`]) returns ωo = −ωi with weight 1
    /// and one bounce without walking: the walk would cross the interface about Λ(ωi) times
    /// (unboundedly many at grazing incidence) without ever changing direction.
    ///
    /// Invalid input ([policy](crate#invalid-input)): a `wi` that is not a unit direction gives
    /// `None` (a debug assertion in debug builds).
    pub fn sample(&self, wi: Vec3, rng: &mut impl Rng) -> Option<WalkSample> {
        require!(is_direction(wi), None; wi);
        let Some(mut side) = Self::starting_side(wi) else {
            return if !M::TRANSMITS && wi.z < 0.0 { self.sample_from_below(wi, rng) } else { None };
        };
        if self.material.is_transparent() {
            return Some(WalkSample { wo: -wi, weight: Vec3::ONE, bounces: 1 });
        }
        let slope = self.geometry.slope();
        let mut wr = -wi;
        let mut ln_c1 = 0.0;
        let mut weight = Vec3::ONE;
        for bounces in 0..MAX_BOUNCES {
            let Some(hit) = self.next_hit(wr, ln_c1, side, rng) else {
                return Some(WalkSample { wo: wr, weight, bounces });
            };
            ln_c1 = hit.ln_c1;
            let s = self.material.sample_phase_unchecked(slope, -wr, side, rng);
            if s.side != side {
                ln_c1 = flip_ln_c1(ln_c1);
            }
            wr = s.wo;
            side = s.side;
            weight *= s.weight;
            if weight == Vec3::ZERO {
                return None;
            }
        }
        None
    }

    /// [`Microsurface::eval`] for an opaque material lit from below the macrosurface
    /// (ωi.z < 0, the ray travels upwards): a backfacing view under a normal map.
    ///
    /// The full-spherical Smith model gives ωi the projected area A(ωi) = (1 + Λ(ωi)) cos θi
    /// = Λ(−ωi)|cos θi| > 0 of the facets with ωi·ωm > 0, whose normals follow the VNDF D_ωi
    /// (sampled exactly on the whole sphere), and the masking G1(ωi) = 1/|1 + Λ(ωi)| (Wang et
    /// al. 2022, eq. 10). The first intersection's ln C¹ is ln(1 − u)/Λ(−ωi)
    /// (`first_ln_c1_from_below`: the visible-height distribution C^{1/G1(ωi)} of Algorithm 1
    /// of the supplement, extended to the lower hemisphere); from there the walk is the
    /// ordinary one (supplement §3.1, Algorithm 2), every exit being upwards. Its order-1 term
    /// is exactly p(ωi, ωo) Λ(−ωi)/(Λ(−ωi) + Λ(ωo)) = F D G2/(4|cos θi|) with the full-spherical
    /// G2 = 1/(Λ(−ωi) + Λ(ωo)) (Wang et al. 2022, eq. 17) of the single-scattering model.
    ///
    /// 0 when ωo is at or below the horizon, or when Λ(−ωi) = 0 (ωi at the nadir sees no
    /// microsurface). Stochastic and unbiased, consistent with
    /// [`Microsurface::sample_from_below`] (the same walk).
    ///
    /// Known limit: the walk carries Λ in f32. For Beckmann, Λ(−ωi) ≈ e^{−a²} (a = |cot θi|/αᵢ)
    /// underflows f32 from a ≈ 9.6 on (α = 0.01 at θi = 96°, 0.05 at 120°, 0.1 at 150°), and
    /// the walk then returns nothing although the model's albedo is that of single scattering
    /// and more (≈ 0.92 there for F = 1); single scattering, which forms this masking in f64 and
    /// in log space, does not share the limit. GGX's Λ stays above 1e-106 and is unaffected.
    pub fn eval_from_below(&self, wi: Vec3, wo: Vec3, order: ScatteringOrder, rng: &mut impl Rng) -> Vec3 {
        if M::TRANSMITS || !(wi.z < 0.0 && wo.z > 0.0) {
            return Vec3::ZERO;
        }
        let slope = self.geometry.slope();
        let mut wr = -wi;
        let Some(mut ln_c1) = first_ln_c1_from_below(slope.lambda(wr), uniform(rng)) else {
            return Vec3::ZERO;
        };
        let lambda_o = slope.lambda(wo);
        let last = order.last();
        let mut throughput = Vec3::ONE;
        let mut sum = Vec3::ZERO;
        let mut bounce = 1;
        // A(ωi) of the current vertex where the height step knows it (not at the first one,
        // which ωi reaches from below)
        let mut incident_area = None;
        loop {
            if order.includes(bounce) {
                let it = Interaction::reflection(-wr, wo).with_incident_area(incident_area);
                let phase = self.material.eval_phase_unchecked(slope, &it, rng);
                if phase != Vec3::ZERO {
                    sum += throughput * phase * (lambda_o * ln_c1).exp();
                }
            }
            if bounce == last {
                break;
            }
            let s = self.material.sample_phase_unchecked(slope, -wr, Side::Outside, rng);
            wr = s.wo;
            throughput *= s.weight;
            if throughput == Vec3::ZERO {
                break;
            }
            let Some(hit) = self.next_hit(wr, ln_c1, Side::Outside, rng) else { break };
            (ln_c1, incident_area) = (hit.ln_c1, hit.incident_area);
            bounce += 1;
        }
        sum
    }

    /// [`Microsurface::sample`] for an opaque material lit from below the macrosurface
    /// (ωi.z < 0): the walk of [`Microsurface::eval_from_below`] (first intersection at
    /// ln C¹ = ln(1 − u)/Λ(−ωi), normal from D_ωi), then the ordinary walk (supplement §3.1,
    /// Algorithm 3). Every path leaves upwards, so for F = 1 the weight is exactly 1 (energy is
    /// conserved, up to walks reaching [`MAX_BOUNCES`]); otherwise it is the product of the
    /// phase-sample weights, f·|cos θo|/pdf.
    ///
    /// `None` if ωi is not below the horizon, the material transmits, Λ(−ωi) = 0, the path was
    /// absorbed, or it reached [`MAX_BOUNCES`].
    ///
    /// Known limit: the walk carries Λ in f32. For Beckmann, Λ(−ωi) ≈ e^{−a²} (a = |cot θi|/αᵢ)
    /// underflows f32 from a ≈ 9.6 on (α = 0.01 at θi = 96°, 0.05 at 120°, 0.1 at 150°), and
    /// the walk then returns `None` although the model's albedo is that of single scattering
    /// and more (≈ 0.92 there for F = 1); single scattering, which forms this masking in f64 and
    /// in log space, does not share the limit. GGX's Λ stays above 1e-106 and is unaffected.
    pub fn sample_from_below(&self, wi: Vec3, rng: &mut impl Rng) -> Option<WalkSample> {
        if M::TRANSMITS || wi.z.is_nan() || wi.z >= 0.0 {
            return None;
        }
        let slope = self.geometry.slope();
        let mut wr = -wi;
        let mut ln_c1 = first_ln_c1_from_below(slope.lambda(wr), uniform(rng))?;
        let mut weight = Vec3::ONE;
        for bounces in 1..=MAX_BOUNCES {
            let s = self.material.sample_phase_unchecked(slope, -wr, Side::Outside, rng);
            wr = s.wo;
            weight *= s.weight;
            if weight == Vec3::ZERO {
                return None;
            }
            match self.next_hit(wr, ln_c1, Side::Outside, rng) {
                Some(hit) => ln_c1 = hit.ln_c1,
                None => return Some(WalkSample { wo: wr, weight, bounces }),
            }
        }
        None
    }

    /// The next intersection of the ray ωr leaving a point with ln C¹ = `ln_c1` on `side`,
    /// or `None` if it escapes. Both are in the frame of that side: inside a dielectric the
    /// configuration is flipped vertically (supplement §3.4). One Λ per bounce: the Λ(ωr) of
    /// the height step also gives the projected area of the next vertex's incident direction
    /// ([`incident_area`]).
    #[inline(always)]
    fn next_hit(&self, wr: Vec3, ln_c1: f32, side: Side, rng: &mut impl Rng) -> Option<Hit> {
        let w = side.frame(wr);
        let lambda = self.geometry.slope().lambda_unchecked(w);
        let ln_c1 = next_ln_c1(w.z, lambda, ln_c1, uniform(rng))?;
        Some(Hit { ln_c1, incident_area: incident_area(w.z, lambda) })
    }
}

/// An intersection of the walk's ray with the microsurface.
#[derive(Debug, Clone, Copy)]
struct Hit {
    /// ln C¹ of its height, in the frame of the ray's side.
    ln_c1: f32,
    /// A(ωi) of the incident direction ωi = −ωr there, in the same frame, where known.
    incident_area: Option<f32>,
}

/// The projected area A(ωi) = (1 + Λ(ωi)) cos θi (supplement §2.2) of the incident direction
/// ωi = −ω of a vertex that the ray ω with z-component `z` and Λ(ω) = `lambda` reached going
/// down: with Λ(ω) = −1 − Λ(ωi), A(ωi) = Λ(ω)·ω.z, one f32 product (relative error below
/// 2⁻²³ beyond that of Λ). `None` for a ray going up or horizontally (ωi backfacing or
/// grazing, whose density the materials form in f64 instead) and where Λ saturated at
/// −`f32::MAX` (|cos θ| below ~1e-38·αᵢ, where the product would not be A).
#[inline(always)]
fn incident_area(z: f32, lambda: f32) -> Option<f32> {
    (z < 0.0 && lambda > -f32::MAX).then_some(lambda * z)
}
