//! What an opaque BSDF answers for views from below its shading plane.

use glam::Vec3;

/// What an opaque BSDF ([`MicrofacetBsdf`](crate::MicrofacetBsdf) of a conductor or of
/// diffuse facets, [`ClassicBrdf`](crate::ClassicBrdf)) answers for a view from below its
/// shading plane, wo.z < 0 in the shading frame. Dielectrics ignore it: a view from below is a
/// view from inside.
///
/// A BSDF sees only the shading frame. Under a normal map a view can lie below the shading
/// plane and still above the geometric surface: the light then reaches the microsurface from
/// below its mean plane, and [`Sidedness::BackfacingLobe`] is the physically based answer.
/// A view from below the *geometric* surface is the renderer's to detect, with its geometric
/// normal ng (`wo_world · ng < 0`): for two-sided geometry it flips both normals towards the
/// viewer before building the [`ShadingFrame`](crate::ShadingFrame) (pbrt's `FaceForward`),
/// for a black backface it skips the BSDF. The views the BSDF then sees from below its shading
/// plane are those of the normal map, and this choice says what they give.
///
/// # Examples
///
/// ```
/// use microsurface::glam::{Vec2, Vec3};
/// use microsurface::{Bsdf, ComplexIor, Conductor, Ggx, MicrofacetBsdf, Sidedness, Technique};
///
/// let gold = MicrofacetBsdf::new(Ggx::isotropic(0.3)?, Conductor::new(ComplexIor::GOLD))?
///     .with_technique(Technique::SingleScattering);
/// let below = Vec3::new(0.6, 0.0, -0.8); // a view under the shading plane
/// let mirrored = Vec3::new(0.6, 0.0, 0.8);
/// let wi = Vec3::new(-0.3, 0.1, 0.9).normalize();
/// // the default: the backfacing lobe of the microsurface (Tokuyoshi's full-spherical masking)
/// assert!(gold.eval(below, wi).f.x > 0.0);
/// // two-sided: the view mirrored into the upper hemisphere (and the light with it)
/// let two_sided = gold.with_sidedness(Sidedness::TwoSided);
/// let flip = |w: Vec3| Vec3::new(w.x, w.y, -w.z);
/// assert_eq!(two_sided.eval(below, flip(wi)).f, gold.eval(mirrored, wi).f);
/// // black: nothing from below
/// let black = gold.with_sidedness(Sidedness::Black);
/// assert_eq!(black.eval(below, wi).f, Vec3::ZERO);
/// assert!(black.sample(below, 0.5, Vec2::splat(0.5)).is_none());
/// # Ok::<(), microsurface::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Sidedness {
    /// The microsurface's own answer (the default of [`MicrofacetBsdf`](crate::MicrofacetBsdf)):
    /// the visible facets of a view from below, with the full-spherical masking
    /// 1/|1 + Λ(ωo)| (Tokuyoshi; Wang et al. 2022, eq. 10). [`ClassicBrdf`](crate::ClassicBrdf)
    /// has no backfacing lobe (its separable G1 is 0 below the plane) and gives nothing.
    #[default]
    BackfacingLobe,
    /// A two-sided material: a view from below is mirrored into the upper hemisphere, and so
    /// is the light: f(wo, wi) = f(w̄o, w̄i) with w̄ = (x, y, −z), and samples are mirrored back.
    TwoSided,
    /// Nothing below the shading plane: `eval` and `pdf` 0, `sample` `None` for wo.z < 0.
    Black,
}

/// How a BSDF answers one view under its [`Sidedness`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Facing {
    /// The directions as given.
    AsGiven,
    /// The directions mirrored through the shading plane (and the sample mirrored back).
    Mirrored,
    /// Nothing.
    Nothing,
}

impl Sidedness {
    /// How the view `wo` is answered: as given above the shading plane (and on it) and under
    /// [`Sidedness::BackfacingLobe`].
    #[inline(always)]
    pub(crate) fn facing(self, wo: Vec3) -> Facing {
        // the default first: one test of the field for every view
        if self == Sidedness::BackfacingLobe || wo.z >= 0.0 || wo.z.is_nan() {
            Facing::AsGiven
        } else if self == Sidedness::TwoSided {
            Facing::Mirrored
        } else {
            Facing::Nothing
        }
    }
}

/// The mirror image (x, y, −z) of a direction through the shading plane.
#[inline(always)]
pub(crate) fn mirror_z(w: Vec3) -> Vec3 {
    Vec3::new(w.x, w.y, -w.z)
}
