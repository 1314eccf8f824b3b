//! Normalization of D, D_ωi and the projected area by adaptive quadrature (Heitz et al. 2016,
//! supplement §4.2.1), for GGX and Beckmann over a range of roughnesses and incident
//! directions on the whole sphere, including directions below the horizon.
//!
//! The integrals are taken in slope space, where sharp lobes are as wide as broad ones: the
//! slopes are stretched to α = 1 and rotated to the azimuth of the incident direction ω, where
//! the normals visible from ω are the half-plane x' < κ = cot θ̃ (θ̃ the stretched angle of
//! ω). The half-plane is mapped to a rectangle by x' = tan u, y' = √(1 + x'²) tan v and
//! integrated with the adaptive 5×5 Gauss–Legendre of `validation::quadrature::integrate`.
//! Every assertion states its absolute tolerance (1e-4), which covers the quadrature error
//! (adaptive tolerances 1e-7 absolute and 1e-6 relative per initial cell) and the f32
//! evaluations of the densities.
//!
//! One broad-lobe cross-check uses the sphere quadrature `integrate_sphere` in (cos θ, φ)
//! instead, so that the slope-space mapping is not trusted blindly.

use glam::Vec3;
use microsurface::slope::MicrosurfaceSlope;
use microsurface::{Beckmann, Ggx};
use std::f64::consts::FRAC_PI_2;
use validation::quadrature::{self, CrossMap, Domain, VisibleTolerance, integrate_sphere};

/// Roughness pairs (αx, αy) of the suite.
const ALPHAS: [(f32, f32); 5] = [(0.05, 0.05), (0.3, 0.3), (1.0, 1.0), (1.0, 0.1), (0.2, 1.5)];
/// Incident polar angles (radians); 2.0 and 2.8 are below the horizon.
const THETAS: [f64; 6] = [0.0, 0.5, 1.2, 1.55, 2.0, 2.8];
/// Adaptive tolerance of every slope-space integral (absolute, for integrals of order 1).
const QUAD_TOL: f64 = 1e-7;
/// Relative adaptive tolerance per initial cell (above the f32 rounding of the integrand).
const REL_TOL: f64 = 1e-6;
/// Maximum refinement depth of each initial cell.
const MAX_DEPTH: u32 = 8;
/// Tolerance of the assertions: the adaptive tolerances (1e-7 absolute, 1e-6 relative per
/// cell) plus the f32 rounding of the integrands, ~1e-7 relative, but up to ~1e-5 relative
/// where the Beckmann exponent (x̃² + ỹ²)/α² ≈ 85 amplifies the rounding of ωm to f32.
const ASSERT_TOL: f64 = 1e-4;

/// The incident direction of a case: isotropic roughness at φ = 0, anisotropic at φ = 0.7
/// (between the axes, so that αᵢ differs from both αx and αy).
fn incident(alpha: (f32, f32), theta: f64) -> Vec3 {
    let phi = if alpha.0 == alpha.1 { 0.0 } else { 0.7 };
    validation::dir(theta, phi)
}

/// ∫ g(ωm) dωm over the upper-hemisphere normals visible from `w` (w·ωm > 0, ωm.z > 0), in
/// slope space adapted to the slope distribution `s` (`validation::quadrature::integrate_visible`
/// with the tangent cross map, valid for any distribution). `g` gets ωm (f32, unit) and must
/// return the integrand (e.g. D(ωm) times something). Returns 0 if `w` = −z (nothing is
/// visible).
fn integrate_visible<S: MicrosurfaceSlope>(s: &S, w: Vec3, g: impl FnMut(Vec3) -> f64) -> f64 {
    let tol = VisibleTolerance { abs_tol: QUAD_TOL, rel_tol: REL_TOL, max_depth: MAX_DEPTH };
    quadrature::integrate_visible((s.alpha_x(), s.alpha_y()), CrossMap::Tangent, w, tol, g)
}

/// The ten slope distributions of the suite: GGX and Beckmann at every roughness.
fn all_slopes() -> Vec<(&'static str, Box<dyn SlopeDyn>)> {
    let mut out: Vec<(&'static str, Box<dyn SlopeDyn>)> = Vec::new();
    for a in ALPHAS {
        out.push(("ggx", Box::new(Ggx::new(a.0, a.1).unwrap())));
    }
    for a in ALPHAS {
        out.push(("beckmann", Box::new(Beckmann::new(a.0, a.1).unwrap())));
    }
    out
}

/// The object-safe subset of `MicrosurfaceSlope` used by the tests, plus the quadrature.
trait SlopeDyn {
    fn alpha(&self) -> (f32, f32);
    fn d(&self, m: Vec3) -> f32;
    fn d_wi(&self, wi: Vec3, m: Vec3) -> f32;
    fn lambda(&self, w: Vec3) -> f32;
    fn projected_area(&self, w: Vec3) -> f32;
    fn visible_integral(&self, w: Vec3, g: &mut dyn FnMut(Vec3) -> f64) -> f64;
}

impl<S: MicrosurfaceSlope> SlopeDyn for S {
    fn alpha(&self) -> (f32, f32) {
        (self.alpha_x(), self.alpha_y())
    }
    fn d(&self, m: Vec3) -> f32 {
        MicrosurfaceSlope::d(self, m)
    }
    fn d_wi(&self, wi: Vec3, m: Vec3) -> f32 {
        MicrosurfaceSlope::d_wi(self, wi, m)
    }
    fn lambda(&self, w: Vec3) -> f32 {
        MicrosurfaceSlope::lambda(self, w)
    }
    fn projected_area(&self, w: Vec3) -> f32 {
        MicrosurfaceSlope::projected_area(self, w)
    }
    fn visible_integral(&self, w: Vec3, g: &mut dyn FnMut(Vec3) -> f64) -> f64 {
        integrate_visible(self, w, g)
    }
}

/// Collects failures and panics once with all of them, so that a failing run lists every
/// failing configuration.
#[derive(Default)]
struct Failures(Vec<String>);

impl Failures {
    fn check(&mut self, ok: bool, msg: impl FnOnce() -> String) {
        if !ok {
            self.0.push(msg());
        }
    }
    fn finish(self, what: &str, cases: usize) {
        assert!(
            self.0.is_empty(),
            "{what}: {} of {cases} checks failed:\n{}",
            self.0.len(),
            self.0.join("\n")
        );
    }
}

/// Supplement §4.2.1: ∫ D_ωi(ωm) dωm = 1 for 2 slopes × 5 roughnesses × 6 incident angles.
#[test]
fn vndf_integrates_to_one_4_2_1() {
    let mut fails = Failures::default();
    let mut cases = 0;
    let mut worst = 0.0f64;
    for (name, s) in all_slopes() {
        {
            for theta in THETAS {
                let wi = incident(s.alpha(), theta);
                let integral = s.visible_integral(wi, &mut |m| f64::from(s.d_wi(wi, m)));
                cases += 1;
                worst = worst.max((integral - 1.0).abs());
                fails.check((integral - 1.0).abs() <= ASSERT_TOL, || {
                    format!(
                        "  {name} α = {:?}, θi = {theta}, ωi = {wi:?}: ∫D_ωi = {integral:.9} \
                         (|∫ − 1| > {ASSERT_TOL:.0e}; quadrature tol {QUAD_TOL:.0e}; projected area {:e})",
                        s.alpha(),
                        s.projected_area(wi)
                    )
                });
            }
        }
    }
    println!("∫D_ωi = 1: {cases} cases, worst |∫ − 1| = {worst:.2e}");
    fails.finish("∫D_ωi dωm = 1", cases);
}

/// ∫ D(ωm) cos θm dωm = 1 (the projected area towards the zenith) for every roughness.
#[test]
fn ndf_projects_to_unit_area_4_2_1() {
    let mut fails = Failures::default();
    let mut cases = 0;
    for (name, s) in all_slopes() {
        {
            let integral = s.visible_integral(Vec3::Z, &mut |m| f64::from(s.d(m)) * f64::from(m.z));
            cases += 1;
            fails.check((integral - 1.0).abs() <= ASSERT_TOL, || {
                format!(
                    "  {name} α = {:?}: ∫D cos θm = {integral:.9} (tol {ASSERT_TOL:.0e}, quadrature tol {QUAD_TOL:.0e})",
                    s.alpha()
                )
            });
        }
    }
    fails.finish("∫D cos θm dωm = 1", cases);
}

/// Directions covering the sphere: the suite's angles plus the zenith-adjacent, horizon,
/// just-below and nadir directions, at three azimuths.
fn sphere_directions() -> Vec<Vec3> {
    let thetas = [0.0, 0.2, 0.5, 1.2, 1.55, FRAC_PI_2, 1.6, 2.0, 2.8, 3.1, std::f64::consts::PI];
    let mut out = Vec::new();
    for t in thetas {
        for phi in [0.0, 0.7, 2.5] {
            out.push(validation::dir(t, phi));
        }
    }
    out
}

/// projected_area(ω) = ∫ max(0, ω·ωm) D(ωm) dωm for ω everywhere on the sphere (with ω = +z
/// this is ∫G1⟨ωo,ωm⟩D = cos θo, the supplement's §4.2.1 identity for ωo up); this is the
/// definition that holds below the horizon, where (1 + Λ) cos θ is a product of two negative
/// factors.
#[test]
fn projected_area_is_the_visible_integral() {
    let mut fails = Failures::default();
    let mut cases = 0;
    let mut worst = 0.0f64;
    for (name, s) in all_slopes() {
        {
            for w in sphere_directions() {
                let integral =
                    s.visible_integral(w, &mut |m| f64::from(w.dot(m).max(0.0)) * f64::from(s.d(m)));
                let area = f64::from(s.projected_area(w));
                let err = (integral - area).abs();
                cases += 1;
                worst = worst.max(err);
                // absolute tolerance, plus a relative one where the area is far from 0 but
                // still an f32 normal number (below 1e-30 the f32 D loses relative precision)
                let rel_ok = area < 1e-30 || err <= 1e-4 * area;
                fails.check(err <= ASSERT_TOL && rel_ok, || {
                    format!(
                        "  {name} α = {:?}, ω = {w:?}: projected_area = {area:.9e}, ∫max(0,ω·m)D = {integral:.9e} \
                         (tol {ASSERT_TOL:.0e} absolute, 1e-4 relative)",
                        s.alpha()
                    )
                });
                if w == Vec3::Z {
                    fails.check((integral - 1.0).abs() <= ASSERT_TOL, || {
                        format!("  {name} α = {:?}: ∫G1⟨z,m⟩D = {integral:.9} ≠ cos θo = 1", s.alpha())
                    });
                }
            }
        }
    }
    println!("projected area = ∫max(0, ω·m)D: {cases} directions, worst |error| = {worst:.2e}");
    fails.finish("projected area", cases);
}

/// projected_area(ω) = (1 + Λ(ω)) cos θ, with a tolerance that follows the conditioning of
/// 1 + Λ in f32 (Λ is rounded to ~6e-8 relative, so 1 + Λ carries an absolute error of about
/// 6e-8 (1 + |Λ|)).
#[test]
fn projected_area_matches_lambda() {
    let mut fails = Failures::default();
    let mut cases = 0;
    for (name, s) in all_slopes() {
        {
            for w in sphere_directions() {
                let (area, lambda) = (f64::from(s.projected_area(w)), f64::from(s.lambda(w)));
                let z = f64::from(w.z);
                if z.abs() < 1e-3 {
                    continue; // (1 + Λ) cos θ is ∞ × 0 at the horizon: ill-conditioned
                }
                let via_lambda = (1.0 + lambda) * z;
                let tol = 1e-6 * (1.0 + lambda.abs()) * z.abs() + 1e-6 * area;
                cases += 1;
                fails.check((area - via_lambda).abs() <= tol, || {
                    format!(
                        "  {name} α = {:?}, ω = {w:?}: projected_area = {area:.9e}, (1+Λ)cos θ = {via_lambda:.9e}, \
                         Λ = {lambda:e} (tol {tol:.1e})",
                        s.alpha()
                    )
                });
            }
        }
    }
    fails.finish("projected_area = (1 + Λ) cos θ", cases);
}

/// Λ(−ω) = −1 − Λ(ω) on the whole sphere.
#[test]
fn lambda_antisymmetry() {
    let mut fails = Failures::default();
    let mut cases = 0;
    for (name, s) in all_slopes() {
        {
            for w in sphere_directions() {
                let (l, lm) = (f64::from(s.lambda(w)), f64::from(s.lambda(-w)));
                let tol = 4e-7 * (1.0 + l.abs());
                cases += 1;
                fails.check((lm - (-1.0 - l)).abs() <= tol, || {
                    format!(
                        "  {name} α = {:?}, ω = {w:?}: Λ(ω) = {l:e}, Λ(−ω) = {lm:e}, −1 − Λ(ω) = {:e} (tol {tol:.1e})",
                        s.alpha(),
                        -1.0 - l
                    )
                });
            }
        }
    }
    fails.finish("Λ(−ω) = −1 − Λ(ω)", cases);
}

/// An independent cross-check of the slope-space quadrature: for broad lobes the plain
/// sphere quadrature in (cos θ, φ) (adaptive, 16 × 32 cells, tolerance 1e-6, depth 8) also
/// integrates D_ωi to 1 and D cos θm to 1 within 1e-4.
#[test]
fn sphere_quadrature_cross_check() {
    let mut fails = Failures::default();
    let mut cases = 0;
    let mut worst = 0.0f64;
    let slopes: Vec<Box<dyn SlopeDyn>> = vec![
        Box::new(Ggx::new(0.3, 0.3).unwrap()),
        Box::new(Ggx::new(1.0, 1.0).unwrap()),
        Box::new(Beckmann::new(1.0, 1.0).unwrap()),
        Box::new(Beckmann::new(0.2, 1.5).unwrap()),
    ];
    for s in &slopes {
        for theta in [0.0, 1.2, 2.0] {
            let wi = incident(s.alpha(), theta);
            let integral =
                integrate_sphere(&mut |m| f64::from(s.d_wi(wi, m)), 16, 32, Domain::UpperHemisphere, 1e-6, 8);
            let ndf = integrate_sphere(
                &mut |m| f64::from(s.d(m)) * f64::from(m.z),
                16,
                32,
                Domain::UpperHemisphere,
                1e-6,
                8,
            );
            cases += 2;
            worst = worst.max((integral - 1.0).abs()).max((ndf - 1.0).abs());
            fails.check((integral - 1.0).abs() <= 1e-4 && (ndf - 1.0).abs() <= 1e-4, || {
                format!(
                    "  α = {:?}, θi = {theta}: sphere quadrature ∫D_ωi = {integral:.8}, ∫D cos = {ndf:.8} (tol 1e-4)",
                    s.alpha()
                )
            });
        }
    }
    println!("sphere-quadrature cross-check: worst |∫ − 1| = {worst:.2e}");
    fails.finish("sphere quadrature cross-check", cases);
}
