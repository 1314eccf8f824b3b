//! The classic real-time/offline renderer BRDF: a Lambertian lobe plus a single-scattering
//! Cook–Torrance microfacet lobe with Blinn–Phong, Beckmann or GGX normals, separable Smith
//! masking and Schlick's Fresnel (Cook and Torrance 1982; Walter et al. 2007; Schlick 1994).

use super::sidedness::{Facing, Sidedness, mirror_z};
use super::{Bsdf, BsdfFlags, BsdfSample, BsdfValue, SampleFlags, unit_directions, unit_view};
use crate::error::Error;
use crate::fresnel::fresnel_schlick;
use crate::rng::cut_tails;
use crate::sampling::sample_cosine_hemisphere;
use crate::special::erfc64;
use core::f32::consts::{FRAC_1_PI, TAU};
use glam::{Vec2, Vec3};

/// Above this `a` = 1/(α tan θ) Walter et al.'s rational approximation of the Beckmann G1 is 1.
const RATIONAL_G1_CUTOFF: f32 = 1.6;

/// The normal distribution of the classic BRDF's specular lobe.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ClassicNdf {
    /// D = (αp + 2)/(2π) cos^αp θm, αp ≥ 0 (larger is smoother).
    Phong(f32),
    /// D = exp(−tan²θm/αb²)/(π αb² cos⁴θm).
    Beckmann(f32),
    /// D = αg²/(π cos⁴θm (αg² + tan²θm)²).
    Ggx(f32),
}

/// The Smith masking term of the classic BRDF, G = G1(ωi) G1(ωo).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ClassicMasking {
    /// Exact Smith G1 = 1/(1 + Λ) (for Phong, the Beckmann Λ with αb = √(2/(αp + 2))).
    #[default]
    Exact,
    /// The rational approximation of Walter et al. 2007 (eq. 27) for Beckmann and Phong,
    /// (3.535a + 2.181a²)/(1 + 2.276a + 2.577a²) for a < 1.6, else 1 (a = 1/(αb tan θ), or
    /// √(αp/2 + 1)/tan θ for Phong); GGX keeps its exact G1. Relative error below 0.5 %
    /// (Walter et al. 2007).
    Rational,
}

/// The classic BRDF: K_d/π + D G F/(4 |cos θi| |cos θo|), with Schlick's F (F0 = K_s), sampled
/// by choosing the diffuse lobe with probability ‖K_d‖/(‖K_d‖ + ‖K_s‖) (cosine sampling) and
/// the specular lobe otherwise (sampling D(m) cos θm and reflecting); the pdf is the mixture of
/// both lobes' densities, so `sample`'s weight is exactly f·cos θi/pdf. Reflection only, in
/// the upper hemisphere of the shading frame: a view from below gives nothing (the classic
/// model has no backfacing lobe), unless [`ClassicBrdf::with_sidedness`] makes the material
/// two-sided ([`Sidedness::TwoSided`]). `sample`'s `uc` chooses the lobe and `u` the
/// direction: the caller's sampler drives it completely.
///
/// # Examples
///
/// ```
/// use microsurface::glam::{Vec2, Vec3};
/// use microsurface::{Bsdf, ClassicBrdf, ClassicMasking, ClassicNdf};
///
/// let plastic =
///     ClassicBrdf::new(Vec3::new(0.5, 0.1, 0.1), Vec3::splat(0.04), ClassicNdf::Ggx(0.2), ClassicMasking::Exact)?;
/// let wo = Vec3::new(0.0, 0.6, 0.8);
/// let s = plastic.sample(wo, 0.9, Vec2::new(0.3, 0.7)).expect("a direction above the surface");
/// let (f, pdf) = plastic.eval_with_pdf(wo, s.wi);
/// assert!((s.weight - f.f * s.wi.z / pdf).abs().max_element() < 1e-5 && pdf == s.pdf);
/// # Ok::<(), microsurface::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClassicBrdf {
    kd: Vec3,
    ks: Vec3,
    ndf: ClassicNdf,
    masking: ClassicMasking,
    p_diffuse: f32,
    sidedness: Sidedness,
}

impl ClassicBrdf {
    /// A classic BRDF with diffuse albedo `kd` and specular color `ks` (both per channel in
    /// [0, 1]).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for a component of `kd` or `ks` outside [0, 1] (or NaN),
    /// both zero, a Phong exponent that is negative or not finite, or a Beckmann/GGX α that is
    /// not finite and > 0.
    pub fn new(kd: Vec3, ks: Vec3, ndf: ClassicNdf, masking: ClassicMasking) -> Result<Self, Error> {
        for c in kd.to_array() {
            Error::check_unit_interval("kd", c)?;
        }
        for c in ks.to_array() {
            Error::check_unit_interval("ks", c)?;
        }
        match ndf {
            ClassicNdf::Phong(e) => Error::check_non_negative("phong_exponent", e).map(|_| ())?,
            ClassicNdf::Beckmann(a) | ClassicNdf::Ggx(a) => Error::check_positive("alpha", a).map(|_| ())?,
        }
        let total = kd.length() + ks.length();
        if total == 0.0 {
            return Err(Error::InvalidParameter { name: "kd + ks", value: 0.0, expected: "not both zero" });
        }
        Ok(Self { kd, ks, ndf, masking, p_diffuse: kd.length() / total, sidedness: Sidedness::default() })
    }

    /// The same BRDF with another answer for views from below the shading plane:
    /// [`Sidedness::TwoSided`] mirrors them into the upper hemisphere;
    /// [`Sidedness::BackfacingLobe`] (the default) and [`Sidedness::Black`] give nothing, the
    /// classic model having no backfacing lobe.
    #[must_use]
    pub fn with_sidedness(self, sidedness: Sidedness) -> Self {
        Self { sidedness, ..self }
    }

    /// What views from below the shading plane give.
    #[must_use]
    pub fn sidedness(&self) -> Sidedness {
        self.sidedness
    }

    /// Whether the view `wo` is answered mirrored (`Some(true)`), as given (`Some(false)`) or
    /// not at all.
    #[inline(always)]
    fn mirrored(&self, wo: Vec3) -> Option<bool> {
        match self.sidedness.facing(wo) {
            Facing::AsGiven => Some(false),
            Facing::Mirrored => Some(true),
            Facing::Nothing => None,
        }
    }

    /// D(m) for a unit normal in the shading frame.
    #[must_use]
    pub fn d(&self, m: Vec3) -> f32 {
        let c = m.z;
        if c <= 0.0 {
            return 0.0;
        }
        let c2 = c * c;
        let s2 = (1.0 - c2).max(0.0);
        match self.ndf {
            ClassicNdf::Phong(e) => (e + 2.0) / TAU * c.powf(e),
            ClassicNdf::Beckmann(a) => {
                // exp(−tan²θ/α²)/(π α² cos⁴θ) in f64: cos⁴θ underflows before the exponential
                let (a, c2) = (f64::from(a), f64::from(c) * f64::from(c));
                if c2 == 0.0 {
                    return 0.0;
                }
                ((-(1.0 - c2).max(0.0) / (c2 * a * a)).exp() / (core::f64::consts::PI * a * a * c2 * c2))
                    as f32
            }
            ClassicNdf::Ggx(a) => {
                // α²/(π cos⁴θ (α² + tan²θ)²) = α²/(π (α² cos²θ + sin²θ)²), finite at grazing
                let t = a * a * c2 + s2;
                a * a * FRAC_1_PI / (t * t)
            }
        }
    }

    /// G1(v) for a direction v above the horizon (0 at or below it).
    #[must_use]
    pub fn g1(&self, v: Vec3) -> f32 {
        if v.z <= 0.0 {
            return 0.0;
        }
        if v.z >= 1.0 {
            return 1.0;
        }
        let tan = (1.0 - v.z * v.z).sqrt() / v.z;
        if tan == 0.0 {
            return 1.0;
        }
        let beckmann_alpha = match self.ndf {
            ClassicNdf::Ggx(a) => {
                let t = a * tan;
                return 2.0 / (1.0 + (1.0 + t * t).sqrt());
            }
            ClassicNdf::Beckmann(a) => a,
            ClassicNdf::Phong(e) => (2.0 / (e + 2.0)).sqrt(),
        };
        let a = 1.0 / (beckmann_alpha * tan);
        match self.masking {
            ClassicMasking::Rational if a < RATIONAL_G1_CUTOFF => {
                (3.535 * a + 2.181 * a * a) / (1.0 + 2.276 * a + 2.577 * a * a)
            }
            ClassicMasking::Rational => 1.0,
            ClassicMasking::Exact => {
                let a = f64::from(a);
                let lambda = 0.5 * (-a * a).exp() / (a * core::f64::consts::PI.sqrt()) - 0.5 * erfc64(a);
                (1.0 / (1.0 + lambda)) as f32
            }
        }
    }

    /// cos θm of a normal sampled from D(m) cos θm (Walter et al. 2007, eqs. 28, 30, 35), with
    /// the tails cut at 2⁻²⁴ (the crate's tail policy: u = 0 would give Phong's horizon normal).
    fn sample_cos_theta_m(&self, u: f32) -> f32 {
        let u = cut_tails(u);
        match self.ndf {
            // D(m) cos θm ∝ cos^(e+1) θm: cos θm = u^(1/(e+2)) (Walter et al. 2007, eq. 30; the
            // exponent 1/(e+1) found in some course notes samples cos^e θm instead)
            ClassicNdf::Phong(e) => u.powf(1.0 / (e + 2.0)),
            ClassicNdf::Beckmann(a) => 1.0 / (1.0 - a * a * (-u).ln_1p()).sqrt(),
            ClassicNdf::Ggx(a) => {
                let tan2 = a * a * u / (1.0 - u).max(f32::MIN_POSITIVE);
                1.0 / (1.0 + tan2).sqrt()
            }
        }
    }
}

impl ClassicBrdf {
    /// f and the pdf at (wo, wi), from one half vector, for valid directions above the
    /// surface.
    #[inline]
    fn eval_and_pdf(&self, wo: Vec3, wi: Vec3) -> (Vec3, f32) {
        let m = (wo + wi).normalize();
        let d = self.d(m);
        let specular = d * self.g1(wi) * self.g1(wo) / (4.0 * wi.z * wo.z);
        let f = self.kd * FRAC_1_PI + fresnel_schlick(wi.dot(m), self.ks) * specular;
        let cos_im = wi.dot(m);
        let pdf_specular = if m.z <= 0.0 || cos_im <= 0.0 { 0.0 } else { d * m.z / (4.0 * cos_im) };
        let pdf = self.p_diffuse * wi.z * FRAC_1_PI + (1.0 - self.p_diffuse) * pdf_specular;
        (if f.is_finite() { f } else { Vec3::ZERO }, if pdf.is_finite() { pdf } else { 0.0 })
    }
}

impl Bsdf for ClassicBrdf {
    fn flags(&self) -> BsdfFlags {
        BsdfFlags {
            reflection: true,
            transmission: false,
            glossy: self.p_diffuse < 1.0,
            diffuse: self.p_diffuse > 0.0,
            specular: false,
        }
    }

    /// Deterministic: the key is ignored.
    fn eval_keyed(&self, wo: Vec3, wi: Vec3, _key: u64) -> BsdfValue {
        self.eval_with_pdf_keyed(wo, wi, 0).0
    }

    /// `uc` chooses the lobe, `u` the direction within it (exact: no other random number).
    fn sample_keyed(&self, wo: Vec3, uc: f32, u: Vec2, _key: u64) -> Option<BsdfSample> {
        unit_view!(wo, uc, u, None, self.sample_keyed(wo, uc, u, 0));
        if self.mirrored(wo)? {
            let s = self.sample_above(mirror_z(wo), uc, u)?;
            return Some(BsdfSample { wi: mirror_z(s.wi), ..s });
        }
        self.sample_above(wo, uc, u)
    }

    /// p_d cos θi/π + p_r D(m) cos θm/(4 |ωi·m|).
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        self.eval_with_pdf_keyed(wo, wi, 0).1
    }

    /// One half vector and one D for both.
    fn eval_with_pdf_keyed(&self, wo: Vec3, wi: Vec3, _key: u64) -> (BsdfValue, f32) {
        unit_directions!(wo, wi, (BsdfValue::ZERO, 0.0), self.eval_with_pdf_keyed(wo, wi, 0));
        let (wo, wi) = match self.mirrored(wo) {
            Some(false) => (wo, wi),
            Some(true) => (mirror_z(wo), mirror_z(wi)),
            None => return (BsdfValue::ZERO, 0.0),
        };
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return (BsdfValue::ZERO, 0.0);
        }
        let (f, pdf) = self.eval_and_pdf(wo, wi);
        (BsdfValue { f, exact: true }, pdf)
    }
}

impl ClassicBrdf {
    /// The sample for a valid view and uniforms, answered as it is (nothing from below).
    #[inline]
    fn sample_above(&self, wo: Vec3, uc: f32, u: Vec2) -> Option<BsdfSample> {
        if wo.z <= 0.0 {
            return None;
        }
        let wi = if uc < self.p_diffuse {
            sample_cosine_hemisphere(u.x, u.y)
        } else {
            let cos_m = self.sample_cos_theta_m(u.x);
            let sin_m = (1.0 - cos_m * cos_m).max(0.0).sqrt();
            let (s, c) = (TAU * u.y).sin_cos();
            let m = Vec3::new(sin_m * c, sin_m * s, cos_m);
            // a normal facing away from ωo reflects nothing (taking |ωo·m| instead would
            // produce directions whose density is not the one `pdf` returns)
            let cos_om = wo.dot(m);
            if cos_om <= 0.0 {
                return None;
            }
            (2.0 * cos_om * m - wo).normalize()
        };
        if wi.z <= 0.0 {
            return None;
        }
        let (f, pdf) = self.eval_and_pdf(wo, wi);
        if pdf <= 0.0 {
            return None;
        }
        let weight = f * (wi.z / pdf);
        let flags = SampleFlags { reflection: true, transmission: false, specular: false, exact_pdf: true };
        weight.is_finite().then_some(BsdfSample { wi, weight, pdf, eta: 1.0, flags })
    }
}
