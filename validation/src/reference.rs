//! A test-only double-precision reference for the f32 crate and the accuracy map built on it.
//!
//! Used by `tests/special/accuracy_map.rs` (which asserts the bounds) and
//! `lab/src/bin/stability.rs` (which prints the map).
//!
//! The reference evaluates the definitions of the supplement (Heitz et al. 2016) in f64, on
//! the *same* f32 inputs the crate receives (widened exactly), with `statrs` special functions.
//! Where a textbook formula cancels catastrophically even in f64 it is written in an
//! algebraically equal form (stated at each function); nothing is copied from the crate.
//!
//! Error metric: e = |value − reference| / max(|reference|, floor), where `reference` is first
//! clamped to ±f32::MAX (the crate documents saturation instead of overflow) and a non-finite
//! value counts as e = ∞. With floor = 1e-30 (`TINY`), e is the relative error wherever
//! |reference| ≥ 1e-30 — eight decades above the f32 subnormal range (< 1.18e-38), so that
//! intermediate products of a correct f32 evaluation stay normal — and the absolute error in
//! units of 1e-30 below. Reflectances (Fresnel terms, in [0, 1]) are compared with the floor
//! 1e-6 (`REFLECTANCE_FLOOR`): their relative error is asserted where F ≥ 1e-6 and their
//! absolute error (≤ bound × 1e-6) below.

use glam::{DVec3, Vec3};
use microsurface::fresnel::{fresnel_conductor, fresnel_dielectric};
use microsurface::research::{Interaction, Side};
use microsurface::research::{Material, MicrosurfaceGeometry, UniformHeight};
use microsurface::slope::MicrosurfaceSlope;
use microsurface::{Beckmann, ComplexIor, Conductor, Dielectric, Ggx};
use rand::SeedableRng;
use statrs::function::erf::erfc;
use statrs::function::gamma::ln_gamma;
use std::f64::consts::PI;

/// Below this |reference| the error is absolute (see the module documentation).
pub const TINY: f64 = 1e-30;
/// The floor of the reflectances.
pub const REFLECTANCE_FLOOR: f64 = 1e-6;

// ---------------------------------------------------------------------------------------------
// Reference formulas (f64)
// ---------------------------------------------------------------------------------------------

/// The two slope distributions of the crate.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    Ggx,
    Beckmann,
}

/// A slope distribution in double precision.
#[derive(Debug, Clone, Copy)]
pub struct RefSlope {
    pub kind: Kind,
    pub ax: f64,
    pub ay: f64,
}

impl RefSlope {
    pub fn new(kind: Kind, ax: f32, ay: f32) -> Self {
        Self { kind, ax: f64::from(ax), ay: f64::from(ay) }
    }

    /// q = αx² x² + αy² y² = (αᵢ sin θ)².
    pub fn q(&self, w: DVec3) -> f64 {
        (self.ax * w.x).powi(2) + (self.ay * w.y).powi(2)
    }

    /// Λ for z ≥ 0. GGX: (−1 + √(1 + 1/a²))/2 with 1/a² = t = q/z², written t/(2(1 + √(1 + t)))
    /// (the same number, without the f64 cancellation of −1 + √(1 + t) for small t).
    /// Beckmann: (erf(a) − 1)/2 + exp(−a²)/(2a√π) = exp(−a²)/(2a√π) − erfc(a)/2, a = z/√q.
    fn lambda_up(&self, q: f64, z: f64) -> f64 {
        if q == 0.0 {
            return 0.0;
        }
        if z == 0.0 {
            return f64::INFINITY;
        }
        match self.kind {
            Kind::Ggx => {
                let t = q / (z * z);
                if t.is_infinite() {
                    return f64::INFINITY;
                }
                t / (2.0 * (1.0 + (1.0 + t).sqrt()))
            }
            Kind::Beckmann => {
                let a = z / q.sqrt();
                (-a * a).exp() / (2.0 * a * PI.sqrt()) - 0.5 * erfc(a)
            }
        }
    }

    /// Λ(ω) on the whole sphere, Λ(−ω) = −1 − Λ(ω).
    pub fn lambda(&self, w: DVec3) -> f64 {
        let q = self.q(w);
        if w.z >= 0.0 { self.lambda_up(q, w.z) } else { -1.0 - self.lambda_up(q, -w.z) }
    }

    /// G1 = 1/(1 + Λ) above the horizon, 0 at or below it.
    pub fn g1(&self, w: DVec3) -> f64 {
        if w.z <= 0.0 { 0.0 } else { 1.0 / (1.0 + self.lambda(w)) }
    }

    /// D(ωm) = P²²(−m.x/m.z, −m.y/m.z)/m.z⁴.
    pub fn d(&self, m: DVec3) -> f64 {
        if m.z <= 0.0 {
            return 0.0;
        }
        let (x, y, z) = (m.x / self.ax, m.y / self.ay, m.z);
        match self.kind {
            Kind::Ggx => 1.0 / (PI * self.ax * self.ay * (x * x + y * y + z * z).powi(2)),
            Kind::Beckmann => (-(x * x + y * y) / (z * z)).exp() / (PI * self.ax * self.ay * z.powi(4)),
        }
    }

    /// The projected area (1 + Λ(ω)) cos θ; on the horizon its limit ½ αᵢ sin θ (GGX) or
    /// αᵢ sin θ/(2√π) (Beckmann); below it Λ(−ω)|cos θ|.
    pub fn projected_area(&self, w: DVec3) -> f64 {
        let q = self.q(w);
        if w.z == 0.0 {
            return match self.kind {
                Kind::Ggx => 0.5 * q.sqrt(),
                Kind::Beckmann => 0.5 * q.sqrt() / PI.sqrt(),
            };
        }
        if w.z > 0.0 { (1.0 + self.lambda_up(q, w.z)) * w.z } else { self.lambda_up(q, -w.z) * -w.z }
    }

    /// αᵢ = √(q / sin²θ), αx at the poles.
    pub fn alpha_i(&self, w: DVec3) -> f64 {
        let s2 = w.x * w.x + w.y * w.y;
        if s2 == 0.0 { self.ax } else { (self.q(w) / s2).sqrt() }
    }

    /// D_ωi(ωm) = ⟨ωi, ωm⟩ D(ωm)/A(ωi).
    pub fn d_wi(&self, wi: DVec3, m: DVec3) -> f64 {
        let c = wi.dot(m);
        if c <= 0.0 || m.z <= 0.0 {
            return 0.0;
        }
        let a = self.projected_area(wi);
        // the unscaled reference underflows where ωi is far below the horizon (a = |cot θ|/αᵢ
        // beyond about 26): NaN marks the value as outside what the reference can represent
        if a <= 0.0 { f64::NAN } else { c * self.d(m) / a }
    }
}

/// Dielectric Fresnel reflectance (textbook form, f64).
/// The dielectric reflectance of a refraction whose both cosines are known, cos θi = `ci` and
/// cos θt = `ct`. For a pair (ωi, ωo) Snell's law holds exactly about the generalized half
/// vector, so ct = |ωo·ωh| is the exact transmitted cosine of the given pair; recomputing it
/// from ci by Snell amplifies the rounding of the f32 inputs by 1/cos²θt near the critical
/// angle (an ill-conditioned step the reference must not add).
pub fn fresnel_dielectric_pair_ref(ci: f64, ct: f64, eta: f64) -> f64 {
    let rs = (ci - eta * ct) / (ci + eta * ct);
    let rp = (eta * ci - ct) / (eta * ci + ct);
    0.5 * (rs * rs + rp * rp)
}

pub fn fresnel_dielectric_ref(cos_i: f64, eta: f64) -> f64 {
    let c = cos_i.abs().min(1.0);
    // η² cos²θt = c² + (η − 1)(η + 1), without the cancellation of 1 − (1 − c²)/η²
    let eta2_ct2 = c * c + (eta - 1.0) * (eta + 1.0);
    if eta2_ct2 <= 0.0 {
        return 1.0;
    }
    let ct = eta2_ct2.sqrt() / eta;
    let rs = (c - eta * ct) / (c + eta * ct);
    let rp = (eta * c - ct) / (eta * c + ct);
    0.5 * (rs * rs + rp * rp)
}

#[derive(Debug, Clone, Copy)]
struct C(f64, f64);

impl C {
    fn add(self, o: C) -> C {
        C(self.0 + o.0, self.1 + o.1)
    }
    fn sub(self, o: C) -> C {
        C(self.0 - o.0, self.1 - o.1)
    }
    fn mul(self, o: C) -> C {
        C(self.0 * o.0 - self.1 * o.1, self.0 * o.1 + self.1 * o.0)
    }
    fn div(self, o: C) -> C {
        let d = o.0 * o.0 + o.1 * o.1;
        C((self.0 * o.0 + self.1 * o.1) / d, (self.1 * o.0 - self.0 * o.1) / d)
    }
    fn norm2(self) -> f64 {
        self.0 * self.0 + self.1 * self.1
    }
    /// Principal square root.
    fn sqrt(self) -> C {
        let r = self.0.hypot(self.1);
        let re = (0.5 * (r + self.0)).max(0.0).sqrt();
        let im = (0.5 * (r - self.0)).max(0.0).sqrt().copysign(self.1);
        C(re, im)
    }
}

/// Conductor Fresnel reflectance with complex arithmetic: w = √(n² − sin²θ),
/// rs = (c − w)/(c + w), rp = (n²c − w)/(n²c + w), F = (|rs|² + |rp|²)/2.
pub fn fresnel_conductor_ref(cos_i: f64, eta: f64, k: f64) -> f64 {
    let c = cos_i.abs().min(1.0);
    let n2 = C(eta, k).mul(C(eta, k));
    let w = n2.sub(C(1.0 - c * c, 0.0)).sqrt();
    let cc = C(c, 0.0);
    let rs = cc.sub(w).div(cc.add(w));
    let n2c = n2.mul(cc);
    let rp = n2c.sub(w).div(n2c.add(w));
    0.5 * (rs.norm2() + rp.norm2())
}

/// ln B(a, b). For max(a, b) ≥ 30, lnΓ(a + b) − lnΓ(a) (a the larger) by the difference of
/// Stirling series, (a − ½) ln1p(b/a) + b ln(a + b) − b + s(a + b) − s(a), which does not
/// cancel for a ≫ b (truncation < 3e-14 absolute); otherwise statrs' ln Γ.
pub fn ln_beta_ref(a: f64, b: f64) -> f64 {
    let (a, b) = if a >= b { (a, b) } else { (b, a) };
    if a < 30.0 {
        return ln_gamma(a) + ln_gamma(b) - ln_gamma(a + b);
    }
    let s = |x: f64| {
        let r = 1.0 / (x * x);
        (1.0 / 12.0 - r * (1.0 / 360.0 - r * (1.0 / 1260.0 - r / 1680.0))) / x
    };
    let c = a + b;
    let diff = (a - 0.5) * (b / a).ln_1p() + b * c.ln() - b + s(c) - s(a);
    ln_gamma(b) - diff
}

fn normalize(v: DVec3) -> Option<DVec3> {
    let l = v.length();
    (l > 0.0 && l.is_finite()).then(|| v / l)
}

/// The Fresnel term of a facet: 1 (perfect conductor), gold (channel 0), or a dielectric.
#[derive(Debug, Clone, Copy)]
pub enum RefFresnel {
    One,
    Conductor { eta: f64, k: f64 },
    Dielectric(f64),
}

impl RefFresnel {
    pub fn eval(&self, c: f64) -> f64 {
        match *self {
            RefFresnel::One => 1.0,
            RefFresnel::Conductor { eta, k } => fresnel_conductor_ref(c, eta, k),
            RefFresnel::Dielectric(eta) => fresnel_dielectric_ref(c, eta),
        }
    }
}

/// Reflection phase function F D_ωi(ωh)/(4 ωi·ωh), with the crate's half vector: where a
/// direction is below the horizon, that of the directions ωi/|ωi| and ωo/|ωo| the vectors
/// represent (the half vector of the plain sum ωi + ωo depends on their lengths, and for the
/// near-forward pairs of a view from below by as much as ωi·ωh itself); where both are above,
/// that of the plain sum, the convention of the crate's front-facing kernels.
pub fn phase_reflection_ref(s: &RefSlope, f: RefFresnel, wi: DVec3, wo: DVec3) -> f64 {
    let (wi, wo) = match (wi.z < 0.0 || wo.z < 0.0, normalize(wi), normalize(wo)) {
        (true, Some(wi), Some(wo)) => (wi, wo),
        (true, _, _) => return 0.0,
        (false, _, _) => (wi, wo),
    };
    let Some(h) = normalize(wi + wo) else { return 0.0 };
    let c = wi.dot(h);
    if h.z <= 0.0 || c <= 0.0 {
        return 0.0;
    }
    f.eval(c) * s.d_wi(wi, h) / (4.0 * c)
}

/// The refraction half vector (upper hemisphere) of a valid refraction, or None.
fn refraction_half(wi: DVec3, wo: DVec3, eta: f64) -> Option<DVec3> {
    let h = -normalize(wi + eta * wo)?;
    let h = if h.z < 0.0 { -h } else { h };
    (h.z > 0.0 && wi.dot(h) > 0.0 && wo.dot(h) < 0.0).then_some(h)
}

/// Below this cosine with the facet normal a refraction is "grazing the facet": ωi arrives
/// within 2.9° of the facet plane, or the refracted ωo leaves within 2.9° of it (ωi within
/// that distance of the critical angle).
pub const GRAZING_REFRACTION: f64 = 0.05;

/// Whether (ωi, ωo) is a valid refraction from outside with min(ωi·ωh, |ωo·ωh|) below
/// `GRAZING_REFRACTION`.
pub fn grazing_refraction(wi: DVec3, wo: DVec3, eta: f64) -> bool {
    refraction_half(wi, wo, eta).is_some_and(|h| wi.dot(h).min(-wo.dot(h)) < GRAZING_REFRACTION)
}

/// Transmission phase function η² (1 − F) D_ωi(ωh) |ωo·ωh| / (ωi·ωh + η ωo·ωh)².
pub fn phase_transmission_ref(s: &RefSlope, eta: f64, wi: DVec3, wo: DVec3) -> f64 {
    let Some(h) = refraction_half(wi, wo, eta) else { return 0.0 };
    let (ci, co) = (wi.dot(h), wo.dot(h));
    let den = ci + eta * co;
    eta * eta * (1.0 - fresnel_dielectric_pair_ref(ci, -co, eta)) * s.d_wi(wi, h) * (-co) / (den * den)
}

/// Single-scattering reflection F D(ωh) G2/(4 cos θi), G2 = 1/(1 + Λ(ωi) + Λ(ωo)).
pub fn single_reflection_ref(s: &RefSlope, f: RefFresnel, wi: DVec3, wo: DVec3) -> f64 {
    if wi.z <= 0.0 || wo.z <= 0.0 {
        return 0.0;
    }
    let g2 = 1.0 / (1.0 + s.lambda(wi) + s.lambda(wo));
    let Some(h) = normalize(wi + wo) else { return 0.0 };
    f.eval(wi.dot(h)) * s.d(h) * g2 / (4.0 * wi.z)
}

/// Single-scattering dielectric BSDF × |cos θo| (reflection and transmission; ωi below the
/// surface by the flipped configuration η ↦ 1/η).
pub fn single_dielectric_ref(s: &RefSlope, eta: f64, wi: DVec3, wo: DVec3) -> f64 {
    if wi.z < 0.0 {
        return single_dielectric_ref(s, 1.0 / eta, -wi, -wo);
    }
    if wi.z == 0.0 || wo.z == 0.0 {
        return 0.0;
    }
    if wo.z > 0.0 {
        return single_reflection_ref(s, RefFresnel::Dielectric(eta), wi, wo);
    }
    let Some(h) = refraction_half(wi, wo, eta) else { return 0.0 };
    let (ci, co) = (wi.dot(h), wo.dot(h));
    let den = ci + eta * co;
    let g2 = ln_beta_ref(1.0 + s.lambda(wi), 1.0 + s.lambda(-wo)).exp();
    ci * (-co) * eta * eta * (1.0 - fresnel_dielectric_pair_ref(ci, -co, eta)) * s.d(h) * g2
        / (wi.z * den * den)
}

// ---------------------------------------------------------------------------------------------
// The accuracy map
// ---------------------------------------------------------------------------------------------

/// One measured case.
#[derive(Debug, Clone)]
pub struct Case {
    pub params: String,
    pub value: f64,
    pub reference: f64,
    pub err: f64,
}

/// The measurement of one function over its grid.
#[derive(Debug, Clone)]
pub struct FunctionReport {
    pub name: String,
    /// The asserted bound on e (see the module documentation).
    pub bound: f64,
    /// The floor of the error metric.
    pub floor: f64,
    /// Points evaluated.
    pub points: usize,
    /// Points with |reference| ≥ floor (where e is a relative error).
    pub relative_points: usize,
    /// The worst cases, worst first.
    pub worst: Vec<Case>,
}

impl FunctionReport {
    pub fn max_err(&self) -> f64 {
        self.worst.first().map_or(0.0, |c| c.err)
    }
}

const KEEP: usize = 3;

struct Tracker {
    report: FunctionReport,
}

impl Tracker {
    fn new(name: impl Into<String>, bound: f64, floor: f64) -> Self {
        Self {
            report: FunctionReport {
                name: name.into(),
                bound,
                floor,
                points: 0,
                relative_points: 0,
                worst: Vec::new(),
            },
        }
    }

    fn push(&mut self, value: f64, reference: f64, params: impl FnOnce() -> String) {
        if reference.is_nan() {
            // the reference cannot represent this value (see `RefSlope::d_wi`): no comparison
            return;
        }
        let r = &mut self.report;
        r.points += 1;
        let reference_c = reference.clamp(f64::from(-f32::MAX), f64::from(f32::MAX));
        if reference_c.abs() >= r.floor {
            r.relative_points += 1;
        }
        let err = if value.is_finite() && !reference.is_nan() {
            (value - reference_c).abs() / reference_c.abs().max(r.floor)
        } else {
            f64::INFINITY
        };
        if err == 0.0 || (r.worst.len() == KEEP && err <= r.worst[KEEP - 1].err) {
            return;
        }
        r.worst.push(Case { params: params(), value, reference, err });
        r.worst.sort_by(|a, b| b.err.total_cmp(&a.err));
        r.worst.truncate(KEEP);
    }
}

/// Roughness pairs: 12 isotropic values log-spaced over [1e-4, 4] and anisotropic pairs with
/// ratios up to 1e4.
pub fn alphas() -> Vec<(f32, f32)> {
    let (lo, hi) = (1e-4f64.ln(), 4f64.ln());
    let mut v: Vec<(f32, f32)> = (0..12)
        .map(|k| {
            let a = (lo + (hi - lo) * k as f64 / 11.0).exp() as f32;
            (a, a)
        })
        .collect();
    v.extend([(1e-4, 1.0), (4.0, 4e-4), (1e-2, 1.0), (0.3, 0.03), (2.0, 0.5)]);
    v
}

/// A direction from cos θ (exact in f64) and φ, rounded to f32.
fn dir_z(z: f64, phi: f64) -> Vec3 {
    let s = (1.0 - z * z).max(0.0).sqrt();
    Vec3::new((s * phi.cos()) as f32, (s * phi.sin()) as f32, z as f32)
}

/// cos θ values of the dense single-direction grid: both poles, near-normal, the body, and
/// the approach to the horizon down to exactly 0, mirrored below.
const Z_FINE: [f64; 19] = [
    1.0,
    0.999_999_9,
    0.999_9,
    0.995,
    0.95,
    0.85,
    0.7,
    0.5,
    0.3,
    0.15,
    0.05,
    1e-2,
    1e-3,
    1e-4,
    1e-5,
    1e-6,
    1e-7,
    1e-9,
    0.0,
];
/// cos θ values of the pair grid.
const Z_COARSE: [f64; 10] = [1.0, 0.999, 0.95, 0.7, 0.3, 0.05, 1e-3, 1e-5, 1e-7, 0.0];
const PHI_FINE: [f64; 6] = [0.0, 0.4, 1.1, std::f64::consts::FRAC_PI_2, 2.5, 4.0];
const PHI_COARSE: [f64; 4] = [0.0, 1.1, 2.5, 4.0];

fn directions(zs: &[f64], phis: &[f64]) -> Vec<Vec3> {
    let mut v = Vec::new();
    for &z in zs {
        for sign in [1.0, -1.0] {
            if z == 0.0 && sign < 0.0 {
                continue;
            }
            if z == 1.0 {
                v.push(Vec3::new(0.0, 0.0, sign as f32));
                continue;
            }
            for &phi in phis {
                v.push(dir_z(sign * z, phi));
            }
        }
    }
    v
}

/// The single-direction grid, plus unit directions so close to a pole that x² + y² is
/// subnormal or zero in f32 (sin θ = 1e-20 and 1e-30 at four azimuths, both poles).
pub fn fine_directions() -> Vec<Vec3> {
    let mut v = directions(&Z_FINE, &PHI_FINE);
    for s in [1e-20f64, 1e-30] {
        for phi in [0.3f64, 1.2, 2.0, 5.0] {
            for z in [1.0f32, -1.0] {
                v.push(Vec3::new((s * phi.cos()) as f32, (s * phi.sin()) as f32, z));
            }
        }
    }
    v
}

pub fn coarse_directions() -> Vec<Vec3> {
    directions(&Z_COARSE, &PHI_COARSE)
}

fn d3(v: Vec3) -> DVec3 {
    v.as_dvec3()
}

fn fmt_v(v: Vec3) -> String {
    format!("({:.3e}, {:.3e}, {:.3e})", v.x, v.y, v.z)
}

/// The measured bounds (see the report in `tests/special/accuracy_map.rs`).
pub mod bounds {
    /// Λ, G1, D, projected area, αᵢ (elementwise functions of one direction).
    pub const DIRECTION: f64 = 1e-6;
    /// D_ωi.
    pub const D_WI: f64 = 5e-6;
    /// Phase functions and single-scattering BSDFs.
    pub const PHASE: f64 = 1e-5;
    /// Fresnel terms.
    pub const FRESNEL: f64 = 1e-5;
    /// The single-scattering transmission BSDF: measured worst 8.9e-5 (Beckmann α = 4 with a
    /// refraction grazing the facet, and GGX/Beckmann at α = (1e-4, 1) lit from inside), where
    /// the transmission phase function of the same configurations stays within 1e-5; the
    /// extra error (from the masking term B(1 + Λi, 1 + Λo) or the flipped η) is not yet
    /// explained, so this bound states the measurement rather than a derived limit.
    pub const TRANSMISSION_SINGLE: f64 = 1e-4;
}

fn rng0() -> rand_pcg::Pcg64Mcg {
    rand_pcg::Pcg64Mcg::seed_from_u64(0)
}

fn slope_functions<S: MicrosurfaceSlope>(
    kind: Kind,
    make: impl Fn(f32, f32) -> S,
    out: &mut Vec<FunctionReport>,
) {
    let tag = match kind {
        Kind::Ggx => "GGX",
        Kind::Beckmann => "Beckmann",
    };
    let mut lambda = Tracker::new(format!("{tag} lambda"), bounds::DIRECTION, TINY);
    let mut g1 = Tracker::new(format!("{tag} g1"), bounds::DIRECTION, TINY);
    let mut d = Tracker::new(format!("{tag} d"), bounds::DIRECTION, TINY);
    let mut area = Tracker::new(format!("{tag} projected_area"), bounds::DIRECTION, TINY);
    let mut alpha_i = Tracker::new(format!("{tag} alpha_i"), bounds::DIRECTION, TINY);
    let mut d_wi = Tracker::new(format!("{tag} d_wi"), bounds::D_WI, TINY);
    let mut cond = Tracker::new(format!("{tag} Conductor(F=1) eval_phase"), bounds::PHASE, TINY);
    let mut gold = Tracker::new(format!("{tag} Conductor(gold, R) eval_phase"), bounds::PHASE, TINY);
    let mut refl = Tracker::new(format!("{tag} Dielectric reflection eval_phase"), bounds::PHASE, TINY);
    let mut trans = Tracker::new(format!("{tag} Dielectric transmission eval_phase"), bounds::PHASE, TINY);
    let mut ss_cond = Tracker::new(format!("{tag} Conductor(F=1) single scattering"), bounds::PHASE, TINY);
    let mut ss_gold =
        Tracker::new(format!("{tag} Conductor(gold, R) single scattering"), bounds::PHASE, TINY);
    let mut ss_refl =
        Tracker::new(format!("{tag} Dielectric single scattering (reflection)"), bounds::PHASE, TINY);
    let mut ss_trans = Tracker::new(
        format!("{tag} Dielectric single scattering (transmission)"),
        bounds::TRANSMISSION_SINGLE,
        TINY,
    );
    let mut trans_graze = Tracker::new(
        format!("{tag} Dielectric transmission eval_phase, grazing the facet"),
        bounds::PHASE,
        TINY,
    );
    let mut ss_trans_graze = Tracker::new(
        format!("{tag} Dielectric single scattering (transmission), grazing the facet"),
        bounds::TRANSMISSION_SINGLE,
        TINY,
    );
    let fine = fine_directions();
    let coarse = coarse_directions();
    let gold_ior = ComplexIor::GOLD;
    let gold_ref = RefFresnel::Conductor { eta: f64::from(gold_ior.eta().x), k: f64::from(gold_ior.k().x) };
    let mut rng = rng0();
    for (ax, ay) in alphas() {
        let s = make(ax, ay);
        let r = RefSlope::new(kind, ax, ay);
        let geo = MicrosurfaceGeometry::new(UniformHeight, s);
        let p = |w: Vec3| format!("α=({ax:.3e}, {ay:.3e}) ω={}", fmt_v(w));
        for &w in &fine {
            let wd = d3(w);
            lambda.push(f64::from(s.lambda(w)), r.lambda(wd), || p(w));
            g1.push(f64::from(geo.g1(w)), r.g1(wd), || p(w));
            d.push(f64::from(s.d(w)), r.d(wd), || p(w));
            area.push(f64::from(s.projected_area(w)), r.projected_area(wd), || p(w));
            alpha_i.push(f64::from(s.alpha_i(w)), r.alpha_i(wd), || p(w));
        }
        let pp = |wi: Vec3, wo: Vec3| format!("α=({ax:.3e}, {ay:.3e}) ωi={} ωo={}", fmt_v(wi), fmt_v(wo));
        let perfect = Conductor::perfect();
        let gold_m = Conductor::new(gold_ior);
        let glass = Dielectric::new(1.5).unwrap();
        for &wi in &coarse {
            let wid = d3(wi);
            for &wo in &coarse {
                let wod = d3(wo);
                d_wi.push(f64::from(s.d_wi(wi, wo)), r.d_wi(wid, wod), || pp(wi, wo));
                cond.push(
                    f64::from(perfect.eval_phase(&s, &Interaction::reflection(wi, wo), &mut rng).x),
                    phase_reflection_ref(&r, RefFresnel::One, wid, wod),
                    || pp(wi, wo),
                );
                gold.push(
                    f64::from(gold_m.eval_phase(&s, &Interaction::reflection(wi, wo), &mut rng).x),
                    phase_reflection_ref(&r, gold_ref, wid, wod),
                    || pp(wi, wo),
                );
                for eta in [1.5f32, 1.0 / 1.5] {
                    let m = Dielectric::new(eta).unwrap();
                    let e = f64::from(eta);
                    let pe = || format!("η={eta:.4} {}", pp(wi, wo));
                    refl.push(
                        f64::from(m.eval_phase(&s, &Interaction::reflection(wi, wo), &mut rng).x),
                        phase_reflection_ref(&r, RefFresnel::Dielectric(e), wid, wod),
                        pe,
                    );
                    let t = if grazing_refraction(wid, wod, e) { &mut trans_graze } else { &mut trans };
                    t.push(
                        f64::from(
                            m.eval_phase(
                                &s,
                                &Interaction::new(wi, wo, Side::Outside, Side::Inside),
                                &mut rng,
                            )
                            .x,
                        ),
                        phase_transmission_ref(&r, e, wid, wod),
                        || format!("η={eta:.4} {}", pp(wi, wo)),
                    );
                }
                ss_cond.push(
                    f64::from(perfect.eval_single_scattering(&s, wi, wo, &mut rng).x),
                    single_reflection_ref(&r, RefFresnel::One, wid, wod),
                    || pp(wi, wo),
                );
                ss_gold.push(
                    f64::from(gold_m.eval_single_scattering(&s, wi, wo, &mut rng).x),
                    single_reflection_ref(&r, gold_ref, wid, wod),
                    || pp(wi, wo),
                );
                let value = f64::from(glass.eval_single_scattering(&s, wi, wo, &mut rng).x);
                let reference = single_dielectric_ref(&r, 1.5, wid, wod);
                let pe = || format!("η=1.5 {}", pp(wi, wo));
                let (e, a, b) = if wi.z > 0.0 { (1.5, wid, wod) } else { (1.0 / 1.5, -wid, -wod) };
                if (wi.z > 0.0) == (wo.z > 0.0) {
                    ss_refl.push(value, reference, pe)
                } else if grazing_refraction(a, b, e) {
                    ss_trans_graze.push(value, reference, pe)
                } else {
                    ss_trans.push(value, reference, pe)
                }
            }
        }
    }
    for t in [
        lambda,
        g1,
        d,
        area,
        alpha_i,
        d_wi,
        cond,
        gold,
        refl,
        trans,
        trans_graze,
        ss_cond,
        ss_gold,
        ss_refl,
        ss_trans,
        ss_trans_graze,
    ] {
        out.push(t.report);
    }
}

fn fresnel_functions(out: &mut Vec<FunctionReport>) {
    let mut fd = Tracker::new("fresnel_dielectric", bounds::FRESNEL, REFLECTANCE_FLOOR);
    let mut fd_near_one =
        Tracker::new("fresnel_dielectric, |η − 1| ≤ 1e-3", bounds::FRESNEL, REFLECTANCE_FLOOR);
    let mut fc = Tracker::new("fresnel_conductor", bounds::FRESNEL, REFLECTANCE_FLOOR);
    let cosines: Vec<f32> =
        (0..=2000).map(|i| i as f32 / 2000.0).chain([1e-7, 1e-5, 1e-3, 0.999_999_9]).collect();
    for eta in [0.25f32, 0.5, 1.0 / 1.5, 0.9, 1.0, 1.1, 1.5, 2.5, 4.0] {
        for &c in &cosines {
            fd.push(
                f64::from(fresnel_dielectric(c, eta)),
                fresnel_dielectric_ref(f64::from(c), f64::from(eta)),
                || format!("cos θ={c:.7e} η={eta:.7}"),
            );
        }
    }
    for eta in [1.0f32 - 1e-3, 1.0 - 1e-6, 1.0 + 1e-6, 1.0 + 1e-3] {
        for &c in &cosines {
            fd_near_one.push(
                f64::from(fresnel_dielectric(c, eta)),
                fresnel_dielectric_ref(f64::from(c), f64::from(eta)),
                || format!("cos θ={c:.7e} η={eta:.9}"),
            );
        }
    }
    let iors = [
        ("gold", ComplexIor::GOLD),
        ("copper", ComplexIor::COPPER),
        ("aluminium", ComplexIor::ALUMINIUM),
        ("silver", ComplexIor::SILVER),
        ("η=1.5,k=0", ComplexIor::new(Vec3::splat(1.5), Vec3::ZERO).unwrap()),
        ("η=0.2,k=0.05", ComplexIor::new(Vec3::splat(0.2), Vec3::splat(0.05)).unwrap()),
    ];
    for (name, ior) in iors {
        for &c in &cosines {
            let v = fresnel_conductor(c, &ior);
            for ch in 0..3 {
                let reference =
                    fresnel_conductor_ref(f64::from(c), f64::from(ior.eta()[ch]), f64::from(ior.k()[ch]));
                fc.push(f64::from(v[ch]), reference, || format!("{name}[{ch}] cos θ={c:.7e}"));
            }
        }
    }
    out.extend([fd.report, fd_near_one.report, fc.report]);
}

/// Measures every function of the map.
pub fn accuracy_map() -> Vec<FunctionReport> {
    let mut out = Vec::new();
    slope_functions(Kind::Ggx, |ax, ay| Ggx::new(ax, ay).unwrap(), &mut out);
    slope_functions(Kind::Beckmann, |ax, ay| Beckmann::new(ax, ay).unwrap(), &mut out);
    fresnel_functions(&mut out);
    out
}

/// The map as a markdown table: the worst cases per function.
pub fn markdown_table(reports: &[FunctionReport]) -> String {
    let mut s = String::new();
    s.push_str(
        "| function | bound | max error | points (relative) | parameters | value | reference | error |\n",
    );
    s.push_str("|---|---|---|---|---|---|---|---|\n");
    for r in reports {
        let status = if r.max_err() <= r.bound { "" } else { " **exceeds**" };
        if r.worst.is_empty() {
            s.push_str(&format!(
                "| {} | {:.0e} | 0 (exact){status} | {} ({}) | – | – | – | – |\n",
                r.name, r.bound, r.points, r.relative_points
            ));
        }
        for (i, c) in r.worst.iter().enumerate() {
            let head = if i == 0 {
                format!(
                    "{} | {:.0e} | {:.2e}{status} | {} ({})",
                    r.name,
                    r.bound,
                    r.max_err(),
                    r.points,
                    r.relative_points
                )
            } else {
                " | | | ".to_string()
            };
            s.push_str(&format!(
                "| {head} | {} | {:.9e} | {:.9e} | {:.2e} |\n",
                c.params, c.value, c.reference, c.err
            ));
        }
    }
    s
}
