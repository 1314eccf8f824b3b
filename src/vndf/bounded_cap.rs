//! GGX visible normals for reflections by the bounded spherical cap (Eto and Tokuyoshi 2023,
//! “Bounded VNDF Sampling for Smith–GGX Reflections”, SIGGRAPH Asia 2023 Technical
//! Communications; Tokuyoshi and Eto 2024, “Bounded VNDF Sampling for the Smith–GGX BRDF”,
//! PACMCGIT 7(1)), with its exact density, on the whole sphere of incident directions.
//!
//! # The bound
//!
//! The spherical-cap sampler (Dupuy and Benyoub 2023) draws c uniformly on the cap
//! c.z ≥ −v̂.z of the unit sphere, v̂ the view stretched to α = 1 (v = (αx ωi.x, αy ωi.y, ωi.z),
//! L = |v|, v̂ = v/L), and returns the unstretched normalize(v̂ + c). At α = 1, c is the
//! reflection of v̂ about the normal, so the normals of c.z < 0 all reflect below the horizon.
//! For any α, reflection ωo = 2(ωi·ωm)ωm − ωi leaves above the horizon only for normals whose
//! c.z ≥ −b, with (derived here from the boundary ωo.z = 0: there ωm ∝ ωi + h for a horizontal
//! unit h, and with n = (ωm.x/α, ωm.y/α, ωm.z), c = 2(v̂·n̂)n̂ − v̂,
//! c.z/v̂.z = 2α²y/(2y − (1 − α²) cos²θi) − 1 with y = 1 + sin θi (ĥ·ωi,xy/sin θi), monotone
//! in y, extreme at h along ±ωi,xy):
//!
//! b = k v̂.z,  k = (1 − a²) σ₊ / (σ₊ + a² σ₋),  σ± = 1 ± sgn(1 − a) sin θi      (eq. 5)
//!
//! for an isotropic roughness a = α. The paper states it for a ≤ 1 (σ₊ = 1 + sin θi) and, for
//! anisotropic GGX, takes the smaller roughness, a = min(αx, αy) (eq. 6), with a clamped to 1
//! (k = 0 above it). The normals with c.z < −b only make rays below the horizon, which a
//! reflection off an opaque surface rejects, so sampling c.z uniformly on [−b, 1] instead of
//! [−v̂.z, 1] loses no valid reflection and raises the density of the kept ones by
//! (1 + v̂.z)/(1 + b). The density of a reflected direction above the horizon is then
//!
//! p(ωo) = D(ωh) / (2 (k ωi.z + L)) = D(ωh) / (4 A_b),  A_b = (L + k ωi.z)/2       (eq. 8)
//!
//! (eq. 8 of the communication times the Jacobian 1/(4 ωi·ωh)), where the spherical cap's
//! is D(ωh)/(4 A), A = (L + ωi.z)/2 the projected area: the bounded cap is the spherical cap
//! with A replaced by A_b ≤ A. The density of the normals themselves is
//! D_b(ωm) = ⟨ωi, ωm⟩ D(ωm)/A_b on the normals whose c.z ≥ −b, 0 elsewhere.
//!
//! # What the crate adds
//!
//! * Roughness above 1: the same derivation with sgn(1 − a) = −1 gives k < 0 (the bound rises
//!   above the equator of the cap, c.z ≥ |b|), used here instead of the paper's clamp to
//!   k = 0; with a = min(αx, αy) for anisotropic GGX as in eq. 6. The bound is checked by brute
//!   force over α ∈ [1e-4, 10], anisotropy to 1e4 and views to 1e-6 rad from grazing
//!   (`tests/vndf/bounded.rs`: no normal below the bound reflects above the horizon).
//! * Views on or below the horizon (ωi.z ≤ 0, shading normals that face away): the paper's
//!   bound is for ωi.z > 0 only and the crate, like its fallback (eq. 7), samples the whole
//!   visible cap there: the density is the spherical cap's, exact on the whole sphere.
//! * k is computed from the direction of ωi (sin θi = |ωi,xy|/|ωi|, the inputs are unit only
//!   to 1e-3), as κ = 1 + k, without cancellation: with p = 1 + sin θ and w = 1 − sin θ,
//!   κ = 2(1 + (1 − a²) sin θ)/(p + a² w) for a ≤ 1 and 2(w + a² sin θ)/(w + a² p) above it,
//!   then raised by a relative 2⁻²⁰ (16 ulps, above its rounding error of a few ulps): a
//!   larger k keeps slightly more normals, which is always valid, while a smaller one would
//!   drop valid reflections. a is clamped to 1e3 (a larger k again). κ costs one square root
//!   and one division per call (|ωi| from (1 + |ωi|²)/2, exact to 1.3e-7 for the inputs the
//!   crate accepts).
//! * The cap's height and A_b are formed without cancellation for k < 0
//!   ([`CapBound`]'s `top`).
//!
//! Not covered: refraction. A dielectric's visible normal decides reflection and refraction
//! after it is drawn, and the normals the bound removes refract validly, so the crate's
//! dielectrics keep the spherical cap (see [`Dielectric`](crate::Dielectric)). Beckmann and
//! the other slope distributions keep their samplers (the bound is GGX's closed form).

use super::VisibleNormalSampler;
use crate::contract::{are_uniform, is_direction};
use crate::slope::{Ggx, MicrosurfaceSlope, cap_bound, sample_bounded_cap};
use glam::{DVec3, Vec3};

/// A normal within this fraction of the cap's height below its bound still gets the bounded
/// density in [`GgxBoundedCap::pdf`] (f32 rounding of the samples at u1 = 1 − 2⁻²⁴; 16 × the
/// tail cut, a probability below 1e-6 that the density gives and the sampler does not).
const BOUND_TOLERANCE: f64 = 1.0 / 1_048_576.0; // 2⁻²⁰

/// GGX visible normals for reflection from the bounded spherical cap (Eto and Tokuyoshi
/// 2023, eqs. 5–8; see the module documentation for the bound, its density and what the
/// crate adds): the spherical-cap sampler of [`GgxSphericalCap`](super::GgxSphericalCap)
/// restricted to the normals that can reflect ωi above the horizon. It is a sampler of
/// *reflection* normals: its density is not D_ωi but D_ωi A/A_b on the normals it keeps
/// (A/A_b ≥ 1) and 0 on the others, all of whose reflections point into the surface. Views
/// on or below the horizon sample the whole visible cap (density D_ωi).
///
/// # Examples
/// ```
/// use microsurface::Ggx;
/// use microsurface::vndf::{GgxBoundedCap, GgxSphericalCap, VisibleNormalSampler};
/// use microsurface::glam::Vec3;
/// let ggx = Ggx::isotropic(0.8)?;
/// let (bounded, cap) = (GgxBoundedCap(ggx), GgxSphericalCap(ggx));
/// let wi = Vec3::new(0.6, 0.0, 0.8);
/// let wm = bounded.sample(wi, [0.3, 0.7, 0.0]);
/// // a kept normal is more likely than under the spherical cap
/// assert!(bounded.pdf(wi, wm) > cap.pdf(wi, wm));
/// # Ok::<(), microsurface::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GgxBoundedCap(pub Ggx);

impl VisibleNormalSampler for GgxBoundedCap {
    #[inline]
    fn sample(&self, wi: Vec3, u: [f32; 3]) -> Vec3 {
        require!(is_direction(wi) && are_uniform(&u), Vec3::NAN; wi, u);
        sample_bounded_cap(&self.0, wi, u[0], u[1])
    }

    /// D_b(ωm) = ⟨ωi, ωm⟩ D(ωm)/A_b where c(ωm).z ≥ −b (tested in f64 as 2(v·n) n.z ≥
    /// (1 − k) v.z |n|², n = (ωm.x/αx, ωm.y/αy, ωm.z), with a tolerance of 2⁻²⁰ of the cap's
    /// height), 0 elsewhere; D_ωi for ωi.z ≤ 0. In f64, rounded once.
    #[inline]
    fn pdf(&self, wi: Vec3, wm: Vec3) -> f32 {
        require!(is_direction(wi) && is_direction(wm), 0.0; wi, wm);
        let ggx = &self.0;
        if wi.z <= 0.0 {
            // the whole visible cap: the spherical cap's density
            return ggx.d_wi(wi, wm);
        }
        let cos_im = wi.as_dvec3().dot(wm.as_dvec3());
        if cos_im <= 0.0 || wm.z <= 0.0 {
            return 0.0;
        }
        let bound = cap_bound(ggx, wi);
        let (ax, ay) = (f64::from(ggx.alpha_x()), f64::from(ggx.alpha_y()));
        let v = DVec3::new(ax * f64::from(wi.x), ay * f64::from(wi.y), f64::from(wi.z));
        let len = v.length();
        let top = bound.top64(v, len);
        let n = DVec3::new(f64::from(wm.x) / ax, f64::from(wm.y) / ay, f64::from(wm.z));
        let n_sq = n.length_squared();
        let kept = 2.0 * v.dot(n) * n.z - (2.0 - f64::from(bound.kappa)) * v.z * n_sq
            >= -BOUND_TOLERANCE * top * n_sq;
        if !kept || top <= 0.0 {
            return 0.0;
        }
        (cos_im * ggx.d64(wm.as_dvec3()) / (0.5 * top)) as f32
    }
}
