//! The random walk on the microsurface: stochastic evaluation and sampling of the
//! multiple-scattering BSDF (Heitz et al. 2016, supplement §3.1 Algorithms 2–3 and §3.4).

use super::Microsurface;
use super::geometry::{MIN_HIT_DEPTH, ScaledDepth, first_hit_two_sided, flip_ln_c1, next_ln_c1};
use crate::contract::is_direction;
use crate::height::MicrosurfaceHeight;
use crate::material::{Interaction, Material, PhaseSample, Side};
use crate::rng::{uniform, uniform_pair};
use crate::slope::MicrosurfaceSlope;
use crate::special::{exp_f32, ln_f32};
use core::num::NonZeroU32;
use glam::Vec3;
use rand::Rng;

/// The hard cap on the number of bounces of one walk: 2¹⁶.
///
/// Walks end with probability one; the cap only guards against non-termination. A walk that
/// reaches it is dropped (its energy is lost). The longest walks are those of a grazing ray
/// through a dielectric with η within a few f32 ulps of 1, which crosses the nearly
/// index-matched interface about Λ(ωi) ≈ αᵢ tan θi/2 times before refraction turns it (at
/// most about 10⁴ bounces); η = 1 exactly is transparent
/// ([`crate::research::Material::is_transparent`]). Loss bound (`tests/walk/cap.rs`, 99 % family-wise
/// confidence): below 1e-4 of the albedo for every material at α = 2, and no capped walk for
/// |η − 1| ≥ 1e-7 at cos θi ≥ 1e-3. The measurements behind the value are in DESIGN.md
/// (“The bounce cap”).
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

    /// Whether the walks leave the depth undrawn while they can ([`Depth`]): for opaque
    /// materials. A dielectric's walk crosses the interface at most first hits (η = 1.5: 92 %
    /// at θi = 0.5), where the depth must be drawn anyway, and the measured cost of carrying
    /// the undrawn state was higher than its gain there (DESIGN.md, “Walk speed”).
    const LAZY: bool = !M::TRANSMITS;

    /// The rate a of an undrawn depth ([`Depth`]), `None` for a drawn one (always, known at
    /// compile time, where the walks draw every depth: [`Self::LAZY`]).
    #[inline(always)]
    fn undrawn_rate(depth: Depth) -> Option<f32> {
        if Self::LAZY { depth.rate() } else { None }
    }

    /// ln C¹ of `depth`, drawn now if it was not ([`Depth::drawn`]; never, known at compile
    /// time, where the walks draw every depth: [`Self::LAZY`]), or taken now where the depth
    /// holds C¹ itself ([`Depth::two_sided`]).
    #[inline(always)]
    fn drawn(depth: Depth, rng: &mut impl Rng) -> f32 {
        if Self::LAZY { depth.drawn(rng) } else { depth.ln_c1() }
    }

    /// The side a phase sample leaves on, known at compile time for an opaque material
    /// ([`Side::Outside`]), so that the walk's side bookkeeping (frames, flips of ln C¹)
    /// folds away for conductors and diffuse facets, whose sampler is not inlined.
    #[inline(always)]
    fn side_after(sampled: Side) -> Side {
        if M::TRANSMITS { sampled } else { Side::Outside }
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
    /// The next-event masking C¹^Λ(ωo) is replaced by its conditional expectation where that
    /// is known in closed form, a/(a + Λ(ωo)): at the first hit on ωi's side (a = 1 + Λ(ωi))
    /// and, for opaque materials, at every hit reached since by rays going up, whose height the
    /// walk does not draw (its law stays a e^{aℓ}; see DESIGN.md, “Walk speed”).
    /// The estimate stays unbiased and its variance drops; order 1 is the exact single
    /// scattering term. The next-event phase function of a reflection is formed from the
    /// unnormalized half vector in f64 (the same accuracy as [`Material::eval_phase`]).
    ///
    /// Invalid input ([policy](crate#invalid-input)): a `wi` or `wo` that is not a unit
    /// direction gives 0 (a debug assertion in debug builds).
    pub fn eval(&self, wi: Vec3, wo: Vec3, order: ScatteringOrder, rng: &mut impl Rng) -> Vec3 {
        require!(is_direction(wi) && is_direction(wo), Vec3::ZERO; wi, wo);
        let Some(side) = Self::starting_side(wi) else {
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
        let wo_side = if M::TRANSMITS { Side::above_or_inside(wo.z) } else { Side::Outside };
        // Λ of ωo seen from its own side, constant along the walk
        let lambda_o = self.geometry.slope().lambda_unchecked(wo_side.frame(wo));
        // the height in the frame of the current side starts above the surface (ln C¹ = 0); it
        // may stay undrawn on ωi's side, where ωo's masking is then known in closed form
        let Some(first) = Depth::first_hit(self, -wi, side, rng) else { return Vec3::ZERO };
        self.walk(-wi, side, first, Evaluation::<Depth>::new(wo, wo_side, order, lambda_o), rng)
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
    /// For opaque materials the heights of hits reached by rays going up are not drawn: such a
    /// ray escapes with probability a/(a + Λ(ωr)), a = 1 + Λ(ωi), which is the walk's law
    /// (DESIGN.md, “Walk speed”); a height is drawn when a ray goes down.
    ///
    /// Invalid input ([policy](crate#invalid-input)): a `wi` that is not a unit direction gives
    /// `None` (a debug assertion in debug builds).
    pub fn sample(&self, wi: Vec3, rng: &mut impl Rng) -> Option<WalkSample> {
        require!(is_direction(wi), None; wi);
        let Some(side) = Self::starting_side(wi) else {
            return if !M::TRANSMITS && wi.z < 0.0 { self.sample_from_below(wi, rng) } else { None };
        };
        if self.material.is_transparent() {
            return Some(WalkSample { wo: -wi, weight: Vec3::ONE, bounces: 1 });
        }
        let Some(first) = Depth::first_hit(self, -wi, side, rng) else {
            return Some(WalkSample { wo: -wi, weight: Vec3::ONE, bounces: 0 });
        };
        self.walk(-wi, side, first, Sampling { weight: Vec3::ONE }, rng)
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
    /// ordinary one (supplement §3.1, Algorithm 2), every exit being upwards. It carries the
    /// depth in the scale of the first hit, −ln C¹·Λ(−ωi), with the masking ratios formed
    /// from ln Λ (`ScaledDepth`), so that it works for every roughness: Λ(−ωi) ≈ e^{−a²}
    /// (Beckmann, a = |cot θi|/αᵢ) underflows f32 from a ≈ 9.6 and f64 from a ≈ 26.6. Its order-1 term
    /// is exactly p(ωi, ωo) Λ(−ωi)/(Λ(−ωi) + Λ(ωo)) = F D G2/(4|cos θi|) with the full-spherical
    /// G2 = 1/(Λ(−ωi) + Λ(ωo)) (Wang et al. 2022, eq. 17) of the single-scattering model.
    ///
    /// 0 when ωo is at or below the horizon, or when Λ(−ωi) = 0 (ωi at the nadir sees no
    /// microsurface). Stochastic and unbiased, consistent with
    /// [`Microsurface::sample_from_below`] (the same walk).
    pub fn eval_from_below(&self, wi: Vec3, wo: Vec3, order: ScatteringOrder, rng: &mut impl Rng) -> Vec3 {
        if M::TRANSMITS || !(wi.z < 0.0 && wo.z > 0.0) {
            return Vec3::ZERO;
        }
        let slope = self.geometry.slope();
        let Some(first) = ScaledDepth::first(slope.ln_lambda(-wi), uniform(rng)) else {
            return Vec3::ZERO;
        };
        let ln_lambda_o = slope.ln_lambda(wo);
        let evaluation = Evaluation::<ScaledDepth>::new(wo, Side::Outside, order, ln_lambda_o);
        self.walk(-wi, Side::Outside, Vertex::from_below(first), evaluation, rng)
    }

    /// [`Microsurface::sample`] for an opaque material lit from below the macrosurface
    /// (ωi.z < 0): the walk of [`Microsurface::eval_from_below`] (first intersection at
    /// ln C¹ = ln(1 − u)/Λ(−ωi), normal from D_ωi), then the ordinary walk (supplement §3.1,
    /// Algorithm 3). Every path leaves upwards, so for F = 1 the weight is exactly 1 (energy is
    /// conserved, up to walks reaching [`MAX_BOUNCES`]); otherwise it is the product of the
    /// phase-sample weights, f·|cos θo|/pdf.
    ///
    /// `None` if ωi is not below the horizon, the material transmits, Λ(−ωi) = 0, the path was
    /// absorbed, or it reached [`MAX_BOUNCES`]. Every roughness is resolved, as in
    /// [`Microsurface::eval_from_below`].
    pub fn sample_from_below(&self, wi: Vec3, rng: &mut impl Rng) -> Option<WalkSample> {
        if M::TRANSMITS || wi.z.is_nan() || wi.z >= 0.0 {
            return None;
        }
        let first = ScaledDepth::first(self.geometry.slope().ln_lambda(-wi), uniform(rng))?;
        self.walk(-wi, Side::Outside, Vertex::from_below(first), Sampling { weight: Vec3::ONE }, rng)
    }

    /// The random walk itself (supplement §3.1, Algorithms 2 and 3; §3.4 inside a dielectric),
    /// from its first vertex `first`, reached by the ray `wr` on `side`, to its exit, its
    /// absorption or its last bounce: at each vertex the `estimator` evaluates and/or samples
    /// the phase function ([`Estimator`]: `eval` or `sample`), the heights ([`Heights`]: ln C¹
    /// from above, or the first hit's scale from below) cross the interface with the sampled
    /// direction and give the next vertex. Bounce k is the k-th vertex; `sample` walks at
    /// most [`MAX_BOUNCES`], `eval` up to the last order it counts.
    #[inline(always)]
    fn walk<D: Heights, E: Estimator<D>>(
        &self,
        wr: Vec3,
        side: Side,
        first: Vertex<D>,
        mut estimator: E,
        rng: &mut impl Rng,
    ) -> E::Output {
        let (mut wr, mut side, mut at) = (wr, side, first);
        let mut bounce = 1;
        loop {
            let Some((s, other_side)) = estimator.vertex(self, bounce, &at, wr, side, rng) else {
                return estimator.end();
            };
            let next_side = Self::side_after(s.side);
            let depth = if next_side != side {
                other_side.unwrap_or_else(|| D::other_side(&at, self, rng))
            } else {
                at.depth
            };
            wr = s.wo;
            side = next_side;
            if !estimator.carry(s.weight) {
                return estimator.end();
            }
            let Some(next) = depth.hit(self, wr, side, rng) else {
                return estimator.escaped(wr, bounce);
            };
            if estimator.capped(bounce) {
                return estimator.end();
            }
            at = next;
            bounce += 1;
        }
    }
}

/// What a walk does at its vertices: `eval`'s next-event estimation ([`Evaluation`]) or
/// `sample`'s path ([`Sampling`]), over the heights `D`. Every method is inlined into
/// [`Microsurface::walk`], which compiles to one loop per estimator and height model.
trait Estimator<D: Heights> {
    /// The walk's result.
    type Output;

    /// The phase-function work at bounce `bounce`, the vertex `at` reached by the ray `wr` on
    /// `side`: the sample of the next direction and, where the estimator formed it, the
    /// vertex's point seen from the other side of the interface ([`Heights::other_side`],
    /// which a crossing reuses); or `None` to end the walk there.
    fn vertex<H: MicrosurfaceHeight, S: MicrosurfaceSlope, M: Material>(
        &mut self,
        surface: &Microsurface<H, S, M>,
        bounce: u32,
        at: &Vertex<D>,
        wr: Vec3,
        side: Side,
        rng: &mut impl Rng,
    ) -> Option<(PhaseSample, Option<D>)>;

    /// Multiplies the path's weight by a phase sample's; false once it is zero (absorbed).
    fn carry(&mut self, weight: Vec3) -> bool;

    /// Whether the walk ends (is dropped) after bounce `bounce` although it did not escape.
    fn capped(&self, bounce: u32) -> bool;

    /// The result of a walk that left the surface along `wo` after `bounces` bounces.
    fn escaped(self, wo: Vec3, bounces: u32) -> Self::Output;

    /// The result of a walk that ended otherwise: absorbed, capped or at its last bounce.
    fn end(self) -> Self::Output;
}

/// `eval`'s estimator: next-event estimation of f·|cos θo| towards ωo (supplement §3.1,
/// Algorithm 2), for the orders `order` selects.
struct Evaluation<D: Heights> {
    wo: Vec3,
    /// The side ωo lies on ([`Side::Outside`] for opaque materials).
    wo_side: Side,
    order: ScatteringOrder,
    /// The last bounce the walk needs to simulate ([`ScatteringOrder::last`]).
    last: u32,
    /// What the masking of ωo needs from ωo ([`Heights::Wo`]).
    masking_wo: D::Wo,
    throughput: Vec3,
    sum: Vec3,
}

impl<D: Heights> Evaluation<D> {
    #[inline(always)]
    fn new(wo: Vec3, wo_side: Side, order: ScatteringOrder, masking_wo: D::Wo) -> Self {
        Self { wo, wo_side, order, last: order.last(), masking_wo, throughput: Vec3::ONE, sum: Vec3::ZERO }
    }
}

impl<D: Heights> Estimator<D> for Evaluation<D> {
    type Output = Vec3;

    /// The next-event term (where `order` counts the bounce) and the next direction in one
    /// material call; at the last bounce the term alone. Where ωo lies across the interface
    /// (a dielectric), the masking takes the vertex's point seen from ωo's side, which is
    /// returned for a crossing of the sampled direction: one ln(1 − C¹) per vertex. A first
    /// hit held as C¹ returns the exact 1 − C¹ instead; its masking takes the logarithm of
    /// that, and so does the crossing ray where its escape bound does not decide (rare: passing
    /// the masking's logarithm on measured 2–5 instructions more per `eval`).
    #[inline(always)]
    fn vertex<H: MicrosurfaceHeight, S: MicrosurfaceSlope, M: Material>(
        &mut self,
        surface: &Microsurface<H, S, M>,
        bounce: u32,
        at: &Vertex<D>,
        wr: Vec3,
        side: Side,
        rng: &mut impl Rng,
    ) -> Option<(PhaseSample, Option<D>)> {
        let (slope, material) = (surface.geometry.slope(), &surface.material);
        let it = Interaction::new(-wr, self.wo, side, self.wo_side).with_incident_area(at.incident_area);
        let includes = self.order.includes(bounce);
        let same_side = side == self.wo_side;
        if bounce == self.last {
            if includes {
                let phase = material.eval_phase_unchecked(slope, &it, rng);
                if phase != Vec3::ZERO {
                    let seen = if same_side { at.depth } else { D::other_side(at, surface, rng) };
                    let masking = D::masking(surface, at, bounce, seen, same_side, self.masking_wo);
                    self.sum += self.throughput * phase * masking;
                }
            }
            return None;
        }
        if !includes {
            return Some((material.sample_phase_walk_unchecked(slope, -wr, side, rng), None));
        }
        let (phase, s) = material.eval_and_sample_phase_unchecked(slope, &it, rng);
        let other_side = (!same_side).then(|| D::other_side(at, surface, rng));
        if phase != Vec3::ZERO {
            let seen = other_side.unwrap_or(at.depth);
            let masking = D::masking(surface, at, bounce, seen, same_side, self.masking_wo);
            self.sum += self.throughput * phase * masking;
        }
        Some((s, other_side))
    }

    #[inline(always)]
    fn carry(&mut self, weight: Vec3) -> bool {
        self.throughput *= weight;
        self.throughput != Vec3::ZERO
    }

    /// Never: the walk ends at its last bounce ([`ScatteringOrder::last`] ≤ [`MAX_BOUNCES`]).
    #[inline(always)]
    fn capped(&self, _bounce: u32) -> bool {
        false
    }

    #[inline(always)]
    fn escaped(self, _wo: Vec3, _bounces: u32) -> Vec3 {
        self.sum
    }

    #[inline(always)]
    fn end(self) -> Vec3 {
        self.sum
    }
}

/// `sample`'s estimator: the path's weight, the product of the phase samples' (supplement
/// §3.1, Algorithm 3).
struct Sampling {
    weight: Vec3,
}

impl<D: Heights> Estimator<D> for Sampling {
    type Output = Option<WalkSample>;

    #[inline(always)]
    fn vertex<H: MicrosurfaceHeight, S: MicrosurfaceSlope, M: Material>(
        &mut self,
        surface: &Microsurface<H, S, M>,
        _bounce: u32,
        _at: &Vertex<D>,
        wr: Vec3,
        side: Side,
        rng: &mut impl Rng,
    ) -> Option<(PhaseSample, Option<D>)> {
        Some((surface.material.sample_phase_walk_unchecked(surface.geometry.slope(), -wr, side, rng), None))
    }

    #[inline(always)]
    fn carry(&mut self, weight: Vec3) -> bool {
        self.weight *= weight;
        self.weight != Vec3::ZERO
    }

    /// After [`MAX_BOUNCES`] bounces (the walk is dropped: its energy is lost).
    #[inline(always)]
    fn capped(&self, bounce: u32) -> bool {
        bounce == MAX_BOUNCES
    }

    #[inline(always)]
    fn escaped(self, wo: Vec3, bounces: u32) -> Option<WalkSample> {
        Some(WalkSample { wo, weight: self.weight, bounces })
    }

    #[inline(always)]
    fn end(self) -> Option<WalkSample> {
        None
    }
}

/// How a walk tracks the heights of its vertices (supplement §3.1, Algorithm 1): as ln C¹ in
/// the frame of the current side for walks from above ([`Depth`]), in the scale of the first
/// hit for walks from below the macrosurface ([`ScaledDepth`]).
trait Heights: Copy {
    /// What the masking of ωo needs from ωo, constant along the walk.
    type Wo: Copy;

    /// The next vertex of the ray `wr` leaving a point at this height on `side` (both in the
    /// frame of that side), or `None` if it escapes.
    fn hit<H: MicrosurfaceHeight, S: MicrosurfaceSlope, M: Material>(
        self,
        surface: &Microsurface<H, S, M>,
        wr: Vec3,
        side: Side,
        rng: &mut impl Rng,
    ) -> Option<Vertex<Self>>;

    /// The point of the vertex `at` seen from the other side of a dielectric interface.
    fn other_side<H: MicrosurfaceHeight, S: MicrosurfaceSlope, M: Material>(
        at: &Vertex<Self>,
        surface: &Microsurface<H, S, M>,
        rng: &mut impl Rng,
    ) -> Self;

    /// The masking of ωo at the vertex `at` of bounce `bounce`, whose point seen from ωo's
    /// side is `seen` (`at.depth`, or [`Heights::other_side`] where ωo lies across the
    /// interface: `same_side` false): the probability that a ray from there escapes along ωo,
    /// or its conditional expectation where that is known in closed form.
    fn masking<H: MicrosurfaceHeight, S: MicrosurfaceSlope, M: Material>(
        surface: &Microsurface<H, S, M>,
        at: &Vertex<Self>,
        bounce: u32,
        seen: Self,
        same_side: bool,
        wo: Self::Wo,
    ) -> f32;
}

impl Heights for Depth {
    /// Λ(ωo) seen from ωo's side.
    type Wo = f32;

    /// One Λ per bounce: the Λ(ωr) of the height step also gives the projected area of the
    /// next vertex's incident direction ([`incident_area`]).
    ///
    /// For an opaque material (`Microsurface::LAZY`), the first hit of a ray from above the
    /// surface is left undrawn ([`Depth::undrawn`]), and so is every later hit as long as the
    /// rays go up: such a ray escapes with probability E[C¹^Λ(ωr)] = a/(a + Λ(ωr)) (one
    /// uniform, no logarithm), and otherwise hits at a height with the same law a e^{aℓ} (see
    /// [`Depth`]). A ray going down (or horizontally) from an undrawn depth draws it first (one
    /// uniform), then steps as Algorithm 1 does.
    #[inline(always)]
    fn hit<H: MicrosurfaceHeight, S: MicrosurfaceSlope, M: Material>(
        self,
        surface: &Microsurface<H, S, M>,
        wr: Vec3,
        side: Side,
        rng: &mut impl Rng,
    ) -> Option<Vertex<Self>> {
        let lazy = Microsurface::<H, S, M>::LAZY;
        let w = side.frame(wr);
        let lambda = surface.geometry.slope().lambda_unchecked(w);
        let depth = match Microsurface::<H, S, M>::undrawn_rate(self) {
            // the ray from above the surface (ln C¹ = 0, going down): its hit ln C¹ has the
            // density a e^{aℓ} with a = |Λ(ωr)| = 1 + Λ(ωi)
            None if lazy && self == Depth::ABOVE && w.z < 0.0 => Depth::undrawn(-lambda),
            Some(rate) if w.z > 0.0 => {
                // rate/(rate + Λ) ≤ 1, 0 where Λ saturates at f32::MAX (a discrete choice: u
                // is not cut, P(u < p) = p to 2⁻²⁴, as for the dielectric's Fresnel choice)
                if uniform(rng) < rate / (rate + lambda) {
                    return None;
                }
                self
            }
            // a dielectric's first hit held as C¹ ([`Depth::two_sided`]), seen from either
            // side, and a ray going up: most escape without the logarithm
            None if !lazy && self.0 > 0.0 && w.z >= 0.0 => {
                let u = uniform(rng);
                if escapes_from_held_c1(lambda, self.0, u) {
                    return None;
                }
                Depth::at(next_ln_c1(w.z, lambda, self.ln_c1(), u)?)
            }
            _ => {
                let ln_c1 = Microsurface::<H, S, M>::drawn(self, rng);
                Depth::at(next_ln_c1(w.z, lambda, ln_c1, uniform(rng))?)
            }
        };
        Some(Vertex { depth, lambda, incident_area: incident_area(w.z, lambda) })
    }

    /// ln(1 − C¹) ([`flip_ln_c1`]), the depth drawn first if it was not; 1 − C¹ itself (exact)
    /// where the depth holds C¹ ([`Depth::two_sided`]: the point seen from the other side,
    /// held alike, its logarithm taken where it is needed).
    #[inline(always)]
    fn other_side<H: MicrosurfaceHeight, S: MicrosurfaceSlope, M: Material>(
        at: &Vertex<Self>,
        _surface: &Microsurface<H, S, M>,
        rng: &mut impl Rng,
    ) -> Self {
        if !Microsurface::<H, S, M>::LAZY && at.depth.0 > 0.0 {
            return Depth::two_sided(1.0 - at.depth.0);
        }
        Depth::at(flip_ln_c1(Microsurface::<H, S, M>::drawn(at.depth, rng)))
    }

    /// [`masking`], in closed form at an undrawn depth, and at a dielectric's first hit on
    /// ωo's side (whose depth is drawn at once: see `Microsurface::LAZY`).
    #[inline(always)]
    fn masking<H: MicrosurfaceHeight, S: MicrosurfaceSlope, M: Material>(
        _surface: &Microsurface<H, S, M>,
        at: &Vertex<Self>,
        bounce: u32,
        seen: Self,
        same_side: bool,
        lambda_o: f32,
    ) -> f32 {
        let closed = match Microsurface::<H, S, M>::undrawn_rate(at.depth) {
            Some(rate) => Some(rate),
            None if !Microsurface::<H, S, M>::LAZY => (bounce == 1 && same_side).then_some(-at.lambda),
            None => None,
        };
        // ln C¹ of a point held as C¹ ([`Depth::two_sided`]): the first hit's seen from ωo
        // across the interface (on its own side, its masking is closed)
        let seen =
            if Microsurface::<H, S, M>::LAZY || closed.is_some() { seen } else { Depth::at(seen.ln_c1()) };
        masking(closed, seen, lambda_o)
    }
}

impl Heights for ScaledDepth {
    /// ln Λ(ωo).
    type Wo = f64;

    /// [`ScaledDepth::next`]; every vertex is outside (opaque materials only).
    #[inline(always)]
    fn hit<H: MicrosurfaceHeight, S: MicrosurfaceSlope, M: Material>(
        self,
        surface: &Microsurface<H, S, M>,
        wr: Vec3,
        _side: Side,
        rng: &mut impl Rng,
    ) -> Option<Vertex<Self>> {
        self.next(surface.geometry.slope(), wr, uniform(rng)).map(Vertex::from_below)
    }

    /// Never called: the walks from below are those of opaque materials, which no ray crosses.
    #[inline(always)]
    fn other_side<H: MicrosurfaceHeight, S: MicrosurfaceSlope, M: Material>(
        at: &Vertex<Self>,
        _surface: &Microsurface<H, S, M>,
        _rng: &mut impl Rng,
    ) -> Self {
        at.depth
    }

    /// C¹^Λ(ωo) ([`ScaledDepth::escape_probability`]), rounded to f32.
    #[inline(always)]
    fn masking<H: MicrosurfaceHeight, S: MicrosurfaceSlope, M: Material>(
        _surface: &Microsurface<H, S, M>,
        _at: &Vertex<Self>,
        _bounce: u32,
        seen: Self,
        _same_side: bool,
        ln_lambda_o: f64,
    ) -> f32 {
        seen.escape_probability(ln_lambda_o) as f32
    }
}

/// The height of the walk's current point, as ln C¹ in the frame of its side.
///
/// The first hit of a ray arriving from above the surface (ln C¹ = 0) along ωr has ln C¹ with
/// the density a e^{aℓ} on (−∞, 0), a = |Λ(ωr)| = 1 + Λ(ωi) (Algorithm 1 from h = +∞:
/// C¹₁ has the CDF c^a). The height enters what follows only through the masking of ωo
/// (next-event estimation), the escape of the next ray and the next height. For a next ray ω
/// going up (Λ = Λ(ω) ≥ 0), E[e^{Λℓ}] = a/(a + Λ) is its escape probability, and given that it
/// hits, the next ln C¹ = ℓ − ln(1 − u)/Λ has the density
/// ∫_{−∞}^{ℓ′} a e^{aℓ} Λ e^{−Λ(ℓ′ − ℓ)} dℓ / (Λ/(a + Λ)) = a e^{aℓ′}: the same law again. So
/// as long as the rays go up, the height need not be drawn at all: the escapes are drawn with
/// probability a/(a + Λ) and the masking of ωo is replaced by its conditional expectation
/// a/(a + Λ(ωo)) (it does not influence the rest of the walk, so the estimate stays unbiased,
/// and its variance drops). The walk's law is unchanged; it draws the height from a e^{aℓ}
/// when it needs it: a ray going down (or horizontally), or a crossing of a dielectric
/// interface (only opaque materials leave it undrawn: `Microsurface::LAZY`).
///
/// One f32: ln C¹ ≤ 0 where drawn (0 above the surface; hits lie at ≤ −`MIN_HIT_DEPTH`, a
/// flipped depth may be −0), the rate a > 0 (a ≥ 1) where undrawn. A single float rather than
/// an enum: measured 10 instructions per walk cheaper. A dielectric's walk, which draws every
/// depth, uses the positive numbers for C¹ itself at its first hit instead ([`Depth::two_sided`]).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Depth(f32);

/// The largest Λ(ωi) for which a dielectric's first hit is drawn as max(C, W)
/// ([`Depth::two_sided`]); beyond, W is the maximum too often (with probability
/// Λ(ωi)/(1 + Λ(ωi))) for the logarithm it saves where C is. Measured per `eval` of GGX glass
/// (η = 1.5, θi = 0.5, ωo inside) against the draw of [`next_ln_c1`]: fewer instructions at
/// α = 0.5 (Λ(ωi) = 0.018) and α = 2 (0.24), even at α = 3 (0.46).
const TWO_SIDED_UP_TO: f32 = 0.5;

impl Depth {
    /// Above the surface: ln C¹ = 0 (where every walk from ωi's side starts).
    const ABOVE: Self = Self(0.0);

    /// A drawn depth, ln C¹ ≤ 0.
    #[inline(always)]
    fn at(ln_c1: f32) -> Self {
        Self(ln_c1)
    }

    /// An undrawn depth of density a e^{aℓ}, a = `rate` > 0.
    #[inline(always)]
    fn undrawn(rate: f32) -> Self {
        Self(rate)
    }

    /// A dielectric's first hit (from above, with Λ(ωi) ≤ [`TWO_SIDED_UP_TO`]) drawn as
    /// max(C, W) by [`first_hit_two_sided`]: ln C¹ ≤ 0 where W is the maximum, and where the
    /// uniform C is, C¹ = C ∈ (0, 1) itself. Its point is then held on both sides of the
    /// interface: C¹ on its side, the exact 1 − C¹ on the other (`Heights::other_side`, where
    /// [`flip_ln_c1`] would take an exponential and a logarithm after the logarithm of the
    /// draw), each logarithm ([`Depth::ln_c1`]) taken only where the walk needs it: for the
    /// masking of ωo across the interface in `eval` (on the first hit's own side it is closed,
    /// see [`masking`]), and for the step of a ray leaving the point that the escape bound
    /// [`escapes_from_held_c1`] does not send out (the refracted ray escapes without any
    /// logarithm nine times in ten at the listing's glass).
    #[inline(always)]
    fn two_sided(depth: f32) -> Self {
        Self(depth)
    }

    /// The first vertex of a walk from above the surface, reached by the ray `wr` on `side`
    /// (going down): [`Heights::hit`] from [`Depth::ABOVE`], but for a dielectric, whose depth
    /// is drawn [`Depth::two_sided`] where Λ(ωi) ≤ [`TWO_SIDED_UP_TO`] and by [`next_ln_c1`]
    /// beyond. That takes Λ(ωi) of ωi = −ωr itself (−1 − Λ(ωr) would cancel) and
    /// Λ(ωr) = −1 − Λ(ωi) from it (the slopes' Λ below the horizon, GGX's bit for bit).
    #[inline(always)]
    fn first_hit<H: MicrosurfaceHeight, S: MicrosurfaceSlope, M: Material>(
        surface: &Microsurface<H, S, M>,
        wr: Vec3,
        side: Side,
        rng: &mut impl Rng,
    ) -> Option<Vertex<Self>> {
        if Microsurface::<H, S, M>::LAZY {
            return Depth::ABOVE.hit(surface, wr, side, rng);
        }
        // the walks start on ωi's side ([`Microsurface::eval`]): the ray goes down
        let w = side.frame(wr);
        debug_assert!(w.z < 0.0, "a first ray {w} not going down");
        let lambda_i = surface.geometry.slope().lambda_unchecked(-w);
        let lambda = -1.0 - lambda_i;
        let depth = if lambda_i <= TWO_SIDED_UP_TO {
            let (u1, u2) = uniform_pair(rng);
            Depth::two_sided(first_hit_two_sided(lambda_i, u1, u2))
        } else {
            Depth::at(next_ln_c1(w.z, lambda, 0.0, uniform(rng))?)
        };
        Some(Vertex { depth, lambda, incident_area: incident_area(w.z, lambda) })
    }

    /// ln C¹ of a depth drawn in full: the f32 itself, or the logarithm of C¹ where it holds
    /// C¹ ([`Depth::two_sided`]).
    #[inline(always)]
    fn ln_c1(self) -> f32 {
        if self.0 > 0.0 { ln_f32(self.0) } else { self.0 }
    }

    /// The rate a of an undrawn depth, `None` for a drawn one (opaque walks only: a
    /// dielectric's positive depth is a first hit held as C¹, [`Depth::two_sided`]).
    #[inline(always)]
    fn rate(self) -> Option<f32> {
        (self.0 > 0.0).then_some(self.0)
    }

    /// ln C¹, drawn now from a e^{aℓ} if it was not: ln(1 − u)/a (the first step of
    /// Algorithm 1 from above the surface, `next_ln_c1` for a ray going down with Λ = −a; u
    /// cut as there).
    #[inline(always)]
    fn drawn(self, rng: &mut impl Rng) -> f32 {
        if self.0 > 0.0 {
            next_ln_c1(-1.0, -self.0, 0.0, uniform(rng)).unwrap_or(-MIN_HIT_DEPTH)
        } else {
            self.0
        }
    }
}

/// Whether a ray going up with Λ = `lambda` ≥ 0 from a point held as C¹ = `c1`
/// ([`Depth::two_sided`]: a multiple of 2⁻²⁴ in (0, 1), 1 − C¹ exact) escapes for the uniform
/// `u`, decided without a logarithm: where u C¹ ≥ Λ (1 − C¹) (products of f32, exact in f64),
/// ln(1 − u) ≤ −u ≤ −Λ (1 − C¹)/C¹ ≤ Λ ln C¹, the escape of [`next_ln_c1`] (whose cut only
/// raises u) in exact arithmetic. Decides most escapes of the rays leaving a dielectric's
/// first hit (Λ small): the refracted ray's, nine in ten at the listing's glass, then needs
/// no logarithm at all.
#[inline(always)]
fn escapes_from_held_c1(lambda: f32, c1: f32, u: f32) -> bool {
    f64::from(u) * f64::from(c1) >= f64::from(lambda) * f64::from(1.0 - c1)
}

/// The masking factor of the next-event estimate at a hit at `depth`, seen from ωo's side
/// (ln(1 − C¹) for a dielectric's ωo across the interface), for ωo with Λ(ωo) = `lambda_o`
/// seen from its own side: C¹^Λ(ωo), the probability that a ray from there escapes along ωo
/// (supplement §3.1).
///
/// Where `closed` holds a rate a, the conditional expectation a/(a + Λ(ωo)) instead: at an
/// undrawn depth (see [`Depth`]) and at the first hit of a ray from above on ωo's side (a =
/// 1 + Λ(ωi), the height-correlated G2/G1 of single scattering), whose ln C¹ has the density
/// a e^{aℓ} given the walk before it. The phase function and the throughput of the term do not
/// depend on the height, so the estimate stays unbiased (Rao–Blackwell) and its variance drops.
/// In f64 (no overflow where Λ saturates at grazing angles), rounded once.
#[inline(always)]
fn masking(closed: Option<f32>, depth: Depth, lambda_o: f32) -> f32 {
    match closed {
        Some(rate) => {
            let rate = f64::from(rate);
            (rate / (rate + f64::from(lambda_o))) as f32
        }
        // `closed` holds the rate of every undrawn depth, so this is ln C¹ ≤ 0
        None => exp_f32(lambda_o * depth.0.min(0.0)),
    }
}

/// A vertex of the walk: an intersection of its ray with the microsurface.
#[derive(Debug, Clone, Copy)]
struct Vertex<D> {
    /// Its height, in the frame of the ray's side.
    depth: D,
    /// Λ(ωr) of the ray, in the same frame (walks from above).
    lambda: f32,
    /// A(ωi) of the incident direction ωi = −ωr there, in the same frame, where known.
    incident_area: Option<f32>,
}

impl Vertex<ScaledDepth> {
    /// A vertex of a walk from below, which passes neither Λ nor the incident area on.
    #[inline(always)]
    fn from_below(depth: ScaledDepth) -> Self {
        Self { depth, lambda: 0.0, incident_area: None }
    }
}

/// The projected area A(ωi) = (1 + Λ(ωi)) cos θi (supplement §2.2) of the incident direction
/// ωi = −ω of a vertex that the ray ω with z-component `z` and Λ(ω) = `lambda` reached: with
/// Λ(ω) = −1 − Λ(ωi), A(ωi) = Λ(ω)·ω.z, one f32 product (relative error below 2⁻²³ beyond
/// that of Λ). This holds on both sides of the horizon: for a ray going up, ωi is backfacing
/// and A(ωi) = Λ(−ωi)|cos θi| (the full-spherical Smith model, Wang et al. 2022, eq. 10).
/// `None` where the product is not a normal f32 (a ray straight up, Λ = 0; a horizontal ray;
/// a Λ(ω) that underflowed, as Beckmann's does for steep rays going up at low roughness: the
/// materials then form the density in f64) and where Λ saturated at ±`f32::MAX`
/// (|cos θ| below ~1e-38·αᵢ, where the product would not be A).
#[inline(always)]
pub(crate) fn incident_area(z: f32, lambda: f32) -> Option<f32> {
    // Λ(ω) and ω.z have the same sign (Λ ≤ −1 below the horizon), so the product is ≥ 0
    let area = lambda * z;
    (area >= f32::MIN_POSITIVE && lambda.abs() < f32::MAX).then_some(area)
}

#[cfg(test)]
mod tests {
    use super::{Depth, Heights, TWO_SIDED_UP_TO, Vertex, escapes_from_held_c1, incident_area};
    use crate::height::UniformHeight;
    use crate::material::{Conductor, Dielectric};
    use crate::microsurface::geometry::{MIN_HIT_DEPTH, first_hit_two_sided, flip_ln_c1, next_ln_c1};
    use crate::microsurface::{Microsurface, ScatteringOrder};
    use crate::rng::{uniform, uniform_pair};
    use crate::slope::{Beckmann, Ggx, MicrosurfaceSlope};
    use glam::Vec3;
    use rand::SeedableRng;
    use rand_pcg::Pcg64Mcg;

    /// The law behind [`Depth::undrawn`], checked on Algorithm 1 as the walk runs it
    /// (`next_ln_c1`): from a point whose ln C¹ has the density a e^{aℓ}, a ray going up with
    /// Λ escapes with probability a/(a + Λ), and given that it hits, its hit's ln C¹ has the
    /// density a e^{aℓ} again (e^{aℓ} uniform on (0, 1)). N = 200 000 two-step draws per
    /// (a, Λ), 12 pairs: the escape share within z σ of a/(a + Λ) and χ² of e^{aℓ} on 20
    /// equal bins, at z = 3.84 and α = 1e-4 each (Šidák over the 12 pairs and both tests at a
    /// family-wise 2e-3), each escape share resolved to 1.2e-3.
    #[test]
    fn undrawn_depth_law_is_algorithm_1s() {
        const N: usize = 200_000;
        const BINS: usize = 20;
        const Z: f64 = 3.84;
        // χ² with 19 degrees of freedom at 1 − 1e-4
        const CHI2_CRITICAL: f64 = 50.8;
        let mut rng = Pcg64Mcg::seed_from_u64(71);
        for a in [1.0f32, 1.07, 3.0, 40.0] {
            for lambda in [0.1f32, 0.6, 5.0] {
                let (mut escaped, mut counts) = (0usize, [0usize; BINS]);
                for _ in 0..N {
                    // the first step from above the surface as `Depth::drawn` takes it
                    let ln_c1 = Depth::undrawn(a).drawn(&mut rng);
                    match next_ln_c1(0.5, lambda, ln_c1, uniform(&mut rng)) {
                        None => escaped += 1,
                        Some(next) => {
                            let v = (f64::from(a) * f64::from(next)).exp();
                            counts[((v * BINS as f64) as usize).min(BINS - 1)] += 1;
                        }
                    }
                }
                let p = f64::from(a) / f64::from(a + lambda);
                let share = escaped as f64 / N as f64;
                let se = (p * (1.0 - p) / N as f64).sqrt();
                assert!(se <= 1.2e-3, "not resolved: σ = {se}");
                assert!(
                    (share - p).abs() <= Z * se,
                    "a = {a}, Λ = {lambda}: N = {N}, escape share {share}, a/(a + Λ) = {p}, σ = {se}, z = {Z}"
                );
                let hits = (N - escaped) as f64;
                let expected = hits / BINS as f64;
                let chi2: f64 = counts.iter().map(|&c| (c as f64 - expected).powi(2) / expected).sum();
                assert!(
                    chi2 <= CHI2_CRITICAL,
                    "a = {a}, Λ = {lambda}: χ² = {chi2} over {hits} hits, {counts:?}"
                );
            }
        }
    }

    /// The law behind [`Depth::two_sided`]: the first hit's C¹ drawn as max(C, W)
    /// ([`first_hit_two_sided`]) has the CDF c^a, a = 1 + Λ(ωi), as Algorithm 1 from above
    /// the surface draws it: N = 200 000 draws per Λ(ωi) (0, the listing's 0.018, 0.3 and
    /// [`TWO_SIDED_UP_TO`]), χ² of C¹^a on 20 equal bins at α = 1e-4 each (family-wise 4e-4).
    /// A point drawn as C¹ itself is held as 1 − C¹ (exact) on the other side, and the
    /// logarithms of both are within 0.51 f32 ulp of ln C¹ and ln(1 − C¹) in f64; a point
    /// drawn as ln C¹ is flipped by [`flip_ln_c1`].
    #[test]
    fn two_sided_first_hit_law_is_algorithm_1s() {
        const N: usize = 200_000;
        const BINS: usize = 20;
        // χ² with 19 degrees of freedom at 1 − 1e-4
        const CHI2_CRITICAL: f64 = 50.8;
        let surface = Microsurface::new(
            UniformHeight,
            Ggx::isotropic(0.5).expect("valid roughness"),
            Dielectric::new(1.5).expect("valid index"),
        );
        let mut rng = Pcg64Mcg::seed_from_u64(83);
        for lambda_i in [0.0f32, 0.018, 0.3, TWO_SIDED_UP_TO] {
            let a = 1.0 + f64::from(lambda_i);
            let (mut counts, mut uniform_wins) = ([0usize; BINS], 0usize);
            for _ in 0..N {
                let (u1, u2) = uniform_pair(&mut rng);
                let depth = Depth::two_sided(first_hit_two_sided(lambda_i, u1, u2));
                let ln_c1 = depth.ln_c1();
                assert!(ln_c1 <= -MIN_HIT_DEPTH, "Λ(ωi) = {lambda_i}: ln C¹ = {ln_c1}");
                let vertex = Vertex { depth, lambda: -1.0 - lambda_i, incident_area: None };
                let other = <Depth as Heights>::other_side(&vertex, &surface, &mut rng);
                if depth.0 > 0.0 {
                    uniform_wins += 1;
                    let c1 = f64::from(depth.0);
                    assert_eq!(f64::from(other.0), 1.0 - c1, "the other side holds 1 − C¹ exactly");
                    let ln_other = other.ln_c1();
                    assert!(
                        ulps(-ln_c1, -c1.ln()) <= 0.51 && ulps(-ln_other, -(1.0 - c1).ln()) <= 0.51,
                        "C¹ = {c1}: ln C¹ {ln_c1}, ln(1 − C¹) {ln_other}"
                    );
                } else {
                    assert_eq!(other.0, flip_ln_c1(ln_c1));
                }
                let v = (a * f64::from(ln_c1)).exp();
                counts[((v * BINS as f64) as usize).min(BINS - 1)] += 1;
            }
            let expected = N as f64 / BINS as f64;
            let chi2: f64 = counts.iter().map(|&c| (c as f64 - expected).powi(2) / expected).sum();
            assert!(chi2 <= CHI2_CRITICAL, "Λ(ωi) = {lambda_i}: χ² = {chi2}, {counts:?}");
            // the uniform is the maximum with probability 1/a
            assert!(uniform_wins > N / 2, "Λ(ωi) = {lambda_i}: the uniform won {uniform_wins} of {N}");
        }
    }

    /// The escape bound of a point held as C¹ ([`escapes_from_held_c1`]) decides only
    /// escapes, and those of [`next_ln_c1`]: 10⁶ draws of C¹ (multiples of 2⁻²⁴), u and
    /// Λ ∈ {0, 0.008, 0.3, 4}, with both outcomes of the bound seen often.
    #[test]
    fn held_c1_escape_bound_is_next_ln_c1s() {
        let mut rng = Pcg64Mcg::seed_from_u64(89);
        let (mut decided, mut left) = (0usize, 0usize);
        for k in 0..1_000_000 {
            let lambda = [0.0f32, 0.008, 0.3, 4.0][k % 4];
            let c1 = (1.0 - uniform(&mut rng)).min(1.0 - 1.0 / 16_777_216.0);
            let u = uniform(&mut rng);
            if escapes_from_held_c1(lambda, c1, u) {
                decided += 1;
                let ln_c1 = Depth::two_sided(c1).ln_c1();
                assert_eq!(next_ln_c1(0.5, lambda, ln_c1, u), None, "Λ = {lambda}, C¹ = {c1}, u = {u}");
            } else {
                left += 1;
            }
        }
        assert!(decided > 300_000 && left > 100_000, "decided {decided}, left {left}");
    }

    /// The f32 ulps between `a` and the exact `b`, relative to b.
    fn ulps(a: f32, b: f64) -> f64 {
        (f64::from(a) - b).abs() / (b * f64::from(f32::EPSILON))
    }

    /// The largest relative error of Λ(ωr)·cos θr against the f64 projected area of ωi = −ωr
    /// over θi and α (the anisotropic case through the azimuth), for rays going down
    /// (`up` = false: ωi facing up) or up (ωi backfacing), and the number of cases compared
    /// (those with a normal f32 area; `None` is required where the f64 area is not a normal
    /// f32).
    fn worst<S: MicrosurfaceSlope>(slope: S, up: bool) -> (f64, usize) {
        let (mut worst, mut compared) = (0.0f64, 0);
        for cos in [1.0f32, 0.99, 0.9, 0.5, 0.1, 1e-2, 1e-3, 1e-6] {
            for phi in [0.0f32, 0.7, 1.6] {
                let sin = (1.0 - cos * cos).sqrt();
                let wi = Vec3::new(sin * phi.cos(), sin * phi.sin(), if up { -cos } else { cos });
                let wr = -wi;
                let exact = slope.projected_area64(wi);
                match incident_area(wr.z, slope.lambda_unchecked(wr)) {
                    Some(area) => {
                        worst = worst.max(ulps(area, exact));
                        compared += 1;
                    }
                    None => assert!(
                        up && exact < f64::from(f32::MIN_POSITIVE),
                        "no area for ωi = {wi}, where it is {exact:e}"
                    ),
                }
            }
        }
        (worst, compared)
    }

    /// A(ωi) = Λ(ωr)·cos θr for the ray ωr = −ωi (Λ(ωr) = −1 − Λ(ωi)): within 4 f32 ulps of the
    /// projected area in f64 (Λ to 2 ulps in the crate's f32 forms, the product one rounding
    /// more), for GGX and Beckmann from the zenith to 1e-6 from the horizon, for rays going
    /// down (ωi facing up) and going up (ωi backfacing, A(ωi) = Λ(−ωi)|cos θi|, down to where
    /// it leaves the normal f32 range: Beckmann's Λ(−ωi) ≈ e^{−a²} underflows at low α).
    #[test]
    fn incident_area_is_the_projected_area_of_the_incident_direction() {
        let mut backfacing = 0;
        for alpha in [0.01f32, 0.1, 0.3, 1.0, 2.5] {
            for up in [false, true] {
                let (g, gn) = worst(Ggx::new(alpha, 0.6 * alpha).expect("valid roughness"), up);
                let (b, bn) = worst(Beckmann::new(alpha, 0.6 * alpha).expect("valid roughness"), up);
                assert!(g <= 4.0 && b <= 4.0, "α = {alpha}, up = {up}: GGX {g} ulps, Beckmann {b} ulps");
                // straight up (cos θ = 1) Λ = 0: no area (A(−z) = 0)
                assert!(
                    gn == if up { 21 } else { 24 } && (up || bn == 24),
                    "α = {alpha}, up = {up}: {gn}, {bn} compared"
                );
                if up {
                    backfacing += bn;
                }
            }
        }
        assert!(backfacing > 80, "only {backfacing} backfacing Beckmann areas compared");
    }

    /// No area for a horizontal ray, a ray straight up (Λ = 0), a Λ or a product outside the
    /// normal f32 range, or Λ saturated.
    #[test]
    fn incident_area_is_none_where_it_is_not_the_area() {
        assert_eq!(incident_area(0.3, 0.2), Some(0.3 * 0.2));
        assert_eq!(incident_area(1.0, 0.0), None);
        assert_eq!(incident_area(0.5, 1e-45), None);
        assert_eq!(incident_area(1e-20, 1e-20), None);
        assert_eq!(incident_area(0.0, f32::MAX), None);
        assert_eq!(incident_area(1e-30, f32::MAX), None);
        assert_eq!(incident_area(0.0, -f32::MAX), None);
        assert_eq!(incident_area(-1e-30, -f32::MAX), None);
        assert_eq!(incident_area(-1e-30, f32::NEG_INFINITY), None);
        assert_eq!(incident_area(-0.5, f32::NAN), None);
        assert_eq!(incident_area(-0.5, -1.5), Some(0.75));
    }
    /// The direction at polar angle θ (radians) in the xz-plane.
    fn polar(theta: f32) -> Vec3 {
        Vec3::new(theta.sin(), 0.0, theta.cos())
    }

    /// Smooth Beckmann seen from below at θi = 120°, where Λ(−ωi) ≈ e^{−a²} underflows f32
    /// (α = 0.05: a = |cot θi|/αᵢ = 11.5) and f64 (α = 0.02: a = 28.9): every path of a perfect
    /// mirror leaves upwards with weight 1 (energy is conserved; GGX as the control). Before,
    /// the f32 walk found Λ(−ωi) = 0 and lost every path of both Beckmann surfaces.
    #[test]
    fn sample_from_below_conserves_energy_at_every_roughness() {
        fn check<S: MicrosurfaceSlope>(label: &str, slope: S) {
            let surface = Microsurface::new(UniformHeight, slope, Conductor::perfect());
            let wi = polar(120f32.to_radians());
            let mut rng = Pcg64Mcg::seed_from_u64(17);
            for k in 0..2000 {
                let s = surface.sample_from_below(wi, &mut rng);
                let s = s.unwrap_or_else(|| panic!("{label}: path {k} lost"));
                assert!(s.weight == Vec3::ONE && s.wo.z > 0.0, "{label}: {s:?}");
            }
        }
        for alpha in [0.05f32, 0.02] {
            check(&format!("Beckmann α = {alpha}"), Beckmann::isotropic(alpha).expect("valid roughness"));
            check(&format!("GGX α = {alpha}"), Ggx::isotropic(alpha).expect("valid roughness"));
        }
    }

    /// The order-1 term of the walk from below is the full-spherical single scattering
    /// F D G2/(4|cos θi|), G2 = 1/(Λ(−ωi) + Λ(ωo)) (Wang et al. 2022, eq. 17), which
    /// [`Microsurface::eval_single_scattering`] evaluates in closed form: the walk's mean over
    /// N = 20 000 evaluations agrees within z σ̂/√N, z = 3.76 (Šidák, family-wise 1e-3 over the
    /// 6 comparisons), each resolving 5 % of the value. Smooth Beckmann at θi = 120° as in
    /// `sample_from_below_conserves_energy_at_every_roughness`; ωo drawn from the phase
    /// function. Before, the walk returned 0 there.
    #[test]
    fn eval_from_below_first_order_is_single_scattering_at_every_roughness() {
        const N: usize = 20_000;
        const Z: f64 = 3.76;
        let wi = polar(120f32.to_radians());
        let first = ScatteringOrder::only(1).expect("order 1");
        for alpha in [0.05f32, 0.02] {
            let slope = Beckmann::isotropic(alpha).expect("valid roughness");
            let surface = Microsurface::new(UniformHeight, slope, Conductor::perfect());
            let mut rng = Pcg64Mcg::seed_from_u64(29);
            for _ in 0..3 {
                let wo = surface.sample_phase(wi, &mut rng).wo;
                let expected = f64::from(surface.eval_single_scattering(wi, wo, &mut rng).x);
                let (mut sum, mut sum_sq) = (0.0f64, 0.0f64);
                for _ in 0..N {
                    let x = f64::from(surface.eval_from_below(wi, wo, first, &mut rng).x);
                    (sum, sum_sq) = (sum + x, sum_sq + x * x);
                }
                let mean = sum / N as f64;
                let sd = (sum_sq / N as f64 - mean * mean).max(0.0).sqrt();
                let se = sd / (N as f64).sqrt();
                let report = format!(
                    "α = {alpha}, ωo = {wo}: N = {N}, mean {mean}, σ̂ {sd}, z = {Z}, expected {expected}"
                );
                assert!(expected > 0.0 && se <= 0.05 * expected, "not resolved: {report}");
                assert!((mean - expected).abs() <= Z * se, "{report}");
            }
        }
    }
}
