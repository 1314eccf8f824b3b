//! Deterministic quadrature of the single-scattering reflected and transmitted albedo of an
//! isotropic dielectric microsurface (height-correlated Smith, dielectric Fresnel), the model of
//! `microsurface::Dielectric` with `Technique::SingleScattering`.
//!
//! With light from outside (ωi.z = μ > 0) and relative index η = η_inside/η_outside (for light
//! from inside, the flipped configuration with 1/η), written over the visible normals:
//!
//! R(μ) = ∫ D_ωi(ωm) F(ωi·ωm) G2(ωi, ωr)/G1(ωi) dωm over ωr = 2(ωi·ωm)ωm − ωi above the horizon,
//! T(μ) = ∫ D_ωi(ωm) (1 − F(ωi·ωm)) G2ᵗ(ωi, ωt)/G1(ωi) dωm over ωt = refract(ωi, ωm) below it,
//!
//! with G2/G1 = (1 + Λi)/(1 + Λi + Λ(ωr)) and G2ᵗ/G1 = (1 + Λi) B(1 + Λi, 1 + Λ(−ωt)) (Heitz
//! 2014, eq. 99 and the beta-function form of the supplement of Heitz et al. 2016, §3.4), since
//! f_r cos θo dωo = D_ωi F G2/G1 dωm (Jacobian 1/(4 ωo·ωm)) and the transmission Jacobian
//! η²|ωt·ωm|/(ωi·ωm + η ωt·ωm)² cancels the BTDF's (Walter et al. 2007, eqs. 16 and 21). T is
//! the transmitted *flux* fraction (the `Transport::Importance` convention of the BTDF); with
//! radiance transport the BTDF carries an extra 1/η².
//!
//! Over the slopes (x̃, ỹ) as in [`super::quadrature`]: D_ωi(ωm) dωm = P²²(x̃, ỹ) (μ − s x̃)/A dx̃ dỹ
//! with A = (1 + Λi) μ, in polar coordinates (ρ, ψ) about the slope origin with the radial
//! variable flattened by the distribution. Along each ray the integrand is continuous (it
//! vanishes where a facet turns away, where the reflection or the refraction grazes the horizon,
//! and at total internal reflection) but has kinks there: the radial integral is split at those
//! breakpoints (the reflection horizon in closed form, the critical angle and the refraction
//! horizon by bisection of sign changes found on a scan) and each piece is graded towards both
//! ends.

use super::quadrature::{Family, GL16};
use glam::{DVec3, Vec3};
use microsurface::slope::MicrosurfaceSlope;
use microsurface::special::beta;
use microsurface::{Beckmann, Ggx};

/// Beyond this w = ρ/α the Beckmann slope density is below e^{−81}.
const BECKMANN_W_MAX: f64 = 9.0;
/// Scan points per ray for the sign changes of the critical angle and the refraction horizon.
const SCAN: usize = 32;
/// Bisection steps per breakpoint (the flattened variable is ≤ π/2: to 2⁻⁴⁰ of it).
const BISECTIONS: usize = 40;
/// Scan points over ψ ∈ [0, π] for the tangencies.
const PSI_SCAN: usize = 64;
/// Halvings towards each end of a piece beyond log₂(1/μ), and at most this many.
const EXTRA_LEVELS: f64 = 2.0;
const MAX_LEVELS: f64 = 24.0;
/// Halvings towards the features of μ = 0.
const GRAZING_LEVELS: usize = 10;
/// Halvings towards a critical-angle breakpoint or a tangency (square-root features).
const CRITICAL_LEVELS: usize = 6;

/// The exact dielectric Fresnel reflectance for cos θ = c ≥ 0 at relative index η (1 beyond
/// the critical angle) (Walter et al. 2007, eq. 22).
pub fn fresnel(c: f64, eta: f64) -> f64 {
    let g_sq = eta * eta - 1.0 + c * c;
    if g_sq <= 0.0 {
        return 1.0;
    }
    let g = g_sq.sqrt();
    let a = (g - c) / (g + c);
    let b = (c * (g + c) - 1.0) / (c * (g - c) + 1.0);
    0.5 * a * a * (1.0 + b * b)
}

/// ∫ₐᵇ of a pair-valued f by `n` equal panels of 16-point Gauss–Legendre.
fn gauss_pair<F: FnMut(f64) -> [f64; 2]>(a: f64, b: f64, n: usize, f: &mut F) -> [f64; 2] {
    let mut sum = [0.0; 2];
    if n == 0 || b <= a {
        return sum;
    }
    let h = (b - a) / n as f64;
    for p in 0..n {
        let mid = a + (p as f64 + 0.5) * h;
        for &(x, w) in &GL16 {
            let (l, r) = (f(mid - 0.5 * h * x), f(mid + 0.5 * h * x));
            sum[0] += w * (l[0] + r[0]);
            sum[1] += w * (l[1] + r[1]);
        }
    }
    [sum[0] * 0.5 * h, sum[1] * 0.5 * h]
}

/// The halvings towards each end of a piece (0: no feature there).
#[derive(Debug, Clone, Copy)]
struct Ends {
    low: usize,
    high: usize,
}

/// ∫ₐᵇ of a pair-valued f, `panels` equal panels with the outer ones split geometrically
/// towards the ends into the given numbers of halvings.
fn graded_both<F: FnMut(f64) -> [f64; 2]>(a: f64, b: f64, panels: usize, ends: Ends, f: &mut F) -> [f64; 2] {
    let panels = panels.max(2);
    let h = (b - a) / panels as f64;
    let mut sum = gauss_pair(a + h, b - h, panels - 2, f);
    let mut add = |v: [f64; 2]| {
        sum[0] += v[0];
        sum[1] += v[1];
    };
    if ends.low > 0 {
        let (mut lo, mut width) = (a + h, 0.5 * h);
        for _ in 0..ends.low {
            add(gauss_pair(lo - width, lo, 1, f));
            lo -= width;
            width *= 0.5;
        }
        add(gauss_pair(a, lo, 1, f));
    } else {
        add(gauss_pair(a, a + h, 1, f));
    }
    if ends.high > 0 {
        let (mut hi, mut width) = (b - h, 0.5 * h);
        for _ in 0..ends.high {
            add(gauss_pair(hi, hi + width, 1, f));
            hi += width;
            width *= 0.5;
        }
        add(gauss_pair(hi, b, 1, f));
    } else {
        add(gauss_pair(b - h, b, 1, f));
    }
    sum
}

/// (R, T): the single-scattering reflected and transmitted albedo at μ ∈ [0, 1], α > 0,
/// η > 0 (light from the side whose relative index is η), with `panels` panels of 16-point
/// Gauss–Legendre per variable and piece.
pub fn dielectric_albedo(family: Family, mu: f64, alpha: f64, eta: f64, panels: usize) -> (f64, f64) {
    let a32 = alpha as f32;
    let lambda = |w: DVec3| -> f64 {
        let w = w.as_vec3();
        match family {
            Family::Ggx => Ggx::isotropic(a32).expect("α > 0").lambda64(w),
            Family::Beckmann => Beckmann::isotropic(a32).expect("α > 0").lambda64(w),
        }
    };
    let area_i = {
        let s = (1.0 - mu * mu).max(0.0).sqrt();
        let w = Vec3::new(s as f32, 0.0, mu as f32);
        match family {
            Family::Ggx => Ggx::isotropic(a32).expect("α > 0").projected_area64(w),
            Family::Beckmann => Beckmann::isotropic(a32).expect("α > 0").projected_area64(w),
        }
    };
    let s = (1.0 - mu * mu).max(0.0).sqrt();
    let wi = DVec3::new(s, 0.0, mu);
    let one_plus_lambda_i = if mu > 0.0 { area_i / mu } else { f64::INFINITY };
    // at μ = 0 the visible region is the half plane x̃ < 0, and its features (F → 1 on the
    // facets seen edge-on at ψ = π/2) have no scale: graded as at μ = 2⁻⁸
    let levels = if mu > 0.0 {
        (EXTRA_LEVELS - mu.log2()).clamp(EXTRA_LEVELS, MAX_LEVELS) as usize
    } else {
        GRAZING_LEVELS
    };
    // 1 − F ∝ √(c − c_crit) at the critical angle: a square-root singularity of the
    // integrand's derivative wherever a piece ends there
    let critical_levels = levels.max(CRITICAL_LEVELS);
    // the radial variable t ↦ ρ and its density (P²² ρ dρ = density dt)
    let rho_of = |t: f64| -> f64 {
        match family {
            Family::Ggx => alpha * t.tan(),
            Family::Beckmann => alpha * t,
        }
    };
    let density = |t: f64| -> f64 {
        match family {
            Family::Ggx => t.sin() * t.cos() * core::f64::consts::FRAC_1_PI,
            Family::Beckmann => t * (-t * t).exp() * core::f64::consts::FRAC_1_PI,
        }
    };
    let t_of = |rho: f64| -> f64 {
        match family {
            Family::Ggx => (rho / alpha).atan(),
            Family::Beckmann => (rho / alpha).min(BECKMANN_W_MAX),
        }
    };
    // the facet at slopes (ρ cos ψ, ρ sin ψ): (m, c = ωi·m, 1/L = m.z)
    let facet = |rho: f64, cp: f64, sp: f64| -> (DVec3, f64, f64) {
        let (x, y) = (rho * cp, rho * sp);
        let inv_len = 1.0 / (1.0 + x * x + y * y).sqrt();
        (DVec3::new(-x * inv_len, -y * inv_len, inv_len), (mu - s * x) * inv_len, inv_len)
    };
    // > 0 where the facet transmits (no total internal reflection)
    let critical = |rho: f64, cp: f64, sp: f64| -> f64 {
        let c = facet(rho, cp, sp).1;
        eta * eta - 1.0 + c * c
    };
    // > 0 where the refraction leaves below the horizon: ωt.z = ((c − g) m.z − μ)/η < 0
    let below = |rho: f64, cp: f64, sp: f64| -> f64 {
        let (_, c, mz) = facet(rho, cp, sp);
        let g = (eta * eta - 1.0 + c * c).max(0.0).sqrt();
        mu - (c - g) * mz
    };
    let integrand = |rho: f64, cp: f64, sp: f64, reflects: bool| -> [f64; 2] {
        let (m, c, _) = facet(rho, cp, sp);
        if c <= 0.0 {
            return [0.0; 2];
        }
        let visible = mu - s * rho * cp;
        let f = fresnel(c, eta);
        let r = if reflects {
            if mu == 0.0 {
                visible * f
            } else {
                let wr = (2.0 * c * m - wi).normalize();
                if wr.z <= 0.0 { 0.0 } else { visible * f * area_i / (area_i + mu * lambda(wr)) }
            }
        } else {
            0.0
        };
        let g_sq = eta * eta - 1.0 + c * c;
        let t = if mu > 0.0 && g_sq > 0.0 && f < 1.0 {
            let g = g_sq.sqrt();
            // −ωt = ((g − c) m + ωi)/η
            let up = ((g - c) * m + wi).normalize();
            if up.z <= 0.0 {
                0.0
            } else {
                visible * (1.0 - f) * one_plus_lambda_i * beta(one_plus_lambda_i, 1.0 + lambda(up))
            }
        } else {
            0.0
        };
        [r, t]
    };
    let rho_max = |cp: f64| -> f64 {
        let root = (s * s * cp * cp + mu * mu).sqrt();
        if cp >= 0.0 {
            if root == 0.0 { 0.0 } else { mu / (s * cp + root) }
        } else if mu == 0.0 {
            f64::INFINITY
        } else {
            (root - s * cp) / mu
        }
    };
    // the breakpoints of a ray: sign changes of the critical angle and the refraction horizon
    let roots = |cp: f64, sp: f64, t_end: f64, breaks: &mut Vec<(f64, usize)>| {
        // at μ = 0 nothing is transmitted, but the critical angle still bounds F = 1
        let curves: [&dyn Fn(f64, f64, f64) -> f64; 2] = [&critical, &below];
        for (which, g) in curves[..if mu > 0.0 { 2 } else { 1 }].iter().enumerate() {
            let at = |t: f64| g(rho_of(t.min(t_end * (1.0 - 1e-15))), cp, sp);
            let mut prev_t = 0.0;
            let mut prev = at(0.0);
            for k in 1..=SCAN {
                let t = t_end * k as f64 / SCAN as f64;
                let v = at(t);
                if (v > 0.0) != (prev > 0.0) {
                    let (mut lo, mut hi) = (prev_t, t);
                    for _ in 0..BISECTIONS {
                        let mid = 0.5 * (lo + hi);
                        if (at(mid) > 0.0) == (prev > 0.0) {
                            lo = mid;
                        } else {
                            hi = mid;
                        }
                    }
                    breaks.push((0.5 * (lo + hi), if which == 0 { critical_levels } else { levels }));
                }
                prev_t = t;
                prev = v;
            }
        }
    };
    let t_end_of = |cp: f64| -> f64 {
        let rho_vis = if cp > 0.0 && s > 0.0 { mu / (s * cp) } else { f64::INFINITY };
        match family {
            Family::Ggx => t_of(rho_vis).min(core::f64::consts::FRAC_PI_2),
            Family::Beckmann => t_of(rho_vis),
        }
    };
    // the number of breakpoints of the ray at ψ: where it changes, a ray is tangent to the
    // critical-angle or the refraction-horizon curve and the radial integral has a singular
    // derivative in ψ
    let count = |psi: f64| -> usize {
        let (sp, cp) = psi.sin_cos();
        let t_end = t_end_of(cp);
        if t_end <= 0.0 {
            return 0;
        }
        let mut b = Vec::new();
        roots(cp, sp, t_end, &mut b);
        b.len()
    };
    let radial = |psi: f64| -> [f64; 2] {
        let (sp, cp) = psi.sin_cos();
        let t_end = t_end_of(cp);
        if t_end <= 0.0 {
            return [0.0; 2];
        }
        let t_mirror = t_of(rho_max(cp));
        let mut breaks = vec![(0.0, 0), (t_end, levels)];
        if t_mirror < t_end {
            breaks.push((t_mirror, levels));
        }
        roots(cp, sp, t_end, &mut breaks);
        breaks.sort_by(|x, y| x.0.total_cmp(&y.0));
        let mut sum = [0.0; 2];
        for w in breaks.windows(2) {
            let ((a, low), (b, high)) = (w[0], w[1]);
            if b <= a {
                continue;
            }
            let reflects = 0.5 * (a + b) < t_mirror;
            let ends = Ends { low, high };
            let part = graded_both(a, b, panels, ends, &mut |t: f64| {
                let v = integrand(rho_of(t), cp, sp, reflects);
                let d = density(t);
                [v[0] * d, v[1] * d]
            });
            sum[0] += part[0];
            sum[1] += part[1];
        }
        sum
    };
    // the outer integral over ψ ∈ [0, π], split at π/2 (where the visibility line recedes to
    // infinity) and at the tangencies, found as changes of the breakpoint count on a scan
    let pi = core::f64::consts::PI;
    let mut psi_breaks = vec![0.0, 0.5 * pi, pi];
    let mut prev_psi = 0.0;
    let mut prev = count(0.0);
    for k in 1..=PSI_SCAN {
        let psi = pi * k as f64 / PSI_SCAN as f64;
        let n = count(psi);
        if n != prev {
            let (mut lo, mut hi) = (prev_psi, psi);
            for _ in 0..BISECTIONS {
                let mid = 0.5 * (lo + hi);
                if count(mid) == prev {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            psi_breaks.push(0.5 * (lo + hi));
        }
        prev_psi = psi;
        prev = n;
    }
    psi_breaks.sort_by(f64::total_cmp);
    let mut outer = [0.0; 2];
    for w in psi_breaks.windows(2) {
        if w[1] <= w[0] {
            continue;
        }
        // π/2 (the conductor's feature of width μ) and the tangencies
        let grade = |psi: f64| if psi == 0.5 * pi { levels } else { critical_levels };
        let ends = Ends {
            low: if w[0] > 0.0 { grade(w[0]) } else { 0 },
            high: if w[1] < pi { grade(w[1]) } else { 0 },
        };
        let part = graded_both(w[0], w[1], panels, ends, &mut |t: f64| radial(t));
        outer[0] += part[0];
        outer[1] += part[1];
    }
    (2.0 * outer[0] / area_i, 2.0 * outer[1] / area_i)
}
