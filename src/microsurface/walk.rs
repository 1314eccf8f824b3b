//! The random walk on the microsurface: stochastic evaluation and sampling of the
//! multiple-scattering BSDF (Heitz et al. 2016, supplement §3.1 Algorithms 2–3 and §3.4).

use super::Microsurface;
use super::geometry::{escape_probability, next_c1};
use crate::height::MicrosurfaceHeight;
use crate::material::Material;
use crate::rng::uniform;
use crate::slope::MicrosurfaceSlope;
use core::num::NonZeroU32;
use glam::Vec3;
use rand::Rng;

/// The hard cap on the number of bounces of one walk.
///
/// Walks end with probability one; the cap only guards against pathological inputs. A walk
/// that reaches it is dropped (its energy is lost): `tests/walk_cap.rs` measures that this
/// removes less than 1e-4 of the albedo for α ≤ 2.
pub const MAX_BOUNCES: u32 = 1024;

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
    /// if the material cannot be lit from there.
    #[inline(always)]
    fn starting_side(wi: Vec3) -> Option<bool> {
        if wi.z > 0.0 {
            Some(true)
        } else if M::TRANSMITS && wi.z < 0.0 {
            Some(false)
        } else {
            None
        }
    }

    /// Evaluates the multiple-scattering BSDF times |cos θo| by a random walk with next-event
    /// estimation (supplement §3.1 Algorithm 2; §3.4 for the dielectric). Stochastic and
    /// unbiased: average several calls.
    ///
    /// `order` selects all bounces, exactly the n-th, or the first n. Returns 0 when ωi or ωo
    /// lies on the horizon, and for opaque materials when either is below it. A dielectric
    /// lit from inside (ωi.z < 0) is evaluated as the flipped configuration, η ↦ 1/η.
    pub fn eval(&self, wi: Vec3, wo: Vec3, order: ScatteringOrder, rng: &mut impl Rng) -> Vec3 {
        let Some(mut outside) = Self::starting_side(wi) else { return Vec3::ZERO };
        if wo.z == 0.0 || (!M::TRANSMITS && wo.z < 0.0) {
            return Vec3::ZERO;
        }
        let (height, slope) = (self.geometry.height(), self.geometry.slope());
        let wo_outside = wo.z > 0.0;
        // Λ of ωo seen from its own side, constant along the walk
        let lambda_o = slope.lambda(if wo_outside { wo } else { -wo });
        let last = order.last();

        let mut wr = -wi;
        let mut h = if outside { f32::INFINITY } else { f32::NEG_INFINITY };
        let mut throughput = Vec3::ONE;
        let mut sum = Vec3::ZERO;
        for bounce in 1..=last {
            let Some(next_h) = self.next_height(wr, h, outside, rng) else { break };
            h = next_h;
            if order.includes(bounce) {
                let phase = self.material.eval_phase(slope, -wr, wo, outside, wo_outside, rng);
                let shadowing = escape_probability(height.c1(if wo_outside { h } else { -h }), lambda_o);
                if shadowing > 0.0 {
                    sum += throughput * phase * shadowing;
                }
            }
            if bounce == last {
                break;
            }
            let s = self.material.sample_phase(slope, -wr, outside, rng);
            wr = s.wo;
            outside = s.outside;
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
    /// `None` if ωi cannot light the material (on the horizon, or below it for an opaque
    /// material), if the path was fully absorbed, or if it reached [`MAX_BOUNCES`].
    pub fn sample(&self, wi: Vec3, rng: &mut impl Rng) -> Option<WalkSample> {
        let mut outside = Self::starting_side(wi)?;
        let slope = self.geometry.slope();
        let mut wr = -wi;
        let mut h = if outside { f32::INFINITY } else { f32::NEG_INFINITY };
        let mut weight = Vec3::ONE;
        for bounces in 0..MAX_BOUNCES {
            let Some(next_h) = self.next_height(wr, h, outside, rng) else {
                return Some(WalkSample { wo: wr, weight, bounces });
            };
            h = next_h;
            let s = self.material.sample_phase(slope, -wr, outside, rng);
            wr = s.wo;
            outside = s.outside;
            weight *= s.weight;
            if weight == Vec3::ZERO {
                return None;
            }
        }
        None
    }

    /// The height of the next intersection of the ray (ωr from height h on side `outside`),
    /// or `None` if it escapes. Inside a dielectric the configuration is flipped vertically,
    /// h ↦ −h (supplement §3.4; the height distributions are symmetric).
    #[inline(always)]
    fn next_height(&self, wr: Vec3, h: f32, outside: bool, rng: &mut impl Rng) -> Option<f32> {
        let (height, slope) = (self.geometry.height(), self.geometry.slope());
        let (w, h_local) = if outside { (wr, h) } else { (-wr, -h) };
        let u = uniform(rng);
        let h_next = if w.z == 0.0 {
            // horizontal: hits at its own height (escapes if it starts above the surface)
            if h_local == f32::INFINITY {
                return None;
            }
            h_local
        } else {
            height.inv_c1(next_c1(w.z, slope.lambda(w), height.c1(h_local), u)?)
        };
        Some(if outside { h_next } else { -h_next })
    }
}
