//! Negative zero is treated exactly like positive zero.
//!
//! For every slope (GGX and Beckmann, isotropic and anisotropic) and every public function of
//! the slopes, the visible-normal samplers, the V-cavity model, the geometry's masking, the
//! materials and the orthonormal basis: every direction (and normal) with a zero component is
//! evaluated with each combination of signs of its zero components, and the results must be
//! finite and bit-identical to those with all zeros positive. Sampled vectors are compared
//! after adding +0 to each component (which maps −0 to +0 and changes nothing else): a sampled
//! direction whose x is −0 instead of +0 is the same direction.
//!
//! Before the fix `Ggx::lambda((1, 0, −0))` was −∞ (against `f32::MAX` at +0), the GGX masking
//! and the materials built on it followed, and the orthonormal basis of a normal with n.z = −0
//! was the one of the lower hemisphere.

use glam::{Vec2, Vec3};
use microsurface::research::{Interaction, Side};
use microsurface::research::{Material, MicrosurfaceGeometry, UniformHeight, orthonormal_basis};
use microsurface::slope::MicrosurfaceSlope;
use microsurface::vndf::{
    BeckmannNewton, GgxBoundedCap, GgxDisk, GgxSphericalCap, SmithVndf, VCavity, VCavitySlope,
    VisibleNormalSampler, smith_normalization,
};
use microsurface::{Beckmann, Conductor, Dielectric, Diffuse, Ggx};
use rand::SeedableRng;

type Rng = rand_pcg::Pcg64Mcg;

/// Unit directions with at least one zero component (horizon, poles, the coordinate planes).
fn directions() -> Vec<Vec3> {
    let s = std::f32::consts::FRAC_1_SQRT_2;
    vec![
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(-1.0, 0.0, 0.0),
        Vec3::new(0.0, 1.0, 0.0),
        Vec3::new(0.0, -1.0, 0.0),
        Vec3::new(0.6, 0.8, 0.0),
        Vec3::new(-0.8, 0.6, 0.0),
        Vec3::new(0.0, 0.0, 1.0),
        Vec3::new(0.0, 0.0, -1.0),
        Vec3::new(0.0, 0.6, 0.8),
        Vec3::new(0.6, 0.0, 0.8),
        Vec3::new(0.0, -0.8, -0.6),
        Vec3::new(-0.8, 0.0, -0.6),
        Vec3::new(s, 0.0, s),
        Vec3::new(0.0, s, -s),
    ]
}

/// Every variant of `v` obtained by flipping the sign of some of its zero components (the
/// first is `v` itself, with all zeros positive).
fn zero_sign_variants(v: Vec3) -> Vec<Vec3> {
    let c = v.to_array();
    let zeros: Vec<usize> = (0..3).filter(|&k| c[k] == 0.0).collect();
    (0..1usize << zeros.len())
        .map(|mask| {
            let mut a = c.map(|x| if x == 0.0 { 0.0 } else { x });
            for (bit, &k) in zeros.iter().enumerate() {
                if mask >> bit & 1 == 1 {
                    a[k] = -0.0;
                }
            }
            Vec3::from_array(a)
        })
        .collect()
}

/// Canonical bits of a result: +0 added (−0 ↦ +0), then the raw bits.
fn bits(values: &[f32]) -> Vec<u32> {
    values.iter().map(|&x| (x + 0.0).to_bits()).collect()
}

/// Checks that `f` is finite and identical (up to the sign of zero results, see the module
/// doc) on every zero-sign variant of its arguments; scalars are compared with their sign of
/// zero, since a scalar −0 where +0 is expected is already a difference of the formula.
struct Checker {
    failures: Vec<String>,
    checked: usize,
}

impl Checker {
    fn new() -> Self {
        Self { failures: Vec::new(), checked: 0 }
    }

    fn compare(&mut self, name: &str, args: &str, reference: &[f32], got: &[f32], strict: bool) {
        self.checked += 1;
        let same = if strict {
            reference.iter().map(|x| x.to_bits()).eq(got.iter().map(|x| x.to_bits()))
        } else {
            bits(reference) == bits(got)
        };
        if !same || got.iter().any(|x| !x.is_finite()) {
            self.failures.push(format!("{name}({args}) = {got:?}, with +0 components {reference:?}"));
        }
    }

    /// A scalar function of one direction.
    fn scalar1(&mut self, name: &str, w: Vec3, f: impl Fn(Vec3) -> f32) {
        let variants = zero_sign_variants(w);
        let reference = f(variants[0]);
        for &v in &variants {
            self.compare(name, &format!("{v:?}"), &[reference], &[f(v)], true);
        }
    }

    /// A scalar function of two directions.
    fn scalar2(&mut self, name: &str, a: Vec3, b: Vec3, f: impl Fn(Vec3, Vec3) -> f32) {
        let (va, vb) = (zero_sign_variants(a), zero_sign_variants(b));
        let reference = f(va[0], vb[0]);
        for &x in &va {
            for &y in &vb {
                self.compare(name, &format!("{x:?}, {y:?}"), &[reference], &[f(x, y)], true);
            }
        }
    }

    /// A vector-valued function of one direction (sampled directions: zero signs canonicalized).
    fn vector1(&mut self, name: &str, w: Vec3, f: impl Fn(Vec3) -> Vec<f32>) {
        let variants = zero_sign_variants(w);
        let reference = f(variants[0]);
        for &v in &variants {
            self.compare(name, &format!("{v:?}"), &reference, &f(v), false);
        }
    }

    fn finish(self) {
        eprintln!("{} comparisons, {} failures", self.checked, self.failures.len());
        assert!(self.checked > 1000, "only {} comparisons", self.checked);
        assert!(self.failures.is_empty(), "{} failures:\n{}", self.failures.len(), self.failures.join("\n"));
    }
}

const UNIFORMS: [(f32, f32); 4] = [(0.0, 0.0), (0.3, 0.7), (0.5, 0.5), (0.999, 0.123)];

/// The stretched-space primitive of the axis-aligned slopes (an inherent method of each).
trait StretchedSampler {
    fn p22_11(&self, cos_theta: f32, sin_theta: f32, u1: f32, u2: f32) -> Vec2;
}

impl StretchedSampler for Ggx {
    fn p22_11(&self, cos_theta: f32, sin_theta: f32, u1: f32, u2: f32) -> Vec2 {
        self.sample_p22_11(cos_theta, sin_theta, u1, u2)
    }
}

impl StretchedSampler for Beckmann {
    fn p22_11(&self, cos_theta: f32, sin_theta: f32, u1: f32, u2: f32) -> Vec2 {
        self.sample_p22_11(cos_theta, sin_theta, u1, u2)
    }
}

fn check_slope<S: MicrosurfaceSlope + VCavitySlope + StretchedSampler>(
    c: &mut Checker,
    name: &str,
    slope: S,
) {
    for w in directions() {
        c.scalar1(&format!("{name}.lambda"), w, |w| slope.lambda(w));
        c.scalar1(&format!("{name}.projected_area"), w, |w| slope.projected_area(w));
        c.scalar1(&format!("{name}.d"), w, |w| slope.d(w));
        c.scalar1(&format!("{name}.d64"), w, |w| slope.d64(w.as_dvec3()) as f32);
        c.scalar1(&format!("{name}.alpha_i"), w, |w| slope.alpha_i(w));
        c.scalar1(&format!("{name}.hit_probability"), w, |w| slope.hit_probability(w));
        c.scalar1(&format!("{name}.frontfacing_proportion"), w, |w| slope.frontfacing_proportion(w));
        if w.z <= 0.0 {
            // documented for backfacing directions only (the horizon included)
            c.scalar1(&format!("{name}.projected_branch_probability"), w, |w| {
                slope.projected_branch_probability(w) as f32
            });
        }
        // ln H and ln D are −∞ where H and D vanish: compare them through exp
        c.scalar1(&format!("{name}.ln_hit_probability"), w, |w| slope.ln_hit_probability(w).exp() as f32);
        c.scalar1(&format!("{name}.ln_d"), w, |w| slope.ln_d(w).exp() as f32);
        let geometry = MicrosurfaceGeometry::new(UniformHeight, slope);
        c.scalar1(&format!("{name}.g1"), w, |w| geometry.g1(w));
        c.scalar1(&format!("{name}.g1_at"), w, |w| geometry.g1_at(w, 0.25));
        for wm in directions() {
            c.scalar2(&format!("{name}.d_wi"), w, wm, |a, b| slope.d_wi(a, b));
            c.scalar2(&format!("{name}.d_wi64"), w, wm, |a, b| slope.d_wi64(a, b.as_dvec3()) as f32);
            c.scalar2(&format!("smith_normalization<{name}>"), w, wm, |a, b| {
                smith_normalization(&slope, a, b)
            });
            c.scalar2(&format!("VCavity<{name}>.masking"), w, wm, |a, b| VCavity(slope).masking(a, b));
            c.scalar2(&format!("VCavity<{name}>.pdf"), w, wm, |a, b| VCavity(slope).pdf(a, b));
            c.scalar2(&format!("SmithVndf<{name}>.pdf"), w, wm, |a, b| SmithVndf(slope).pdf(a, b));
        }
        for (u1, u2) in UNIFORMS {
            c.vector1(&format!("{name}.sample_d_wi(·, {u1}, {u2})"), w, |w| {
                slope.sample_d_wi(w, u1, u2).to_array().to_vec()
            });
            c.vector1(&format!("SmithVndf<{name}>.sample(·, {u1}, {u2})"), w, |w| {
                SmithVndf(slope).sample(w, [u1, u2, 0.5]).to_array().to_vec()
            });
            for u3 in [0.0, 0.6] {
                c.vector1(&format!("VCavity<{name}>.sample(·, {u1}, {u2}, {u3})"), w, |w| {
                    VCavity(slope).sample(w, [u1, u2, u3]).to_array().to_vec()
                });
            }
            if w.z < 0.0 {
                // k on the lower side: the V-cavity's boundary planes
                c.vector1(&format!("{name}.sample_unmasked(·, {u1}, {u2})"), w, |w| {
                    let k = Vec3::new(w.x, w.y, 3.0 * w.z);
                    slope.sample_unmasked(w, k, u1, u2).to_array().to_vec()
                });
            }
            c.vector1(&format!("{name}.sample_projected(·, {u1}, {u2})"), w, |k| {
                slope.sample_projected(k, u1, u2).to_array().to_vec()
            });
        }
        check_materials(c, name, slope, w);
    }
    // sample_p22_11 takes (cos θ, sin θ): cos θ = ±0 at the horizon, sin θ = ±0 at the poles
    for (cos_theta, sin_theta) in [(0.0, 1.0), (1.0, 0.0), (-1.0, 0.0)] {
        for (u1, u2) in UNIFORMS {
            let reference = slope.p22_11(cos_theta, sin_theta, u1, u2);
            for (cv, sv) in [(-cos_theta, sin_theta), (cos_theta, -sin_theta)] {
                let (cv, sv) =
                    (if cv == 0.0 { cv } else { cos_theta }, if sv == 0.0 { sv } else { sin_theta });
                let got = slope.p22_11(cv, sv, u1, u2);
                c.compare(
                    &format!("{name}.sample_p22_11"),
                    &format!("{cv:?}, {sv:?}, {u1}, {u2}"),
                    &reference.to_array(),
                    &got.to_array(),
                    false,
                );
            }
        }
    }
    // p22 of ±0 slopes
    for s in [Vec2::new(0.0, 0.0), Vec2::new(0.0, 1.5), Vec2::new(-2.0, 0.0)] {
        c.scalar1(&format!("{name}.p22"), s.extend(0.0), |v| slope.p22(v.x, v.y));
    }
}

/// The materials' evaluations and samplers, for ωi = `w` and every other test direction.
fn check_materials<S: MicrosurfaceSlope>(c: &mut Checker, name: &str, slope: S, w: Vec3) {
    fn one<S: MicrosurfaceSlope, M: Material>(c: &mut Checker, name: &str, slope: S, m: M, w: Vec3) {
        for wo in directions() {
            for (wi_out, wo_out) in [(true, true), (true, false), (false, true), (false, false)] {
                let rng = || Rng::seed_from_u64(3);
                c.scalar2(&format!("{name}.eval_phase[{wi_out},{wo_out}]"), w, wo, |a, b| {
                    m.eval_phase(&slope, &Interaction::new(a, b, side(wi_out), side(wo_out)), &mut rng()).x
                });
                c.scalar2(&format!("{name}.pdf_phase[{wi_out},{wo_out}]"), w, wo, |a, b| {
                    m.pdf_phase(&slope, &Interaction::new(a, b, side(wi_out), side(wo_out)))
                });
                c.scalar2(&format!("{name}.vertex[{wi_out},{wo_out}]"), w, wo, |a, b| {
                    m.vertex(&slope, &Interaction::new(a, b, side(wi_out), side(wo_out)), &mut rng()).x
                });
                c.scalar2(&format!("{name}.connection[{wi_out},{wo_out}]"), w, wo, |a, b| {
                    let (v, p, q) =
                        m.connection(&slope, &Interaction::new(a, b, side(wi_out), side(wo_out)), &mut rng());
                    v.x + 2.0 * p + 3.0 * q
                });
            }
            c.scalar2(&format!("{name}.eval_single_scattering"), w, wo, |a, b| {
                m.eval_single_scattering(&slope, a, b, &mut Rng::seed_from_u64(5)).x
            });
        }
        for outside in [true, false] {
            for seed in 0..4 {
                c.vector1(&format!("{name}.sample_phase[{outside}] seed {seed}"), w, |a| {
                    let s = m.sample_phase(&slope, a, side(outside), &mut Rng::seed_from_u64(seed));
                    let mut v = s.wo.to_array().to_vec();
                    v.extend(s.weight.to_array());
                    v.push(f32::from(u8::from(s.side == Side::Outside)));
                    v
                });
            }
        }
    }
    one(c, &format!("Conductor<{name}>"), slope, Conductor::perfect(), w);
    one(c, &format!("Dielectric<{name}>"), slope, Dielectric::new(1.5).unwrap(), w);
    one(c, &format!("Diffuse<{name}>"), slope, Diffuse::white(), w);
}

#[test]
fn ggx_lambda_at_negative_zero_is_the_saturated_positive_value() {
    let ggx = Ggx::isotropic(0.5).unwrap();
    assert_eq!(ggx.lambda(Vec3::new(1.0, 0.0, -0.0)), f32::MAX);
    assert_eq!(ggx.lambda(Vec3::new(1.0, 0.0, 0.0)), f32::MAX);
    let beckmann = Beckmann::isotropic(0.5).unwrap();
    assert_eq!(beckmann.lambda(Vec3::new(1.0, 0.0, -0.0)), f32::MAX);
}

#[test]
fn every_slope_function_treats_negative_zero_like_positive_zero() {
    let mut c = Checker::new();
    for (ax, ay) in [(0.5, 0.5), (1.0, 0.1), (0.05, 2.0)] {
        check_slope(&mut c, &format!("Ggx({ax}, {ay})"), Ggx::new(ax, ay).unwrap());
        check_slope(&mut c, &format!("Beckmann({ax}, {ay})"), Beckmann::new(ax, ay).unwrap());
    }
    c.finish();
}

#[test]
fn named_samplers_treat_negative_zero_like_positive_zero() {
    let mut c = Checker::new();
    for (ax, ay) in [(0.5, 0.5), (1.0, 0.1), (0.05, 2.0)] {
        let ggx = Ggx::new(ax, ay).unwrap();
        let beckmann = Beckmann::new(ax, ay).unwrap();
        for w in directions() {
            for (u1, u2) in UNIFORMS {
                let u = [u1, u2, 0.5];
                c.vector1("GgxSphericalCap.sample", w, |w| {
                    GgxSphericalCap(ggx).sample(w, u).to_array().to_vec()
                });
                c.vector1("GgxBoundedCap.sample", w, |w| GgxBoundedCap(ggx).sample(w, u).to_array().to_vec());
                c.vector1("GgxDisk.sample", w, |w| GgxDisk(ggx).sample(w, u).to_array().to_vec());
                c.vector1("BeckmannNewton.sample", w, |w| {
                    BeckmannNewton(beckmann).sample(w, u).to_array().to_vec()
                });
            }
            for wm in directions() {
                c.scalar2("GgxSphericalCap.pdf", w, wm, |a, b| GgxSphericalCap(ggx).pdf(a, b));
                c.scalar2("GgxBoundedCap.pdf", w, wm, |a, b| GgxBoundedCap(ggx).pdf(a, b));
                c.scalar2("GgxDisk.pdf", w, wm, |a, b| GgxDisk(ggx).pdf(a, b));
                c.scalar2("BeckmannNewton.pdf", w, wm, |a, b| BeckmannNewton(beckmann).pdf(a, b));
            }
        }
    }
    // the frame of a normal on the horizon
    for n in directions() {
        c.vector1("orthonormal_basis", n, |n| {
            let (t, b) = orthonormal_basis(n);
            [t.to_array(), b.to_array()].concat()
        });
    }
    c.finish();
}

/// The side of the interface for the test tables' `outside` flags.
fn side(outside: bool) -> Side {
    if outside { Side::Outside } else { Side::Inside }
}
