//! Noncentral (sheared) microsurfaces: a slope distribution offset by a mean slope
//! (Dupuy 2015, thesis §3.2).

use crate::contract::{is_direction, is_direction64, is_uniform};
use crate::error::Error;
use crate::slope::MicrosurfaceSlope;
use crate::vector::ensure_visible;
use crate::vector::normalize_fast;
use glam::{DVec3, Vec2, Vec3};

/// A sheared microsurface (Dupuy 2015, thesis §3.2): the slopes of the central distribution `S`
/// ([`Ggx`](crate::Ggx), [`Beckmann`](crate::Beckmann), [`Elliptical`](crate::Elliptical), …)
/// offset by the mean slope x̃n = (x̃n, ỹn), so that its mean normal is
/// n = (−x̃n, −ỹn, 1)/√(1 + x̃n² + ỹn²).
///
/// * D (eq. 3.2): D(ωh) = P_S(x̃h − x̃n, ỹh − ỹn) sec⁴θh, evaluated as D_S(v/‖v‖)/‖v‖⁴ with
///   v = (h.x + x̃n h.z, h.y + ỹn h.z, h.z) the unsheared normal (stable up to grazing). It keeps
///   ∫ D cos θh dωh = 1 (eq. 3.1), but its mean normal is n: ∫ ωh D(ωh) dωh = n sec θn.
/// * The projected area A(ω) = ∫ ⟨ω, ωh⟩⁺ D(ωh) dωh (the shear-invariance derivation of eq. 3.3)
///   is ‖k‖ A_S(k/‖k‖) with k = (ω.x, ω.y, c) and c = ω.z − ω.x x̃n − ω.y ỹn = ⟨ω, n⟩ sec θn,
///   valid on the whole sphere (A_S is).
/// * G1 (eq. 3.3): G1(ω) = cos θ / A(ω) = (cos θ/c) G1_S(k/‖k‖) for ω above the base plane, 0
///   below. It exceeds 1 where c < cos θ (ω tilted away from n): the masking is normalized to
///   the base plane's projected area cos θ, not the tilted mean plane's c (thesis §3.4 on
///   its limits). The thesis' listing 3.2 returns 0 where c ≤ 0; the derivation, continued on
///   the whole sphere of A_S, gives the continuous z/A(ω), which this type returns.
/// * Visible normals (eq. 3.4): `S`'s visible normal m from k/‖k‖, sheared back,
///   ωh ∝ (m.x − x̃n m.z, m.y − ỹn m.z, m.z), with density D_ωi(ωh) = ⟨ωi, ωh⟩⁺ D(ωh)/A(ωi).
///
/// # Not a [`MicrosurfaceSlope`]
/// The random walk (Heitz et al. 2016) and the position-free estimators (Wang et al. 2022) rest
/// on a microsurface that is a stationary height field over the base plane z = 0: its Smith Λ
/// obeys A(ω) − A(−ω) = cos θ (hence Λ(−ω) = −1 − Λ(ω), the trait's contract) and its heights
/// have a distribution. A sheared surface h(x, y) = h₀(x, y) + x̃n x + ỹn y has neither: its
/// heights drift across the base plane (no height distribution), and
/// A(ω) − A(−ω) = c ≠ cos θ. It is stationary over its tilted mean plane, where a walk would
/// be a central one in the frame of n with exits through that plane, not the base plane (no
/// longer the noncentral BRDF of the thesis). This type therefore does not implement
/// [`MicrosurfaceSlope`], so that the type system keeps it out of
/// [`Microsurface`](crate::research::Microsurface), [`PositionFree`](crate::research::PositionFree) and
/// [`MicrofacetBsdf`](crate::MicrofacetBsdf); its single-scattering BRDF is
/// [`Noncentral::eval_single_scattering`] (with [`Noncentral::sample_single_scattering`] and
/// [`Noncentral::pdf_single_scattering`]), and renderers use it through
/// [`NoncentralBsdf`](crate::leadr::NoncentralBsdf).
///
/// # Single scattering: separable G2
/// The thesis' correlated G2 (eq. 2.13), 1/G2 = 1/G1(ωi) + 1/G1(ωo) − 1, is not positive for
/// noncentral G1 > 1 (two views tilted away from n); the single-scattering BRDF here uses the
/// separable G2 = G1(ωi) G1(ωo), positive everywhere, so that a sampled reflection's weight is
/// F·G1(ωo).
///
/// # Examples
/// ```
/// use microsurface::{Beckmann, Elliptical};
/// use microsurface::leadr::Noncentral;
/// use microsurface::glam::{Vec2, Vec3};
///
/// let slope = Elliptical::<Beckmann>::from_bivariate(0.3, 0.2, 0.5)?;
/// let surface = Noncentral::new(slope, Vec2::new(0.4, -0.1))?;
/// let wi = Vec3::new(0.3, 0.2, 0.9).normalize();
/// let wm = surface.sample_d_wi(wi, 0.3, 0.7);
/// assert!(wm.z > 0.0 && wi.dot(wm) > 0.0 && surface.d_wi(wi, wm) > 0.0);
/// assert!(surface.g1(wi) > 0.0);
/// # Ok::<(), microsurface::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Noncentral<S> {
    /// The central (unsheared) distribution.
    central: S,
    /// The mean slope (x̃n, ỹn).
    mean_slope: Vec2,
    /// The mean slope in f64.
    mean_x: f64,
    mean_y: f64,
}

impl<S: MicrosurfaceSlope> Noncentral<S> {
    /// The distribution `slope` sheared to the mean slope `mean_slope` = (x̃n, ỹn), i.e. the
    /// mean normal (−x̃n, −ỹn, 1)/‖·‖ (slopes x̃ = −m.x/m.z as everywhere in the crate).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] (`"mean_slope.x"`, `"mean_slope.y"`) if a component is NaN or
    /// infinite.
    pub fn new(slope: S, mean_slope: Vec2) -> Result<Self, Error> {
        for (name, value) in [("mean_slope.x", mean_slope.x), ("mean_slope.y", mean_slope.y)] {
            if !value.is_finite() {
                return Err(Error::InvalidParameter { name, value, expected: "finite" });
            }
        }
        Ok(Self {
            central: slope,
            mean_slope,
            mean_x: f64::from(mean_slope.x),
            mean_y: f64::from(mean_slope.y),
        })
    }

    /// The central (unsheared) distribution.
    #[inline]
    pub fn central(&self) -> &S {
        &self.central
    }

    /// The mean slope (x̃n, ỹn).
    #[inline]
    pub fn mean_slope(&self) -> Vec2 {
        self.mean_slope
    }

    /// The mean normal n = (−x̃n, −ỹn, 1)/√(1 + x̃n² + ỹn²).
    #[inline]
    pub fn mean_normal(&self) -> Vec3 {
        normalize_fast(Vec3::new(-self.mean_slope.x, -self.mean_slope.y, 1.0), Vec3::Z)
    }

    /// The slope density P²²(x̃ − x̃n, ỹ − ỹn) of the central distribution (eq. 3.2).
    #[inline]
    pub fn p22(&self, slope_x: f32, slope_y: f32) -> f32 {
        require!(!slope_x.is_nan() && !slope_y.is_nan(), 0.0; slope_x, slope_y);
        let x = (f64::from(slope_x) - self.mean_x) as f32;
        let y = (f64::from(slope_y) - self.mean_y) as f32;
        self.central.p22(x, y)
    }

    /// D(ωm) by eq. 3.2 for ωm.z > 0, 0 otherwise. Evaluated in f64 (see [`Self::d64`]).
    ///
    /// Invalid input ([policy](crate#invalid-input)): a non-unit `wm` gives 0.
    #[inline]
    pub fn d(&self, wm: Vec3) -> f32 {
        require!(is_direction(wm), 0.0; wm);
        self.d_unchecked(wm.as_dvec3()) as f32
    }

    /// D(ωm) in double precision: D_S(v/‖v‖)/‖v‖⁴ with the unsheared normal
    /// v = (m.x + x̃n m.z, m.y + ỹn m.z, m.z), formed in f64 (so that the accuracy is `S`'s `d64`).
    ///
    /// Invalid input ([policy](crate#invalid-input)): a non-unit `wm` gives 0.
    #[inline]
    pub fn d64(&self, wm: DVec3) -> f64 {
        require!(is_direction64(wm), 0.0; wm);
        self.d_unchecked(wm)
    }

    #[inline(always)]
    pub(crate) fn d_unchecked(&self, wm: DVec3) -> f64 {
        if wm.z.is_nan() || wm.z <= 0.0 {
            return 0.0;
        }
        let v = DVec3::new(wm.x + self.mean_x * wm.z, wm.y + self.mean_y * wm.z, wm.z);
        let len_sq = v.length_squared();
        let inv_len = 1.0 / len_sq.sqrt();
        self.central.d64_unchecked(v * inv_len) * (inv_len * inv_len) * (inv_len * inv_len)
    }

    /// k = (ω.x, ω.y, ω.z − ω.x x̃n − ω.y ỹn): the direction whose central projected area is ω's
    /// sheared one (unnormalized), in f64.
    #[inline(always)]
    fn unsheared_view(&self, w: Vec3) -> DVec3 {
        let w = w.as_dvec3();
        DVec3::new(w.x, w.y, w.z - w.x * self.mean_x - w.y * self.mean_y)
    }

    /// The projected area A(ω) = ∫ ⟨ω, ωm⟩⁺ D(ωm) dωm = ‖k‖ A_S(k/‖k‖) for any ω, evaluated in
    /// f64 (k as in the type's documentation; the f32 rounding of k/‖k‖ is the only error beyond
    /// `S`'s `projected_area64`) and rounded to f32.
    ///
    /// Invalid input ([policy](crate#invalid-input)): a non-unit `w` gives NaN.
    #[inline]
    pub fn projected_area(&self, w: Vec3) -> f32 {
        require!(is_direction(w), f32::NAN; w);
        self.projected_area_unchecked(w) as f32
    }

    #[inline(always)]
    fn projected_area_unchecked(&self, w: Vec3) -> f64 {
        let k = self.unsheared_view(w);
        let len = k.length();
        len * self.central.projected_area64((k / len).as_vec3())
    }

    /// Smith's masking G1(ω) = cos θ / A(ω) (eq. 3.3) for ω.z > 0, 0 for ω.z ≤ 0 (the base
    /// plane masks). It can exceed 1 (see the type's documentation); where ω sees
    /// (almost) nothing of a steep surface and cos θ/A overflows, it saturates to `f32::MAX`.
    ///
    /// Invalid input ([policy](crate#invalid-input)): a non-unit `w` gives NaN.
    #[inline]
    pub fn g1(&self, w: Vec3) -> f32 {
        require!(is_direction(w), f32::NAN; w);
        self.g1_unchecked(w) as f32
    }

    #[inline(always)]
    pub(crate) fn g1_unchecked(&self, w: Vec3) -> f64 {
        if w.z.is_nan() || w.z <= 0.0 {
            return 0.0;
        }
        let area = self.projected_area_unchecked(w);
        (f64::from(w.z) / area).min(f64::from(f32::MAX))
    }

    /// The distribution of visible normals D_ωi(ωm) = ⟨ωi, ωm⟩⁺ D(ωm)/A(ωi), for any ωi (0 where
    /// ωi sees nothing), in f64 internally: the density of [`Self::sample_d_wi`].
    ///
    /// Invalid input ([policy](crate#invalid-input)): non-unit directions give 0.
    #[inline]
    pub fn d_wi(&self, wi: Vec3, wm: Vec3) -> f32 {
        require!(is_direction(wi) && is_direction(wm), 0.0; wi, wm);
        self.d_wi_unchecked(wi, wm.as_dvec3()) as f32
    }

    /// D_ωi as the central D_ωi of the unsheared pair: with v = (m.x + x̃n m.z, m.y + ỹn m.z, m.z)
    /// and k as above, ⟨ωi, ωm⟩ = ⟨k, v⟩, so D_ωi(ωm) = D_S,k̂(v̂)/‖v‖³. This inherits the central
    /// slope's precision where A(ωi) underflows (a view far behind the mean plane: Beckmann's
    /// log-space D_ωi); the visibility is decided on the given pair, the central value rescaled
    /// by the ratio of the two cosines (which differ only by the rounding of k̂).
    #[inline(always)]
    pub(crate) fn d_wi_unchecked(&self, wi: Vec3, wm: DVec3) -> f64 {
        let cos_im = wi.as_dvec3().dot(wm);
        if cos_im <= 0.0 || wm.z <= 0.0 {
            return 0.0;
        }
        let v = DVec3::new(wm.x + self.mean_x * wm.z, wm.y + self.mean_y * wm.z, wm.z);
        let len_v = v.length();
        let m = v / len_v;
        let k = self.unsheared_view(wi);
        let len_k = k.length();
        let view = (k / len_k).as_vec3();
        let cos_central = view.as_dvec3().dot(m);
        if cos_central > 0.0 {
            let scale = cos_im / (cos_central * len_k * len_v);
            return self.central.d_wi64_unchecked(view, m) * scale / (len_v * len_v * len_v);
        }
        let area = len_k * self.central.projected_area64(view);
        if area > 0.0 { cos_im * self.d_unchecked(wm) / area } else { 0.0 }
    }

    /// Samples ωm from D_ωi exactly (eq. 3.4), for any ωi, from two uniforms in [0, 1): `S`'s
    /// visible normal m from k/‖k‖, sheared to (m.x − x̃n m.z, m.y − ỹn m.z, m.z)/‖·‖. Its
    /// visibility ⟨ωi, ωm⟩ ∝ ⟨k, m⟩ > 0 is `S`'s. Tails as `S`'s sampler; +z-like "nothing"
    /// (the sheared +z, i.e. n) for ωi = −z.
    ///
    /// Invalid input ([policy](crate#invalid-input)): a non-unit `wi` or a uniform outside
    /// [0, 1] gives a NaN vector.
    #[inline]
    pub fn sample_d_wi(&self, wi: Vec3, u1: f32, u2: f32) -> Vec3 {
        require!(is_direction(wi) && is_uniform(u1) && is_uniform(u2), Vec3::NAN; wi, u1, u2);
        self.sample_d_wi_unchecked(wi, u1, u2)
    }

    #[inline(always)]
    pub(crate) fn sample_d_wi_unchecked(&self, wi: Vec3, u1: f32, u2: f32) -> Vec3 {
        let k = self.unsheared_view(wi);
        let m = self.central.sample_d_wi_unchecked((k / k.length()).as_vec3(), u1, u2).as_dvec3();
        let h = DVec3::new(m.x - self.mean_x * m.z, m.y - self.mean_y * m.z, m.z);
        ensure_visible(wi, (h / h.length()).as_vec3())
    }
}
