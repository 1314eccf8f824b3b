//! The microsurface: geometry (heights and slopes) plus a material, with the random-walk
//! multiple-scattering BSDF (Heitz et al. 2016, supplement §3).

mod geometry;
mod walk;
mod walk_lanes;

pub use geometry::{HeightSample, MicrosurfaceGeometry};
#[cfg(feature = "invariance")]
pub(crate) use walk::incident_area;
pub use walk::{MAX_BOUNCES, ScatteringOrder, WalkSample};
pub use walk_lanes::WalkOutputs;

use crate::contract::is_direction;
use crate::height::MicrosurfaceHeight;
use crate::material::{Interaction, Material, PhaseSample, Side};
use crate::single_scattering::SingleScattering;
use crate::slope::MicrosurfaceSlope;
use glam::Vec3;
use rand::Rng;

/// A microsurface with height distribution `H`, slope distribution `S` and material `M`
/// (`Microsurface` in Heitz et al. 2016, supplement §3.1), statically dispatched.
///
/// Directions are unit vectors in the local frame (z up, the macrosurface normal), both
/// pointing away from the surface: `wi` towards the light, `wo` towards the viewer.
/// Evaluations return the BSDF **times |cos θo|**, per RGB channel, like the supplement's
/// `eval()`.
///
/// The walks run in C¹ space: a height enters the Smith model only through its CDF value
/// C¹(h) (supplement §1.1), so they carry ln C¹ instead of h, and their results are the same
/// for every height distribution (bit for bit, given the same random numbers). `H` serves the
/// height-space queries of [`MicrosurfaceGeometry`]; `tests/walk/random_walk.rs` checks the walks against
/// the supplement's height-space algorithm run on [`UniformHeight`](crate::research::UniformHeight) and
/// [`GaussianHeight`](crate::research::GaussianHeight).
///
/// # Examples
/// ```
/// use microsurface::{Dielectric, Ggx};
/// use microsurface::research::{Microsurface, ScatteringOrder, UniformHeight};
/// use microsurface::glam::Vec3;
/// use microsurface::rand::SeedableRng;
///
/// let glass = Microsurface::new(UniformHeight, Ggx::isotropic(0.4)?, Dielectric::new(1.5)?);
/// let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(1);
/// let wi = Vec3::new(0.5, 0.0, 0.866);
/// // a walk sample leaves above (reflection) or below (transmission) the macrosurface
/// let s = glass.sample(wi, &mut rng).expect("light entering glass leaves it");
/// assert!(s.wo.is_normalized() && s.bounces >= 1);
/// // f·|cos θo| of the second order alone, for the transmitted direction straight down
/// let second = ScatteringOrder::only(2).expect("orders start at 1");
/// let f_cos = glass.eval(wi, -Vec3::Z, second, &mut rng);
/// assert!(f_cos.is_finite() && f_cos.min_element() >= 0.0);
/// # Ok::<(), microsurface::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Microsurface<H, S, M> {
    geometry: MicrosurfaceGeometry<H, S>,
    material: M,
}

impl<H: MicrosurfaceHeight, S: MicrosurfaceSlope, M: Material> Microsurface<H, S, M> {
    /// Combines a height distribution, a slope distribution and a material.
    pub fn new(height: H, slope: S, material: M) -> Self {
        Self { geometry: MicrosurfaceGeometry::new(height, slope), material }
    }

    /// The material-independent geometry (masking, height sampling).
    #[inline]
    pub fn geometry(&self) -> &MicrosurfaceGeometry<H, S> {
        &self.geometry
    }

    /// The slope distribution.
    #[inline]
    pub fn slope(&self) -> &S {
        self.geometry.slope()
    }

    /// The material.
    #[inline]
    pub fn material(&self) -> &M {
        &self.material
    }

    /// The phase function p(ωi, ωo) (times the material's weight) of a ray arriving from
    /// outside, summed over both sides of the interface for a dielectric (reflection and
    /// transmission), as the supplement's wrapper does. Integrates to 1 over the sphere for
    /// non-absorptive materials (test 4.3.1). Stochastic for the diffuse material.
    ///
    /// Invalid input ([policy](crate#invalid-input)): a `wi` or `wo` that is not a unit
    /// direction gives 0 (a debug assertion in debug builds).
    #[inline]
    pub fn eval_phase(&self, wi: Vec3, wo: Vec3, rng: &mut impl Rng) -> Vec3 {
        require!(is_direction(wi) && is_direction(wo), Vec3::ZERO; wi, wo);
        let slope = self.geometry.slope();
        let reflected = self.material.eval_phase(slope, &Interaction::reflection(wi, wo), rng);
        if M::TRANSMITS {
            let transmitted = Interaction::new(wi, wo, Side::Outside, Side::Inside);
            reflected + self.material.eval_phase(slope, &transmitted, rng)
        } else {
            reflected
        }
    }

    /// Samples the phase function p(ωi, ·) of a ray arriving from outside.
    ///
    /// Invalid input ([policy](crate#invalid-input)): a `wi` that is not a unit direction gives
    /// a sample with a NaN `wo` and a zero weight (a debug assertion in debug builds).
    #[inline]
    pub fn sample_phase(&self, wi: Vec3, rng: &mut impl Rng) -> PhaseSample {
        require!(is_direction(wi), PhaseSample { wo: Vec3::NAN, weight: Vec3::ZERO, side: Side::Outside }; wi);
        self.material.sample_phase(self.geometry.slope(), wi, Side::Outside, rng)
    }

    /// The single-scattering BSDF times |cos θo| (what `eval` with
    /// [`ScatteringOrder::Only`]`(1)` estimates). Zero for ωi or ωo on the horizon and for an
    /// opaque material's ωo below it. A dielectric lit from below is evaluated from inside; an
    /// opaque material lit from below the macrosurface (a backfacing view) has the
    /// full-spherical height-correlated masking G2 = 1/(Λ(−ωi) + Λ(ωo)) (Wang et al. 2022,
    /// eq. 17), the order-1 term of [`Microsurface::eval_from_below`].
    ///
    /// Invalid input ([policy](crate#invalid-input)): a `wi` or `wo` that is not a unit
    /// direction gives 0 (a debug assertion in debug builds).
    #[inline]
    pub fn eval_single_scattering(&self, wi: Vec3, wo: Vec3, rng: &mut impl Rng) -> Vec3 {
        require!(is_direction(wi) && is_direction(wo), Vec3::ZERO; wi, wo);
        if !M::TRANSMITS && (wi.z <= 0.0 || wo.z <= 0.0) {
            if wi.z < 0.0 && wo.z > 0.0 {
                return SingleScattering::new(*self.slope(), self.material).eval_unchecked(wi, wo, rng);
            }
            return Vec3::ZERO;
        }
        self.material.eval_single_scattering(self.geometry.slope(), wi, wo, rng)
    }
}
