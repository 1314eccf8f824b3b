//! Russian roulette of the camera paths (PT and BDPT's camera sub-path): the survival
//! probability and the quantities it compares.

use super::PositionFree;
use crate::material::{Material, Side};
use crate::path::{Incident, LAMBDA_RATIO_LOG_BELOW};
use crate::slope::MicrosurfaceSlope;
use core::f64::consts::PI;
use glam::{DVec3, Vec3};

/// Path tracing's Russian roulette starts after this many sampled bounces (it is unbiased at
/// any depth).
pub(crate) const ROULETTE_FROM_BOUNCE: u32 = 3;

/// The bidirectional estimator's sub-paths start their Russian roulette after this many sampled
/// directions: one earlier than path tracing, whose variance per sample is higher and which
/// measured worse from the second (DESIGN.md, “BDPT against PT”).
pub(crate) const BDPT_ROULETTE_FROM: usize = 2;

/// The margin C of the survival factor's cap C·P/ĉ (see [`Roulette::survival`]). The cap
/// binds only where G1 overstates the next phase function's peak relative to ĉ by more than C,
/// as it does by up to e^{a²} below a light-tailed surface. Measured (DESIGN.md, “Russian
/// roulette”): C = 8 raised the variance of BDPT at GGX α = 0.1 by 31 % (mostly at
/// the mirror direction, whose later vertices keep contributing), C = 64 by 7 %, C = 256 by
/// 1.5 % (within the noise, at 11 % fewer instructions); below a smooth GGX surface each factor
/// 4 of C costs about one more bounce (16 extensions at C = 256, 4.7 at C = 1).
const PEAK_CAP_MARGIN: f64 = 256.0;

/// The reference scale ĉ of a path whose single-scattering term is 0 (ωo outside the first
/// vertex's lobe), relative to the first vertex's phase peak.
const REFERENCE_FLOOR: f64 = 1.0 / (1u64 << 20) as f64;

/// The camera path's Russian roulette: the reference scale ĉ of the path's contributions.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Roulette {
    /// ĉ: max over channels of the first vertex's next-event contribution (the path's single
    /// scattering); where that is 0 or not computed, 2⁻²⁰ times the first vertex's phase peak.
    reference: f64,
}

impl Roulette {
    /// The roulette before its reference is set: ĉ = 0 keeps the factor G1 (the reference of a
    /// path whose evaluated orders exclude the first is set by [`Self::set_reference`] all the
    /// same, from the first vertex's phase peak).
    pub(crate) const UNSET: Self = Self { reference: 0.0 };

    /// The roulette of a path of `pf` whose first vertex has the incident state `start` with
    /// 1 + L̃ = `k_start` and the next-event contribution `single` (`None` where the
    /// evaluated orders exclude it).
    #[inline(always)]
    pub(crate) fn new<S: MicrosurfaceSlope, M: Material>(
        pf: &PositionFree<S, M>,
        start: Incident,
        k_start: f64,
        single: Option<DVec3>,
    ) -> Self {
        let mut roulette = Self::UNSET;
        roulette.set_reference(pf, start, k_start, single.unwrap_or(DVec3::ZERO));
        roulette
    }

    /// Sets ĉ from the first vertex (`start`, 1 + L̃ = `k_start`) and its next-event
    /// contribution `single` (0 where not computed).
    #[inline(always)]
    pub(crate) fn set_reference<S: MicrosurfaceSlope, M: Material>(
        &mut self,
        pf: &PositionFree<S, M>,
        start: Incident,
        k_start: f64,
        single: DVec3,
    ) {
        let first = single.max_element();
        self.reference = if first > 0.0 { first } else { Self::floor(pf, start, k_start) };
    }

    /// 2⁻²⁰ times the first vertex's phase peak.
    #[cold]
    #[inline(never)]
    fn floor<S: MicrosurfaceSlope, M: Material>(
        pf: &PositionFree<S, M>,
        start: Incident,
        k_start: f64,
    ) -> f64 {
        REFERENCE_FLOOR * pf.phase_peak(start.in_frame(), k_start)
    }

    /// The survival probability of a path with `throughput` whose next vertex has the incident
    /// state `next` with 1 + L̃ = `k_next`:
    ///
    /// q = min(1, T · max(1, Φ)), T = max(throughput), Φ = min(G1, C·P/ĉ),
    ///
    /// with G1 = 1/k_next the next vertex's incident masking, P = D(m*)/(4A(ωin)) the peak of
    /// its phase function (m* the facet it sees closest to the slopes' mode, A its projected
    /// area: [`PositionFree::phase_peak`]), ĉ this path's single-scattering term (where it is
    /// 0: 2⁻²⁰ times the first vertex's peak) and C = 256 (`PEAK_CAP_MARGIN`). Any q ∈ (0, 1]
    /// with weight 1/q is unbiased; q only sets the variance and the path length.
    ///
    /// - From above (k_next ≥ 1, G1 ≤ 1) q = min(1, T): a surviving path's next contributions
    ///   are at most its vertex terms.
    /// - The G1 factor keeps the variance finite where a bounce goes almost straight up: its
    ///   throughput carries Λ(ω) → 0, which the next vertex's G1 = 1/Λ(ω) cancels (the next
    ///   contribution is at most G1 times the vertex term, and T·G1 does not grow along a path).
    /// - The cap: the next contribution is also at most T·P (the phase function times
    ///   k_in·S_last ≤ 1). Lit from below a light-tailed surface (Beckmann), G1 ∝ e^{a²} while
    ///   P grows as a³ (a = |cot θ|/αᵢ): T·G1 stayed ≥ 1 forever and roulette never ended such
    ///   paths, whose contributions had vanished after a few bounces. The cap ends them once
    ///   T·C·P falls below this path's own scale ĉ.
    ///
    /// A phase function integrates to 1 over the sphere, so P ≥ 1/(4π) and the cap exceeds G1
    /// wherever C·k_next ≥ 4πĉ: P is evaluated only for smaller k_next (steep or backfacing
    /// ω). The measurements behind the rule: DESIGN.md, “Russian roulette”.
    #[inline(always)]
    pub(crate) fn survival<S: MicrosurfaceSlope, M: Material>(
        &self,
        pf: &PositionFree<S, M>,
        throughput: DVec3,
        next: Incident,
        k_next: f64,
    ) -> f64 {
        let t = throughput.max_element();
        if t >= 1.0 {
            return 1.0;
        }
        if k_next >= 1.0 || k_next.is_nan() {
            // G1 ≤ 1 (lit from above)
            return t;
        }
        let g1 = 1.0 / k_next;
        // the cap exceeds G1 where C·k_next ≥ 4πĉ (P ≥ 1/(4π)) or C·D_floor ≥ 4ĉ|cos θin|
        // (P ≥ s·D_floor/(4k_next|cos θin|), `PeakScales::floor`)
        let reference = self.reference;
        let factor = if PEAK_CAP_MARGIN * k_next >= 4.0 * PI * reference
            || PEAK_CAP_MARGIN * pf.peaks.floor >= 4.0 * reference * f64::from(next.w.z.abs())
        {
            g1
        } else {
            self.capped(pf, g1, next, k_next)
        };
        (t * factor.max(1.0)).min(1.0)
    }

    /// min(G1, C·P/ĉ), the survival factor where the cap may bind.
    #[inline(never)]
    fn capped<S: MicrosurfaceSlope, M: Material>(
        &self,
        pf: &PositionFree<S, M>,
        g1: f64,
        next: Incident,
        k_next: f64,
    ) -> f64 {
        // NaN (0/0: no reference and no peak) keeps G1
        g1.min(PEAK_CAP_MARGIN * pf.phase_peak(next.in_frame(), k_next) / self.reference)
    }
}

/// The scales of the phase function's peak that [`Roulette::survival`] needs, fixed for a
/// surface: computed once by [`PositionFree::new`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct PeakScales {
    /// The bound of a facet's scattering relative to a mirror's, D/(4A) per unit D: 1 for
    /// opaque materials; for a dielectric the refraction's largest Jacobian factor
    /// 4(1 − F)⟨ωi, ωh⟩|⟨ωo, ωh⟩| r²/(⟨ωi, ωh⟩ − r|⟨ωo, ωh⟩|)² ≤ 4r²/(1 − r)² (at normal
    /// incidence on the facet; r the index ratio of either direction, 36 for η = 1.5, +∞ for
    /// η = 1). A diffuse facet's phase function is at most albedo/π, which the mirror's peak
    /// D(m*)/(4A) exceeds wherever 4A < π D(m*); elsewhere (A < 1 on the vertices that use it)
    /// it can fall short by a factor below 4, which the margin C absorbs.
    pub(crate) material: f64,
    /// `material` times the least of D at the zenith and at the normals 1e-3 above the horizon
    /// along x and y: a lower bound of D over the hemisphere for the axis-aligned GGX and
    /// Beckmann (0 for Beckmann, whose D vanishes at the horizon), an estimate for other slopes
    /// (an overestimate only keeps the factor G1 in [`Roulette::survival`]).
    pub(crate) floor: f64,
}

impl PeakScales {
    /// The scales of a surface with slope distribution `slope` and material `material`.
    pub(crate) fn new<S: MicrosurfaceSlope, M: Material>(slope: &S, material: &M) -> Self {
        let d = |m: DVec3| slope.d64_unchecked(m.normalize());
        let mut floor = d(DVec3::Z).min(d(DVec3::new(1.0, 0.0, 1e-3)));
        if slope.alpha_x() != slope.alpha_y() {
            floor = floor.min(d(DVec3::new(0.0, 1.0, 1e-3)));
        }
        let scale = if M::TRANSMITS {
            let refraction = |r_sq: f64| 4.0 * r_sq / (1.0 - r_sq.sqrt()).powi(2);
            let eta_sq = f64::from(material.relative_eta_sq(Side::Outside, Side::Inside));
            refraction(eta_sq).max(refraction(1.0 / eta_sq)).max(1.0)
        } else {
            1.0
        };
        Self { material: scale, floor: scale * floor }
    }
}

impl<S: MicrosurfaceSlope, M: Material> PositionFree<S, M> {
    /// P(ω) = s·D(m*)/(4A(ω)): a bound of the peak of the phase function from the incident
    /// direction ω (in its side frame) with 1 + L̃ = `k`. D(m*)/(4A(ω)) is the peak of the
    /// mirror-facet phase function D(ωh)/(4A(ω)), m* the facet visible from ω closest to the
    /// slopes' mode: +z for ω above the horizon; below it, the normal ⊥ ω whose slope is closest
    /// to 0 in the metric of (αx, αy) (the most probable facet ω grazes, exactly so for an
    /// axis-aligned elliptical distribution), which the reflection's forward limit ωo → −ω
    /// reaches. A(ω) = k|cos θ|. s = [`PeakScales::material`] bounds a refraction's phase
    /// function relative to a mirror's (1 for opaque materials).
    ///
    /// Used only as a scale (its accuracy sets the roulette's variance, not its bias). Where k
    /// underflows (Beckmann, a > 26.6) D(m*)/A is formed by the visible-normal density at a
    /// facet 1e-9 rad inside the visible side of m*, which evaluates it in log space.
    /// +∞ at the nadir (no facet grazes ω).
    #[inline]
    pub(crate) fn phase_peak(&self, w: Vec3, k: f64) -> f64 {
        let scale = 0.25 * self.peaks.material;
        let z = f64::from(w.z);
        if z >= 0.0 {
            return scale * self.model.slope.d64_unchecked(DVec3::Z) / (k * z);
        }
        let (x, y) = (f64::from(w.x), f64::from(w.y));
        let (ax, ay) = (f64::from(self.model.slope.alpha_x()), f64::from(self.model.slope.alpha_y()));
        let (ax2, ay2) = (ax * ax, ay * ay);
        let q = ax2 * x * x + ay2 * y * y;
        if q <= 0.0 || q.is_nan() {
            return f64::INFINITY;
        }
        // the slope s* = (z/q)(αx² x, αy² y) on the visibility line s·(x, y) = z, and
        // m* ∝ (−s*, 1) (then m*·ω = 0)
        let l = z / q;
        let m = DVec3::new(-l * ax2 * x, -l * ay2 * y, 1.0).normalize();
        if k >= LAMBDA_RATIO_LOG_BELOW {
            return scale * self.model.slope.d64_unchecked(m) / (k * -z);
        }
        // Λ(−ω) below f64's range: D(m*) underflows with it; D/A from the visible-normal
        // density just inside m*, which forms it in log space
        let w64 = w.as_dvec3();
        let inside = (m + 1e-9 * w64).normalize();
        scale * self.model.slope.d_wi64_unchecked(w, inside) / w64.dot(inside)
    }
}
