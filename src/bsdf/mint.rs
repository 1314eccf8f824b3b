//! Interop through the `mint` vector types (feature `mint`).

use super::{Bsdf, SampleFlags};
use glam::{Vec2, Vec3};
use mint::{Vector2, Vector3};

/// A sample of [`MintBsdf::sample_mint`]: a [`BsdfSample`](crate::BsdfSample) with its
/// vectors as `mint` types.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MintSample {
    /// The sampled direction towards the light (unit, shading frame).
    pub wi: Vector3<f32>,
    /// f·|cos θi|/pdf per channel.
    pub weight: Vector3<f32>,
    /// The density of `wi` (see [`BsdfSample::pdf`](crate::BsdfSample::pdf)).
    pub pdf: f32,
    /// The relative index of a transmission (see [`BsdfSample::eta`](crate::BsdfSample::eta)).
    pub eta: f32,
    /// The kind of event.
    pub flags: SampleFlags,
}

/// The [`Bsdf`] calls with `mint` vectors in and out (feature `mint`), for a renderer whose
/// vectors are not this crate's `glam` version: glam (any version with its `mint` feature),
/// nalgebra and cgmath convert their vectors to and from `mint::Vector3<f32>`, so their
/// values go in as they are and come out with one `.into()`. Implemented for every [`Bsdf`]
/// (and `dyn Bsdf`); the methods are those of the trait, with the same inputs policy.
///
/// With the feature on, this crate's `glam` types convert to and from the `mint` types too
/// (`glam`'s `mint-05` feature): `ShadingFrame::from_normal(n.into())` takes a `mint` normal.
///
/// # Examples
///
/// A renderer's own vector type (here a plain struct; a nalgebra or cgmath vector converts the
/// same way):
///
/// ```
/// use microsurface::{ComplexIor, Conductor, Ggx, MicrofacetBsdf, MintBsdf, Technique};
///
/// #[derive(Debug, Clone, Copy)]
/// struct V3 { x: f32, y: f32, z: f32 }
/// impl From<V3> for mint::Vector3<f32> {
///     fn from(v: V3) -> Self { mint::Vector3 { x: v.x, y: v.y, z: v.z } }
/// }
/// impl From<mint::Vector3<f32>> for V3 {
///     fn from(v: mint::Vector3<f32>) -> Self { V3 { x: v.x, y: v.y, z: v.z } }
/// }
///
/// let gold = MicrofacetBsdf::new(Ggx::isotropic(0.3)?, Conductor::new(ComplexIor::GOLD))?
///     .with_technique(Technique::SingleScattering);
/// let wo = V3 { x: 0.6, y: 0.0, z: 0.8 };
/// let s = gold.sample_mint(wo, 0.5, [0.3, 0.7], 0).expect("gold reflects");
/// let wi: V3 = s.wi.into();
/// let (f, pdf) = gold.eval_with_pdf_mint(wo, wi, 0);
/// let f: V3 = f.into();
/// assert!(f.x > 0.0 && pdf > 0.0);
/// // single scattering is exact: the weight is f·cos θi/pdf
/// assert!((f.x * wi.z / pdf - s.weight.x).abs() < 1e-4 * s.weight.x);
/// # Ok::<(), microsurface::Error>(())
/// ```
pub trait MintBsdf {
    /// [`Bsdf::eval_keyed`]'s f.
    fn eval_mint(&self, wo: impl Into<Vector3<f32>>, wi: impl Into<Vector3<f32>>, key: u64) -> Vector3<f32>;

    /// [`Bsdf::pdf`].
    fn pdf_mint(&self, wo: impl Into<Vector3<f32>>, wi: impl Into<Vector3<f32>>) -> f32;

    /// [`Bsdf::eval_with_pdf_keyed`]: f and the density.
    fn eval_with_pdf_mint(
        &self,
        wo: impl Into<Vector3<f32>>,
        wi: impl Into<Vector3<f32>>,
        key: u64,
    ) -> (Vector3<f32>, f32);

    /// [`Bsdf::sample_keyed`].
    fn sample_mint(
        &self,
        wo: impl Into<Vector3<f32>>,
        uc: f32,
        u: impl Into<Vector2<f32>>,
        key: u64,
    ) -> Option<MintSample>;
}

impl<B: Bsdf + ?Sized> MintBsdf for B {
    #[inline]
    fn eval_mint(&self, wo: impl Into<Vector3<f32>>, wi: impl Into<Vector3<f32>>, key: u64) -> Vector3<f32> {
        self.eval_keyed(vec3(wo), vec3(wi), key).f.into()
    }

    #[inline]
    fn pdf_mint(&self, wo: impl Into<Vector3<f32>>, wi: impl Into<Vector3<f32>>) -> f32 {
        self.pdf(vec3(wo), vec3(wi))
    }

    #[inline]
    fn eval_with_pdf_mint(
        &self,
        wo: impl Into<Vector3<f32>>,
        wi: impl Into<Vector3<f32>>,
        key: u64,
    ) -> (Vector3<f32>, f32) {
        let (v, pdf) = self.eval_with_pdf_keyed(vec3(wo), vec3(wi), key);
        (v.f.into(), pdf)
    }

    #[inline]
    fn sample_mint(
        &self,
        wo: impl Into<Vector3<f32>>,
        uc: f32,
        u: impl Into<Vector2<f32>>,
        key: u64,
    ) -> Option<MintSample> {
        let s = self.sample_keyed(vec3(wo), uc, Vec2::from(u.into()), key)?;
        Some(MintSample { wi: s.wi.into(), weight: s.weight.into(), pdf: s.pdf, eta: s.eta, flags: s.flags })
    }
}

/// A `mint` vector as this crate's `glam` vector.
#[inline(always)]
fn vec3(v: impl Into<Vector3<f32>>) -> Vec3 {
    Vec3::from(v.into())
}
