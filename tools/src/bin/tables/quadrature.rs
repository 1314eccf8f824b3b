//! Deterministic quadrature of the single-scattering directional albedo of an isotropic
//! conductor microsurface with F = 1 and height-correlated Smith masking-shadowing.
//!
//! E(μ, α) = ∫ f(ωi, ωo) cos θo dωo with f = D G2 / (4 cos θi cos θo) and
//! G2 = 1/(1 + Λ(ωi) + Λ(ωo)). Written over the half vector ωm and then over its slopes
//! (x̃, ỹ) (D(ωm) dωm = P²²(x̃, ỹ)/cos θm dx̃ dỹ, ⟨ωi, ωm⟩ = (μ − sin θi x̃) cos θm):
//!
//! E(μ) = ∫∫ P²²(x̃, ỹ) (μ − s x̃) · A/(A + μ Λ(ωo)) dx̃ dỹ,   s = sin θi, A = (1 + Λ(ωi)) μ,
//!
//! over the slopes whose mirror direction ωo is above the horizon: the disk
//! (x̃ + tan θi)² + ỹ² < 1/μ², which contains the origin. The form A/(A + μΛo) has the limit 1 at
//! μ = 0, where the disk becomes the half plane x̃ < 0 and E(0) = 1 exactly (the visible
//! microfacets of a grazing ray are its top, from which every reflection escapes).
//!
//! Polar coordinates (ρ, ψ) about the slope origin (the peak of P²²): the disk's boundary is
//! ρmax(ψ) = μ/(s cos ψ + √(s² cos²ψ + μ²)) (cancellation-free for cos ψ ≥ 0, and
//! (√(s² cos²ψ + μ²) − s cos ψ)/μ otherwise), and the radial measure is flattened by the
//! distribution's own substitution: ρ = α tan β for GGX (P²² ρ dρ = sin β cos β dβ / π), ρ = α w
//! for Beckmann (P²² ρ dρ = w e^{−w²} dw / π, cut at w = 9 where e^{−81} < 1e-35).
//! Composite Gauss–Legendre in both variables, graded towards the radial boundary and towards
//! ψ = π/2; the error is estimated a posteriori by doubling
//! the panels.

use glam::Vec3;
use microsurface::slope::MicrosurfaceSlope;
use microsurface::{Beckmann, Ggx};

/// The slope families the tables cover.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Family {
    /// GGX (Trowbridge–Reitz).
    Ggx,
    /// Beckmann.
    Beckmann,
}

impl Family {
    /// The name used in file names and tables.
    pub fn name(self) -> &'static str {
        match self {
            Family::Ggx => "ggx",
            Family::Beckmann => "beckmann",
        }
    }
}

/// Beyond this w = ρ/α the Beckmann slope density is below e^{−81}.
const BECKMANN_W_MAX: f64 = 9.0;

/// 16-point Gauss–Legendre nodes and weights on [−1, 1] (positive half; symmetric).
pub const GL16: [(f64, f64); 8] = [
    (0.095_012_509_837_637_44, 0.189_450_610_455_068_5),
    (0.281_603_550_779_258_9, 0.182_603_415_044_923_6),
    (0.458_016_777_657_227_4, 0.169_156_519_395_002_5),
    (0.617_876_244_402_643_7, 0.149_595_988_816_576_7),
    (0.755_404_408_355_003, 0.124_628_971_255_533_9),
    (0.865_631_202_387_831_7, 0.095_158_511_682_492_78),
    (0.944_575_023_073_232_6, 0.062_253_523_938_647_89),
    (0.989_400_934_991_649_9, 0.027_152_459_411_754_1),
];

/// ∫ₐᵇ f by `panels` equal panels of 16-point Gauss–Legendre.
pub fn gauss_legendre(a: f64, b: f64, panels: usize, mut f: impl FnMut(f64) -> f64) -> f64 {
    let h = (b - a) / panels as f64;
    let mut sum = 0.0;
    for p in 0..panels {
        let mid = a + (p as f64 + 0.5) * h;
        let half = 0.5 * h;
        for &(x, w) in &GL16 {
            sum += w * (f(mid - half * x) + f(mid + half * x));
        }
    }
    sum * 0.5 * h
}

/// Halvings of the last panel of [`graded_gauss_legendre`] beyond log₂(1/μ), the scale of the
/// features it resolves.
const EXTRA_LEVELS: f64 = 6.0;
/// At most this many halvings (down to 2⁻⁴⁰ of the last panel).
const MAX_LEVELS: f64 = 40.0;

/// ∫ₐᵇ f by `panels` equal panels, the last of which is split geometrically towards b into
/// `levels` halvings (halves, quarters, …): resolves a feature at b down to 2⁻ˡᵉᵛᵉˡˢ of the
/// panel, such as the shadowing of mirror directions that approach the horizon.
pub fn graded_gauss_legendre(
    a: f64,
    b: f64,
    panels: usize,
    levels: usize,
    mut f: impl FnMut(f64) -> f64,
) -> f64 {
    let h = (b - a) / panels as f64;
    let body = b - h;
    let mut sum = if panels > 1 { gauss_legendre(a, body, panels - 1, &mut f) } else { 0.0 };
    let mut lo = body;
    let mut width = 0.5 * h;
    for _ in 0..levels {
        sum += gauss_legendre(lo, lo + width, 1, &mut f);
        lo += width;
        width *= 0.5;
    }
    sum + gauss_legendre(lo, b, 1, &mut f)
}

/// The single-scattering albedo E(μ, α) of an isotropic F = 1 conductor, with `panels` panels
/// of 16-point Gauss–Legendre in each of the two variables. μ ∈ [0, 1], α > 0.
pub fn single_scattering_albedo(family: Family, mu: f64, alpha: f64, panels: usize) -> f64 {
    let a32 = alpha as f32;
    let lambda = |w: Vec3| -> f64 {
        f64::from(match family {
            Family::Ggx => Ggx::isotropic(a32).expect("α > 0").lambda(w),
            Family::Beckmann => Beckmann::isotropic(a32).expect("α > 0").lambda(w),
        })
    };
    let area = |w: Vec3| -> f64 {
        f64::from(match family {
            Family::Ggx => Ggx::isotropic(a32).expect("α > 0").projected_area(w),
            Family::Beckmann => Beckmann::isotropic(a32).expect("α > 0").projected_area(w),
        })
    };
    let s = (1.0 - mu * mu).max(0.0).sqrt();
    // the features at the radial boundary and at ψ = π/2 have widths of order μ
    let levels =
        if mu > 0.0 { (EXTRA_LEVELS - mu.log2()).clamp(EXTRA_LEVELS, MAX_LEVELS) as usize } else { 0 };
    let wi = glam::DVec3::new(s, 0.0, mu);
    let area_i = area(wi.as_vec3());
    // the integrand at slopes (ρ cos ψ, ρ sin ψ), without the radial density
    let shadow = |rho: f64, cos_psi: f64, sin_psi: f64| -> f64 {
        let (x, y) = (rho * cos_psi, rho * sin_psi);
        let inv_len = 1.0 / (1.0 + x * x + y * y).sqrt();
        let m = glam::DVec3::new(-x * inv_len, -y * inv_len, inv_len);
        let cos_im = (mu - s * x) * inv_len;
        let wo = 2.0 * cos_im * m - wi;
        if wo.z <= 0.0 || cos_im <= 0.0 {
            return 0.0;
        }
        let visible = mu - s * x;
        if mu == 0.0 {
            return visible;
        }
        let lo = lambda(wo.normalize().as_vec3());
        visible * area_i / (area_i + mu * lo)
    };
    let rho_max = |cos_psi: f64| -> f64 {
        let root = (s * s * cos_psi * cos_psi + mu * mu).sqrt();
        if cos_psi >= 0.0 {
            if root == 0.0 { 0.0 } else { mu / (s * cos_psi + root) }
        } else if mu == 0.0 {
            f64::INFINITY
        } else {
            (root - s * cos_psi) / mu
        }
    };
    let radial = |psi: f64| -> f64 {
        let (sin_psi, cos_psi) = psi.sin_cos();
        let r_max = rho_max(cos_psi);
        if r_max <= 0.0 {
            return 0.0;
        }
        match family {
            Family::Ggx => {
                let b_max = (r_max / alpha).atan();
                graded_gauss_legendre(0.0, b_max, panels, levels, |b| {
                    let (sb, cb) = b.sin_cos();
                    let rho = alpha * sb / cb;
                    sb * cb * core::f64::consts::FRAC_1_PI * shadow(rho, cos_psi, sin_psi)
                })
            }
            Family::Beckmann => {
                let w_max = (r_max / alpha).min(BECKMANN_W_MAX);
                graded_gauss_legendre(0.0, w_max, panels, levels, |w| {
                    w * (-w * w).exp() * core::f64::consts::FRAC_1_PI * shadow(alpha * w, cos_psi, sin_psi)
                })
            }
        }
    };
    // ρmax changes from μ/(2s) to 1 within |cos ψ| ≲ μ/s of ψ = π/2: both halves are graded
    // towards it
    let half = core::f64::consts::FRAC_PI_2;
    let outer = graded_gauss_legendre(0.0, half, panels, levels, radial)
        + graded_gauss_legendre(0.0, half, panels, levels, |t| radial(core::f64::consts::PI - t));
    2.0 * outer / area_i
}
