//! The batch calls (`BatchBsdf`) against the scalar calls they stand for, query by query: over
//! views and lights on the whole sphere (grazing down to cos θ = 1e-6, backfacing views), GGX
//! roughness from 2e-3 to 10 (isotropic and anisotropic), gold, a perfect mirror and glass of
//! η = 1.5, 1/1.5 and 1.33, and glass reflections near the critical angle; the compensated lobes
//! (gold, copper and glass, every scheme, GGX, Beckmann and Dirac lobes); invalid and drifted
//! lanes mixed with valid ones; slices of unequal length.

use microsurface::glam::{Vec2, Vec3};
use microsurface::{
    BatchBsdf, Beckmann, Channels, Compensated, Compensation, ComplexIor, Conductor, Dielectric, Directions,
    Error, Ggx, MicrofacetBsdf, SampleOutputs, Technique,
};
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64Mcg;

/// Queries per configuration (not a multiple of 8: the scalar tail is exercised too).
const N: usize = 4099;

/// A direction: uniform on the sphere, or grazing (|cos θ| = 10⁻ᵏ, k = 1…6) one time in four.
fn direction(rng: &mut Pcg64Mcg, upper: bool) -> Vec3 {
    let z = if rng.random::<f32>() < 0.25 {
        10f32.powi(-(1 + rng.random_range(0..6)))
    } else {
        1.0 - rng.random::<f32>()
    };
    let z = if !upper && rng.random::<bool>() { -z } else { z };
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = core::f32::consts::TAU * rng.random::<f32>();
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

struct Soa {
    x: Vec<f32>,
    y: Vec<f32>,
    z: Vec<f32>,
}

impl Soa {
    fn of(v: &[Vec3]) -> Self {
        Self {
            x: v.iter().map(|w| w.x).collect(),
            y: v.iter().map(|w| w.y).collect(),
            z: v.iter().map(|w| w.z).collect(),
        }
    }
    fn dirs(&self) -> Directions<'_> {
        Directions::new(&self.x, &self.y, &self.z).expect("equal lengths")
    }
}

struct Out {
    a: Vec<f32>,
    b: Vec<f32>,
    c: Vec<f32>,
}

impl Out {
    fn new(n: usize) -> Self {
        Self { a: vec![-1.0; n], b: vec![-1.0; n], c: vec![-1.0; n] }
    }
    fn channels(&mut self) -> Channels<'_> {
        Channels::new(&mut self.a, &mut self.b, &mut self.c)
    }
    fn get(&self, i: usize) -> Vec3 {
        Vec3::new(self.a[i], self.b[i], self.c[i])
    }
}

/// The largest relative error of `b` against `s` beyond an absolute allowance `abs` (per
/// component), as (worst excess ratio, where).
fn excess(b: Vec3, s: Vec3, rel: f32, abs: f32) -> f32 {
    let mut worst = 0.0f32;
    for k in 0..3 {
        let (b, s) = (b[k], s[k]);
        let bound = rel * s.abs() + abs;
        worst = worst.max(if b == s { 0.0 } else { (b - s).abs() / bound });
    }
    worst
}

/// Views (upper or whole sphere) and lights (whole sphere).
fn queries(seed: u64, views_upper: bool) -> (Vec<Vec3>, Vec<Vec3>) {
    let mut rng = Pcg64Mcg::seed_from_u64(seed);
    let wo = (0..N).map(|_| direction(&mut rng, views_upper)).collect();
    let wi = (0..N).map(|_| direction(&mut rng, false)).collect();
    (wo, wi)
}

/// The bounds of a batch call against the scalar call: f within `rel`·|f| + `abs`·F for a
/// reflection and `transmit_rel`·|f| + (`abs` + `pdf_abs`/pdf)·F for a transmission (F the
/// largest channel of the scalar f, so `abs` is relative to the lobe's size at that query; a
/// transmission's f is its density times the shadowing, so the density's absolute allowance
/// carries over), the density within `pdf_rel`·pdf + `pdf_abs` (all 0: bit for bit).
#[derive(Clone, Copy)]
struct Bounds {
    rel: f32,
    transmit_rel: f32,
    abs: f32,
    pdf_rel: f32,
    pdf_abs: f32,
}

impl Bounds {
    const EXACT: Self = Self { rel: 0.0, transmit_rel: 0.0, abs: 0.0, pdf_rel: 0.0, pdf_abs: 0.0 };
}

/// Batch eval, pdf and eval_with_pdf against the scalar calls within `bounds`.
fn check_eval<B: BatchBsdf>(label: &str, bsdf: &B, seed: u64, bounds: Bounds) {
    let Bounds { rel, transmit_rel, abs, pdf_rel, pdf_abs } = bounds;
    for views_upper in [true, false] {
        let (wo, wi) = queries(seed, views_upper);
        let (so, si) = (Soa::of(&wo), Soa::of(&wi));
        let (mut f, mut f2, mut pdf, mut pdf2) = (Out::new(N), Out::new(N), vec![-1.0; N], vec![-1.0; N]);
        bsdf.eval_batch(&so.dirs(), &si.dirs(), &mut f.channels()).expect("lengths");
        bsdf.pdf_batch(&so.dirs(), &si.dirs(), &mut pdf).expect("lengths");
        bsdf.eval_with_pdf_batch(&so.dirs(), &si.dirs(), &mut f2.channels(), &mut pdf2).expect("lengths");
        let (mut worst_f, mut worst_t, mut worst_pdf, mut nonzero) = (0.0f32, 0.0f32, 0.0f32, 0);
        for i in 0..N {
            let value = bsdf.eval(wo[i], wi[i]).f;
            let density = bsdf.pdf(wo[i], wi[i]);
            let (value2, density2) = bsdf.eval_with_pdf(wo[i], wi[i]);
            let transmits = wo[i].z * wi[i].z < 0.0;
            // a transmission's f is its density times a factor: the density's absolute allowance
            // carried over, pdf_abs·f/pdf
            let carried = if transmits && density > 0.0 { pdf_abs / density } else { 0.0 };
            let scale = (abs + carried) * value.max_element();
            let rel = if transmits { transmit_rel } else { rel };
            for (b, s) in [(f.get(i), value), (f2.get(i), value2.f)] {
                let e = excess(b, s, rel, scale);
                assert!(
                    e <= 1.0,
                    "{label}: f({}, {}) = {b} in the batch, {s} scalar (bound {rel}·|f| + {scale})",
                    wo[i],
                    wi[i]
                );
                let error =
                    if s == Vec3::ZERO { 0.0 } else { ((b - s).abs() / s.max_element()).max_element() };
                if transmits {
                    worst_t = worst_t.max(error);
                } else {
                    worst_f = worst_f.max(error);
                }
            }
            for (b, s) in [(pdf[i], density), (pdf2[i], density2)] {
                let bound = pdf_rel * s + pdf_abs;
                assert!(
                    b == s || (b - s).abs() <= bound,
                    "{label}: pdf({}, {}) = {b} in the batch, {s} scalar",
                    wo[i],
                    wi[i]
                );
                worst_pdf = worst_pdf.max(if s > 0.0 { (b - s).abs() / s } else { 0.0 });
            }
            nonzero += usize::from(value != Vec3::ZERO);
        }
        eprintln!(
            "{label} (views {}): f rel. error ≤ {worst_f:.2e} (reflection), {worst_t:.2e} (transmission), pdf rel. error ≤ {worst_pdf:.2e}, {nonzero} of {N} nonzero",
            if views_upper { "above" } else { "whole sphere" }
        );
        assert!(nonzero > N / 8, "{label}: only {nonzero} nonzero values compared");
    }
}

/// Batch samples against the scalar samples: the direction and η bit for bit, the weight within
/// `rel` relative, the density within `pdf_rel`·pdf + `pdf_abs` (0: bit for bit).
fn check_sample<B: BatchBsdf>(label: &str, bsdf: &B, seed: u64, rel: f32, pdf_rel: f32, pdf_abs: f32) {
    let (wo, _) = queries(seed, false);
    let mut rng = Pcg64Mcg::seed_from_u64(seed + 7);
    let uc: Vec<f32> = (0..N).map(|_| rng.random()).collect();
    let u1: Vec<f32> = (0..N).map(|_| rng.random()).collect();
    let u2: Vec<f32> = (0..N).map(|_| rng.random()).collect();
    let so = Soa::of(&wo);
    let (mut w, mut weight, mut pdf, mut eta) = (Out::new(N), Out::new(N), vec![-1.0; N], vec![-1.0; N]);
    let mut out = SampleOutputs { wi: w.channels(), weight: weight.channels(), pdf: &mut pdf, eta: &mut eta };
    bsdf.sample_batch(&so.dirs(), &uc, &u1, &u2, &mut out).expect("lengths");
    let (mut some, mut worst_weight, mut worst_pdf) = (0, 0.0f32, 0.0f32);
    for i in 0..N {
        let s = bsdf.sample(wo[i], uc[i], Vec2::new(u1[i], u2[i]));
        match s {
            None => assert!(
                pdf[i] == 0.0 && w.get(i) == Vec3::ZERO && weight.get(i) == Vec3::ZERO && eta[i] == 1.0,
                "{label}: no scalar sample for {}, the batch has pdf {}",
                wo[i],
                pdf[i]
            ),
            Some(s) => {
                some += 1;
                let ok = w.get(i) == s.wi
                    && eta[i] == s.eta
                    && excess(weight.get(i), s.weight, rel, 0.0) <= 1.0
                    && (pdf[i] == s.pdf || (pdf[i] - s.pdf).abs() <= pdf_rel * s.pdf + pdf_abs);
                worst_weight = worst_weight.max(((weight.get(i) - s.weight).abs() / s.weight).max_element());
                worst_pdf = worst_pdf.max((pdf[i] - s.pdf).abs() / s.pdf);
                assert!(
                    ok,
                    "{label}: sample of {} = {:?}, batch ({}, {}, {})",
                    wo[i],
                    s,
                    w.get(i),
                    weight.get(i),
                    pdf[i]
                );
            }
        }
    }
    eprintln!("{label}: sample weight rel. error ≤ {worst_weight:.2e}, pdf rel. error ≤ {worst_pdf:.2e}");
    assert!(some > N / 4, "{label}: only {some} samples compared");
}

fn single<
    S: microsurface::slope::MicrosurfaceSlope,
    M: microsurface::research::Material + microsurface::research::SpecularLimit,
>(
    slope: S,
    material: M,
) -> MicrofacetBsdf<S, M> {
    MicrofacetBsdf::new(slope, material).expect("valid roughness").with_technique(Technique::SingleScattering)
}

/// Conductors: densities and samples bit for bit; f within 2e-5 relative plus 4e-6 of the
/// value's largest channel (the scalar f forms D, Λ and G2 in f64, the lanes in f32).
#[test]
fn conductor_batches_are_the_scalar_calls() {
    let gold = Conductor::new(ComplexIor::GOLD);
    for (k, (ax, ay)) in [(2e-3f32, 2e-3f32), (0.05, 0.05), (0.5, 0.5), (0.3, 0.02), (2.0, 0.7), (10.0, 10.0)]
        .into_iter()
        .enumerate()
    {
        let slope = Ggx::new(ax, ay).expect("valid roughness");
        let seed = 100 + k as u64;
        let bounds = Bounds { rel: 4e-6, transmit_rel: 4e-6, abs: 1e-6, ..Bounds::EXACT };
        check_eval(&format!("gold GGX ({ax}, {ay})"), &single(slope, gold), seed, bounds);
        check_eval(&format!("mirror GGX ({ax}, {ay})"), &single(slope, Conductor::perfect()), seed, bounds);
        check_sample(&format!("gold GGX ({ax}, {ay})"), &single(slope, gold), seed, 0.0, 0.0, 0.0);
        let mirror = single(slope, Conductor::perfect());
        check_sample(&format!("mirror GGX ({ax}, {ay})"), &mirror, seed, 0.0, 0.0, 0.0);
    }
}

/// The bounds of a GGX dielectric's batch calls: reflection f within 2e-5 relative plus 4e-6 of
/// the value; densities within 1e-4 relative plus 1e-6 absolute; transmission f within 1.5e-4
/// relative (the density's 1e-4 and the lane beta function's 4e-7·(1 + |ln B|) + 3 ulps for
/// ln B ≥ −87, at most 3.6e-5, plus Λ in f32) plus (4e-6 + 1e-6/pdf) of the value.
const GLASS: Bounds = Bounds { rel: 2e-5, transmit_rel: 1.5e-4, abs: 4e-6, pdf_rel: 1e-4, pdf_abs: 1e-6 };

/// The bound of a GGX dielectric's sample weights: G2/G1 of a reflection in f32 (a few ulps), of
/// a transmission the lane beta function's 4e-7·(1 + |ln B|) + 3 ulps for ln B ≥ −87, plus Λ in
/// f32.
const GLASS_WEIGHT_REL: f32 = 5e-5;

/// Dielectrics: f and densities within [`GLASS`]; samples with the scalar's direction, event
/// and η bit for bit, the weight within [`GLASS_WEIGHT_REL`], the density within [`GLASS`].
#[test]
fn dielectric_batches_are_the_scalar_calls() {
    for (k, eta) in [1.5f32, 1.0 / 1.5, 1.33].into_iter().enumerate() {
        let glass = Dielectric::new(eta).expect("valid index");
        for (j, (ax, ay)) in [(2e-3f32, 2e-3f32), (0.5, 0.5), (0.3, 0.02), (2.0, 0.7)].into_iter().enumerate()
        {
            let slope = Ggx::new(ax, ay).expect("valid roughness");
            let seed = 200 + 10 * k as u64 + j as u64;
            let bsdf = single(slope, glass);
            check_eval(&format!("glass η = {eta}, GGX ({ax}, {ay})"), &bsdf, seed, GLASS);
            check_sample(
                &format!("glass η = {eta}, GGX ({ax}, {ay})"),
                &bsdf,
                seed,
                GLASS_WEIGHT_REL,
                GLASS.pdf_rel,
                GLASS.pdf_abs,
            );
        }
    }
}

/// Reflections of glass seen from the denser side (η = 1/1.5, 1/1.33, 1/2.5) at facet cosines
/// within 10⁻⁶ to 10⁻¹ of the critical angle, on both sides of it (F has an infinite slope
/// there): within [`GLASS`].
#[test]
fn dielectric_reflections_near_the_critical_angle() {
    use microsurface::Bsdf;
    for (k, eta) in [1.0f32 / 1.5, 1.0 / 1.33, 1.0 / 2.5].into_iter().enumerate() {
        let mut rng = Pcg64Mcg::seed_from_u64(250 + k as u64);
        let critical = (1.0 - eta * eta).sqrt();
        let (mut wo, mut wi) = (Vec::with_capacity(N), Vec::with_capacity(N));
        while wo.len() < N {
            // a facet normal and a view at cos θ = critical ± 10⁻ʲ from it, in the facet's plane
            // of incidence, and its mirror image
            let h = direction(&mut rng, true);
            let offset = 10f32.powf(-1.0 - 5.0 * rng.random::<f32>());
            let c = (critical + if rng.random::<bool>() { offset } else { -offset }).min(1.0);
            let t = h.any_orthonormal_vector();
            let phi = core::f32::consts::TAU * rng.random::<f32>();
            let (b, tangent) = (h.cross(t), t);
            let side = tangent * phi.cos() + b * phi.sin();
            let o = (h * c + side * (1.0 - c * c).max(0.0).sqrt()).normalize();
            let i = (h * (2.0 * o.dot(h)) - o).normalize();
            if o.z > 0.0 && i.z > 0.0 {
                wo.push(o);
                wi.push(i);
            }
        }
        for (ax, ay) in [
            (1e-37f32, 0.5f32),
            (3e-39, 0.5),
            (1e-12, 0.5),
            (1e-6, 0.5),
            (0.5, 1e-36),
            (1e-4, 0.5),
            (2e-4, 0.5),
        ] {
            let bsdf =
                single(Ggx::new(ax, ay).expect("valid roughness"), Dielectric::new(eta).expect("valid"));
            let (so, si) = (Soa::of(&wo), Soa::of(&wi));
            let (mut f, mut pdf) = (Out::new(N), vec![-1.0; N]);
            bsdf.eval_with_pdf_batch(&so.dirs(), &si.dirs(), &mut f.channels(), &mut pdf).expect("lengths");
            let mut worst = 0.0f32;
            for i in 0..N {
                let (v, p) = bsdf.eval_with_pdf(wo[i], wi[i]);
                let e = excess(f.get(i), v.f, GLASS.rel, GLASS.abs * v.f.max_element());
                worst = worst.max(if v.f.x > 0.0 { (f.get(i).x - v.f.x).abs() / v.f.x } else { 0.0 });
                assert!(
                    e <= 1.0 && (pdf[i] - p).abs() <= GLASS.pdf_rel * p + GLASS.pdf_abs,
                    "η = {eta}, GGX ({ax}, {ay}): f({}, {}) = {}, pdf {} in the batch, ({}, {p}) scalar",
                    wo[i],
                    wi[i],
                    f.get(i),
                    pdf[i],
                    v.f
                );
            }
            eprintln!(
                "glass η = {eta}, GGX ({ax}, {ay}) near the critical angle: f rel. error ≤ {worst:.2e}"
            );
        }
    }
}

/// Configurations without lane kernels (Beckmann, the random walk) answer with the scalar calls.
#[test]
fn other_configurations_are_the_scalar_calls() {
    let gold = Conductor::new(ComplexIor::GOLD);
    let beckmann = single(Beckmann::isotropic(0.4).expect("valid roughness"), gold);
    check_eval("gold Beckmann", &beckmann, 300, Bounds::EXACT);
    check_sample("gold Beckmann", &beckmann, 300, 0.0, 0.0, 0.0);
    let walk = MicrofacetBsdf::new(Ggx::isotropic(0.4).expect("valid roughness"), gold).expect("valid");
    check_eval("gold walk", &walk, 301, Bounds::EXACT);
}

/// GGX lobes sharp along one axis (α from f32's subnormals to 2e-4 beside α = 0.5, on both sides
/// of the smallest α the lanes take), gold and glass: every batch call (eval, pdf,
/// eval_with_pdf) finite and within [`GLASS`]'s bounds of the scalar call, on random queries
/// and on queries in the plane of the sharp axis's normal (h.x = 0, where D is largest). With
/// the lanes taking every roughness, α = 1e-6 fails this (a density 1.06e-4 off) and α = 1e-12
/// too (f 60 % off, its D's squared ratio subnormal).
#[test]
fn extreme_anisotropy_batches_are_the_scalar_calls() {
    let mut rng = Pcg64Mcg::seed_from_u64(340);
    let (mut wo, mut wi) = queries(341, false);
    for i in 0..N / 2 {
        let (a, b) = (rng.random::<f32>() * 1.5, rng.random::<f32>() * 3.1);
        (wo[i], wi[i]) = (Vec3::new(0.0, a.sin(), a.cos()), Vec3::new(0.0, -b.sin(), b.cos()));
    }
    for (ax, ay) in
        [(1e-37f32, 0.5f32), (3e-39, 0.5), (1e-12, 0.5), (1e-6, 0.5), (0.5, 1e-36), (1e-4, 0.5), (2e-4, 0.5)]
    {
        let slope = Ggx::new(ax, ay).expect("valid roughness");
        for (name, bsdf) in [
            ("gold", &single(slope, Conductor::new(ComplexIor::GOLD)) as &dyn BatchCheck),
            ("glass", &single(slope, Dielectric::new(1.5).expect("valid index")) as &dyn BatchCheck),
        ] {
            bsdf.check(&format!("{name} GGX ({ax}, {ay})"), &wo, &wi);
        }
    }
}

/// [`extreme_anisotropy_batches_are_the_scalar_calls`]'s check, object safe over the BSDFs.
trait BatchCheck {
    fn check(&self, label: &str, wo: &[Vec3], wi: &[Vec3]);
}

impl<B: BatchBsdf> BatchCheck for B {
    fn check(&self, label: &str, wo: &[Vec3], wi: &[Vec3]) {
        let n = wo.len();
        let (so, si) = (Soa::of(wo), Soa::of(wi));
        let (mut f, mut f2, mut pdf, mut pdf2) = (Out::new(n), Out::new(n), vec![-1.0; n], vec![-1.0; n]);
        self.eval_batch(&so.dirs(), &si.dirs(), &mut f.channels()).expect("lengths");
        self.pdf_batch(&so.dirs(), &si.dirs(), &mut pdf).expect("lengths");
        self.eval_with_pdf_batch(&so.dirs(), &si.dirs(), &mut f2.channels(), &mut pdf2).expect("lengths");
        for i in 0..n {
            let (v, p) = self.eval_with_pdf(wo[i], wi[i]);
            let carried = if wo[i].z * wi[i].z < 0.0 && p > 0.0 { GLASS.pdf_abs / p } else { 0.0 };
            let allowance = (GLASS.abs + carried) * v.f.max_element();
            for (what, bf, bp) in [("eval, pdf", f.get(i), pdf[i]), ("eval_with_pdf", f2.get(i), pdf2[i])] {
                let close = bf.is_finite()
                    && bp.is_finite()
                    && excess(bf, v.f, GLASS.transmit_rel, allowance) <= 1.0
                    && (bp - p).abs() <= GLASS.pdf_rel * p + GLASS.pdf_abs;
                assert!(
                    close,
                    "{label} {what}: query {i} ({}, {}): batch ({bf}, {bp}), scalar ({}, {p})",
                    wo[i], wi[i], v.f
                );
            }
        }
    }
}

/// Slices of unequal length are rejected before anything is written.
#[test]
fn unequal_lengths_are_rejected() {
    let gold = single(Ggx::isotropic(0.5).expect("valid roughness"), Conductor::new(ComplexIor::GOLD));
    let (x, z) = (vec![0.0f32; 16], vec![1.0f32; 16]);
    assert!(matches!(
        Directions::new(&x, &x[..15], &z),
        Err(Error::LengthMismatch { name: "y", expected: 16, found: 15 })
    ));
    let d = Directions::new(&x, &x, &z).expect("equal");
    let short = Directions::new(&x[..8], &x[..8], &z[..8]).expect("equal");
    let mut f = Out::new(16);
    let mut pdf = vec![-1.0; 15];
    assert!(matches!(gold.pdf_batch(&d, &d, &mut pdf), Err(Error::LengthMismatch { name: "pdf", .. })));
    assert!(matches!(
        gold.eval_batch(&d, &short, &mut f.channels()),
        Err(Error::LengthMismatch { name: "wi", .. })
    ));
    assert!(pdf.iter().all(|&p| p == -1.0) && f.a.iter().all(|&v| v == -1.0), "a rejected call wrote");
    let (mut w, mut weight, mut p, mut eta) = (Out::new(16), Out::new(16), vec![-1.0; 16], vec![-1.0; 16]);
    let mut out = SampleOutputs { wi: w.channels(), weight: weight.channels(), pdf: &mut p, eta: &mut eta };
    let u = vec![0.5f32; 16];
    assert!(matches!(
        gold.sample_batch(&d, &u, &u[..3], &u, &mut out),
        Err(Error::LengthMismatch { name: "u1", .. })
    ));
    assert!(p.iter().all(|&v| v == -1.0));
}

/// Invalid lanes (NaN, zero, non-unit directions, uniforms outside [0, 1)) among valid ones get
/// the scalar calls' nothing, and their neighbours their own values (release builds: the scalar
/// calls assert in debug builds).
#[cfg(not(debug_assertions))]
#[test]
fn invalid_lanes_get_nothing_and_do_not_poison_their_neighbours() {
    use microsurface::Bsdf;
    let gold = single(Ggx::isotropic(0.5).expect("valid roughness"), Conductor::new(ComplexIor::GOLD));
    let glass = single(Ggx::isotropic(0.5).expect("valid roughness"), Dielectric::new(1.5).expect("valid"));
    let bad = [
        Vec3::NAN,
        Vec3::ZERO,
        Vec3::new(0.0, 0.0, 2.0),
        Vec3::new(f32::INFINITY, 0.0, 0.0),
        Vec3::new(0.6, 0.0, 0.9),
    ];
    let (mut wo, mut wi) = queries(400, true);
    for (k, b) in bad.iter().enumerate() {
        wo[8 * k + 3] = *b;
        wi[8 * k + 5] = *b;
    }
    check_lanes("gold", &gold, &wo, &wi);
    check_lanes("glass", &glass, &wo, &wi);
    let mut rng = Pcg64Mcg::seed_from_u64(401);
    let mut u1: Vec<f32> = (0..N).map(|_| rng.random()).collect();
    let u2: Vec<f32> = (0..N).map(|_| rng.random()).collect();
    let uc = u2.clone();
    for (k, u) in [f32::NAN, -0.1, 1.0, 3.0].into_iter().enumerate() {
        u1[8 * k + 2] = u;
    }
    let so = Soa::of(&wo);
    let (mut w, mut weight, mut pdf, mut eta) = (Out::new(N), Out::new(N), vec![-1.0; N], vec![-1.0; N]);
    let mut out = SampleOutputs { wi: w.channels(), weight: weight.channels(), pdf: &mut pdf, eta: &mut eta };
    gold.sample_batch(&so.dirs(), &uc, &u1, &u2, &mut out).expect("lengths");
    for i in 0..N {
        let s = gold.sample(wo[i], uc[i], Vec2::new(u1[i], u2[i]));
        assert_eq!(s.map_or(0.0, |s| s.pdf), pdf[i], "sample {i}");
        assert_eq!(s.map_or(Vec3::ZERO, |s| s.weight), weight.get(i), "sample {i}");
    }
    let mut out = SampleOutputs { wi: w.channels(), weight: weight.channels(), pdf: &mut pdf, eta: &mut eta };
    glass.sample_batch(&so.dirs(), &uc, &u1, &u2, &mut out).expect("lengths");
    for i in 0..N {
        let s = glass.sample(wo[i], uc[i], Vec2::new(u1[i], u2[i]));
        let close = match s {
            None => pdf[i] == 0.0 && weight.get(i) == Vec3::ZERO && w.get(i) == Vec3::ZERO,
            Some(s) => {
                s.wi == w.get(i)
                    && excess(weight.get(i), s.weight, GLASS_WEIGHT_REL, 0.0) <= 1.0
                    && (pdf[i] - s.pdf).abs() <= GLASS.pdf_rel * s.pdf + GLASS.pdf_abs
            }
        };
        assert!(close, "glass sample {i} of {}: {s:?}, batch pdf {}", wo[i], pdf[i]);
    }
}

#[cfg(not(debug_assertions))]
fn check_lanes<B: BatchBsdf>(label: &str, bsdf: &B, wo: &[Vec3], wi: &[Vec3]) {
    let (so, si) = (Soa::of(wo), Soa::of(wi));
    let (mut f, mut pdf) = (Out::new(N), vec![-1.0; N]);
    bsdf.eval_with_pdf_batch(&so.dirs(), &si.dirs(), &mut f.channels(), &mut pdf).expect("lengths");
    for i in 0..N {
        let (v, p) = bsdf.eval_with_pdf(wo[i], wi[i]);
        let (rel, carried) = if wo[i].z * wi[i].z < 0.0 && p > 0.0 {
            (GLASS.transmit_rel, GLASS.pdf_abs / p)
        } else {
            (GLASS.rel, 0.0)
        };
        let close = excess(f.get(i), v.f, rel, (GLASS.abs + carried) * v.f.max_element()) <= 1.0
            && (pdf[i] - p).abs() <= GLASS.pdf_rel * p + GLASS.pdf_abs;
        assert!(
            close,
            "{label}: query {i} ({}, {}): batch ({}, {}), scalar ({}, {p})",
            wo[i],
            wi[i],
            f.get(i),
            pdf[i],
            v.f
        );
        if !(wo[i].length_squared() - 1.0).abs().le(&1e-3) || !(wi[i].length_squared() - 1.0).abs().le(&1e-3)
        {
            assert!(f.get(i) == Vec3::ZERO && pdf[i] == 0.0, "{label}: invalid query {i} got a value");
        }
    }
}

/// The compensated lobes' schemes.
const SCHEMES: [Compensation; 3] = [Compensation::Walk, Compensation::KullaConty, Compensation::Turquin];

/// GGX roughnesses of the compensated lobes (√(αx αy) within the tables' α ≤ 1), isotropic and
/// anisotropic.
const COMPENSATED_GGX: [(f32, f32); 6] =
    [(2e-3, 2e-3), (0.05, 0.05), (0.5, 0.5), (1.0, 1.0), (0.3, 0.02), (2.0, 0.4)];

/// A Dirac lobe's roughness (below `SMOOTH_ALPHA`): f and pdf are 0, the batch calls
/// single scattering's.
const DIRAC: f32 = 1e-4;

/// Batch eval, pdf and eval_with_pdf equal to the scalar calls bit for bit, on the given queries.
fn check_exact<B: BatchBsdf>(label: &str, bsdf: &B, wo: &[Vec3], wi: &[Vec3]) {
    let n = wo.len();
    let (so, si) = (Soa::of(wo), Soa::of(wi));
    let (mut f, mut f2, mut pdf, mut pdf2) = (Out::new(n), Out::new(n), vec![-1.0; n], vec![-1.0; n]);
    bsdf.eval_batch(&so.dirs(), &si.dirs(), &mut f.channels()).expect("lengths");
    bsdf.pdf_batch(&so.dirs(), &si.dirs(), &mut pdf).expect("lengths");
    bsdf.eval_with_pdf_batch(&so.dirs(), &si.dirs(), &mut f2.channels(), &mut pdf2).expect("lengths");
    for i in 0..n {
        let (v, p) = bsdf.eval_with_pdf(wo[i], wi[i]);
        let same = |a: Vec3, b: Vec3| a.to_array().map(f32::to_bits) == b.to_array().map(f32::to_bits);
        assert!(
            same(f.get(i), bsdf.eval(wo[i], wi[i]).f)
                && pdf[i].to_bits() == bsdf.pdf(wo[i], wi[i]).to_bits()
                && same(f2.get(i), v.f)
                && pdf2[i].to_bits() == p.to_bits(),
            "{label}: query {i} ({}, {}): batch ({}, {}), scalar ({}, {p})",
            wo[i],
            wi[i],
            f2.get(i),
            pdf2[i],
            v.f
        );
    }
}

/// Compensated conductors (gold, copper; every scheme): the batch is single scattering's batch
/// with the scalar calls' added lobe (1 − E read bit for bit from the lobe's column, the walk's
/// series within rounding), Turquin factor and mixture density: densities bit for bit, f
/// within single scattering's bounds (a compensated f is at least single scattering's,
/// Turquin's scales it), samples bit for bit (Turquin's are single scattering's batch
/// samples); on Beckmann (single scattering's scalar fallback) bit for bit but for the walk's
/// series, within the same bounds; the Dirac mirror bit for bit.
#[test]
fn compensated_conductor_batches_are_the_scalar_calls() {
    let bounds = Bounds { rel: 4e-6, transmit_rel: 4e-6, abs: 1e-6, ..Bounds::EXACT };
    for (m, (name, ior)) in
        [("gold", ComplexIor::GOLD), ("copper", ComplexIor::COPPER)].into_iter().enumerate()
    {
        let metal = Conductor::new(ior);
        for (s, scheme) in SCHEMES.into_iter().enumerate() {
            for (k, (ax, ay)) in COMPENSATED_GGX.into_iter().enumerate() {
                let slope = Ggx::new(ax, ay).expect("valid roughness");
                let bsdf = Compensated::with_scheme(slope, metal, scheme).expect("tabulated");
                let label = format!("{name} {scheme:?} GGX ({ax}, {ay})");
                let seed = 500 + 100 * m as u64 + 10 * s as u64 + k as u64;
                check_eval(&label, &bsdf, seed, bounds);
                check_sample(&label, &bsdf, seed, 0.0, 0.0, 0.0);
            }
            let seed = 590 + 100 * m as u64 + s as u64;
            let beckmann = Beckmann::isotropic(0.4).expect("valid roughness");
            let bsdf = Compensated::with_scheme(beckmann, metal, scheme).expect("tabulated");
            let label = format!("{name} {scheme:?} Beckmann 0.4");
            // (the walk's series from the column differs by its rounding; 1 − E is exact)
            check_eval(
                &label,
                &bsdf,
                seed,
                if scheme == Compensation::Walk { bounds } else { Bounds::EXACT },
            );
            check_sample(&label, &bsdf, seed, 0.0, 0.0, 0.0);
            let dirac = Compensated::with_scheme(Ggx::isotropic(DIRAC).expect("valid"), metal, scheme);
            let (dirac, label) = (dirac.expect("tabulated"), format!("{name} {scheme:?} Dirac"));
            let (wo, wi) = queries(seed, false);
            check_exact(&label, &dirac, &wo, &wi);
            check_sample(&label, &dirac, seed, 0.0, 0.0, 0.0);
        }
    }
}

/// Compensated gold and glass in small batches (1, 15, 31 and 63 queries: on both sides of the
/// sizes from which glass and gold's Kulla–Conty and Turquin lobes lay out their tables' values
/// for the batch, and below gold's walk's; every scheme), invalid
/// and drifted directions among them: on Beckmann slopes, whose single scattering is its scalar
/// calls in a batch, equal to the scalar calls bit for bit (the same functions of f and the
/// density; the odd queries, the scalar calls themselves).
#[test]
fn small_compensated_batches_are_the_scalar_calls() {
    let beckmann = Beckmann::isotropic(0.4).expect("valid roughness");
    let (mut wo, mut wi) = queries(620, false);
    (wo[5], wi[9], wi[14]) = (Vec3::NAN, Vec3::ZERO, wi[14] * 1.006);
    (wo[20], wo[60]) = (wo[20] * 1.004, wo[60] * 0.995);
    for scheme in SCHEMES {
        let gold =
            Compensated::with_scheme(beckmann, Conductor::new(ComplexIor::GOLD), scheme).expect("tabulated");
        let glass = Compensated::with_scheme(beckmann, Dielectric::new(1.5).expect("valid"), scheme)
            .expect("tabulated");
        for n in [1, 15, 31, 63] {
            check_exact(&format!("gold {scheme:?} Beckmann 0.4, {n} queries"), &gold, &wo[..n], &wi[..n]);
            check_exact(&format!("glass {scheme:?} Beckmann 0.4, {n} queries"), &glass, &wo[..n], &wi[..n]);
        }
    }
}

/// Compensated glass (η = 1.5 and 1/1.5; every scheme): within the single-scattering
/// dielectric's bounds ([`GLASS`], carried through the added lobes, the mixture and Turquin's
/// factor); Turquin's samples with single scattering's batch direction, event and η bit for bit
/// and its weight within [`GLASS_WEIGHT_REL`], the additive schemes' samples bit for bit (the
/// scalar call); Beckmann and the Dirac lobe bit for bit.
#[test]
fn compensated_dielectric_batches_are_the_scalar_calls() {
    for (e, eta) in [1.5f32, 1.0 / 1.5].into_iter().enumerate() {
        let glass = Dielectric::new(eta).expect("valid index");
        for (s, scheme) in SCHEMES.into_iter().enumerate() {
            for (k, (ax, ay)) in COMPENSATED_GGX.into_iter().enumerate() {
                let slope = Ggx::new(ax, ay).expect("valid roughness");
                let bsdf = Compensated::with_scheme(slope, glass, scheme).expect("tabulated");
                let label = format!("glass η = {eta} {scheme:?} GGX ({ax}, {ay})");
                let seed = 700 + 100 * e as u64 + 10 * s as u64 + k as u64;
                check_eval(&label, &bsdf, seed, GLASS);
                if scheme == Compensation::Turquin {
                    check_sample(&label, &bsdf, seed, GLASS_WEIGHT_REL, GLASS.pdf_rel, GLASS.pdf_abs);
                } else {
                    check_sample(&label, &bsdf, seed, 0.0, 0.0, 0.0);
                }
            }
            let seed = 790 + 100 * e as u64 + s as u64;
            let beckmann = Beckmann::isotropic(0.4).expect("valid roughness");
            let bsdf = Compensated::with_scheme(beckmann, glass, scheme).expect("tabulated");
            let label = format!("glass η = {eta} {scheme:?} Beckmann 0.4");
            check_eval(&label, &bsdf, seed, Bounds::EXACT);
            check_sample(&label, &bsdf, seed, 0.0, 0.0, 0.0);
            let dirac = Compensated::with_scheme(Ggx::isotropic(DIRAC).expect("valid"), glass, scheme);
            let (dirac, label) = (dirac.expect("tabulated"), format!("glass η = {eta} {scheme:?} Dirac"));
            let (wo, wi) = queries(seed, false);
            check_exact(&label, &dirac, &wo, &wi);
            check_sample(&label, &dirac, seed, 0.0, 0.0, 0.0);
        }
    }
}

/// Compensated lobes (both materials, every scheme): slices of unequal length are rejected
/// before anything is written.
#[test]
fn compensated_unequal_lengths_are_rejected() {
    let slope = Ggx::isotropic(0.5).expect("valid roughness");
    for scheme in SCHEMES {
        let gold =
            Compensated::with_scheme(slope, Conductor::new(ComplexIor::GOLD), scheme).expect("tabulated");
        let glass =
            Compensated::with_scheme(slope, Dielectric::new(1.5).expect("valid"), scheme).expect("tabulated");
        check_lengths(&format!("gold {scheme:?}"), &gold);
        check_lengths(&format!("glass {scheme:?}"), &glass);
    }
}

fn check_lengths<B: BatchBsdf>(label: &str, bsdf: &B) {
    let (x, z) = (vec![0.0f32; 16], vec![1.0f32; 16]);
    let d = Directions::new(&x, &x, &z).expect("equal");
    let short = Directions::new(&x[..8], &x[..8], &z[..8]).expect("equal");
    let (mut f, mut f_short) = (Out::new(16), Out::new(15));
    let (mut pdf, mut pdf_short) = (vec![-1.0; 16], vec![-1.0; 15]);
    let rejected = |r: Result<(), Error>, name: &str| matches!(r, Err(Error::LengthMismatch { name: n, .. }) if n == name);
    assert!(rejected(bsdf.eval_batch(&d, &short, &mut f.channels()), "wi"), "{label}: eval, short wi");
    assert!(rejected(bsdf.eval_batch(&d, &d, &mut f_short.channels()), "f"), "{label}: eval, short f");
    assert!(rejected(bsdf.pdf_batch(&d, &d, &mut pdf_short), "pdf"), "{label}: pdf, short pdf");
    assert!(rejected(bsdf.pdf_batch(&d, &short, &mut pdf), "wi"), "{label}: pdf, short wi");
    assert!(
        rejected(bsdf.eval_with_pdf_batch(&d, &d, &mut f.channels(), &mut pdf_short), "pdf"),
        "{label}: eval_with_pdf, short pdf"
    );
    assert!(
        rejected(bsdf.eval_with_pdf_batch(&d, &d, &mut f_short.channels(), &mut pdf), "f"),
        "{label}: eval_with_pdf, short f"
    );
    let untouched = |v: &[f32]| v.iter().all(|&v| v == -1.0);
    assert!(
        untouched(&f.a) && untouched(&f_short.a) && untouched(&pdf) && untouched(&pdf_short),
        "{label}: a rejected call wrote"
    );
    let (mut w, mut weight, mut p, mut eta) = (Out::new(16), Out::new(16), vec![-1.0; 16], vec![-1.0; 16]);
    let mut out = SampleOutputs { wi: w.channels(), weight: weight.channels(), pdf: &mut p, eta: &mut eta };
    let u = vec![0.5f32; 16];
    assert!(rejected(bsdf.sample_batch(&d, &u, &u[..3], &u, &mut out), "u1"), "{label}: sample, short u1");
    assert!(rejected(bsdf.sample_batch(&d, &u[..15], &u, &u, &mut out), "uc"), "{label}: sample, short uc");
    assert!(untouched(&p) && untouched(&w.a) && untouched(&weight.a), "{label}: a rejected sample wrote");
}

/// Compensated lobes (gold and glass, every scheme): invalid lanes (NaN, zero, non-unit
/// directions, uniforms outside [0, 1)) get the scalar calls' nothing and drifted directions
/// (|ω| within 10⁻² of 1, which the scalar calls renormalize) the scalar call's answer, both
/// bit for bit; their neighbours stay within the bounds (release builds: the scalar calls assert
/// on garbage in debug builds).
#[cfg(not(debug_assertions))]
#[test]
fn compensated_invalid_and_drifted_lanes_are_the_scalar_calls() {
    let bad = [
        Vec3::NAN,
        Vec3::ZERO,
        Vec3::new(0.0, 0.0, 2.0),
        Vec3::new(f32::INFINITY, 0.0, 0.0),
        Vec3::new(0.6, 0.0, 0.9),
    ];
    let (mut wo, mut wi) = queries(450, false);
    // the queries with an odd direction, and those with an odd view (the sample's argument)
    let (mut odd, mut odd_views) = (Vec::new(), Vec::new());
    for (k, b) in bad.iter().enumerate() {
        (wo[8 * k + 3], wi[8 * k + 5]) = (*b, *b);
        odd.extend([8 * k + 3, 8 * k + 5]);
        odd_views.push(8 * k + 3);
    }
    // drifted: lengths 1.006 and 0.995 (|‖ω‖² − 1| beyond the as-is tolerance 10⁻³)
    for k in 0..40 {
        let i = 64 + 16 * k;
        (wo[i], wi[i + 1], wi[i + 2]) = (wo[i] * 1.006, wi[i + 1] * 0.995, wi[i + 2] * 1.006);
        wo[i + 2] *= 0.995;
        odd.extend([i, i + 1, i + 2]);
        odd_views.extend([i, i + 2]);
    }
    // in the last, partial block of eight queries (and of 64)
    (wo[N - 1], wi[N - 3]) = (Vec3::NAN, Vec3::ZERO);
    wo[N - 2] *= 1.006;
    odd.extend([N - 1, N - 3, N - 2]);
    odd_views.extend([N - 1, N - 2]);
    let mut rng = Pcg64Mcg::seed_from_u64(451);
    let mut u1: Vec<f32> = (0..N).map(|_| rng.random()).collect();
    let u2: Vec<f32> = (0..N).map(|_| rng.random()).collect();
    let uc: Vec<f32> = (0..N).map(|_| rng.random()).collect();
    for (k, u) in [f32::NAN, -0.1, 1.0, 3.0].into_iter().enumerate() {
        u1[8 * k + 2] = u;
        odd_views.push(8 * k + 2);
    }
    let slope = Ggx::new(0.5, 0.3).expect("valid roughness");
    let conductor = Bounds { rel: 4e-6, transmit_rel: 4e-6, abs: 1e-6, ..Bounds::EXACT };
    for scheme in SCHEMES {
        let gold =
            Compensated::with_scheme(slope, Conductor::new(ComplexIor::GOLD), scheme).expect("tabulated");
        let glass =
            Compensated::with_scheme(slope, Dielectric::new(1.5).expect("valid"), scheme).expect("tabulated");
        check_odd_lanes(
            &format!("gold {scheme:?}"),
            &gold,
            conductor,
            0.0,
            (&wo, &wi),
            (&uc, &u1, &u2),
            (&odd, &odd_views),
        );
        check_odd_lanes(
            &format!("glass {scheme:?}"),
            &glass,
            GLASS,
            GLASS_WEIGHT_REL,
            (&wo, &wi),
            (&uc, &u1, &u2),
            (&odd, &odd_views),
        );
    }
}

#[cfg(not(debug_assertions))]
fn check_odd_lanes<B: BatchBsdf>(
    label: &str,
    bsdf: &B,
    bounds: Bounds,
    weight_rel: f32,
    (wo, wi): (&[Vec3], &[Vec3]),
    (uc, u1, u2): (&[f32], &[f32], &[f32]),
    (odd, odd_views): (&[usize], &[usize]),
) {
    let (so, si) = (Soa::of(wo), Soa::of(wi));
    let (mut f, mut pdf) = (Out::new(N), vec![-1.0; N]);
    bsdf.eval_with_pdf_batch(&so.dirs(), &si.dirs(), &mut f.channels(), &mut pdf).expect("lengths");
    let (mut f_only, mut pdf_only) = (Out::new(N), vec![-1.0; N]);
    bsdf.eval_batch(&so.dirs(), &si.dirs(), &mut f_only.channels()).expect("lengths");
    bsdf.pdf_batch(&so.dirs(), &si.dirs(), &mut pdf_only).expect("lengths");
    let bits = |v: Vec3| v.to_array().map(f32::to_bits);
    for i in 0..N {
        let (v, p) = bsdf.eval_with_pdf(wo[i], wi[i]);
        let (e, q) = (bsdf.eval(wo[i], wi[i]).f, bsdf.pdf(wo[i], wi[i]));
        if odd.contains(&i) {
            assert!(
                bits(f.get(i)) == bits(v.f)
                    && pdf[i].to_bits() == p.to_bits()
                    && bits(f_only.get(i)) == bits(e)
                    && pdf_only[i].to_bits() == q.to_bits(),
                "{label}: odd query {i} ({}, {}): batch ({}, {}), scalar ({}, {p})",
                wo[i],
                wi[i],
                f.get(i),
                pdf[i],
                v.f
            );
            continue;
        }
        let (rel, carried) = if wo[i].z * wi[i].z < 0.0 && p > 0.0 {
            (bounds.transmit_rel, bounds.pdf_abs / p)
        } else {
            (bounds.rel, 0.0)
        };
        let close = |b: Vec3, s: Vec3, bp: f32, sp: f32| {
            excess(b, s, rel, (bounds.abs + carried) * s.max_element()) <= 1.0
                && (bp - sp).abs() <= bounds.pdf_rel * sp + bounds.pdf_abs
        };
        assert!(
            close(f.get(i), v.f, pdf[i], p) && close(f_only.get(i), e, pdf_only[i], q),
            "{label}: query {i} ({}, {}): batch ({}, {}), scalar ({}, {p})",
            wo[i],
            wi[i],
            f.get(i),
            pdf[i],
            v.f
        );
    }
    let so = Soa::of(wo);
    let (mut w, mut weight, mut sp, mut eta) = (Out::new(N), Out::new(N), vec![-1.0; N], vec![-1.0; N]);
    let mut out = SampleOutputs { wi: w.channels(), weight: weight.channels(), pdf: &mut sp, eta: &mut eta };
    bsdf.sample_batch(&so.dirs(), uc, u1, u2, &mut out).expect("lengths");
    for i in 0..N {
        let s = bsdf.sample(wo[i], uc[i], Vec2::new(u1[i], u2[i]));
        let ok = match s {
            None => sp[i] == 0.0 && w.get(i) == Vec3::ZERO && weight.get(i) == Vec3::ZERO && eta[i] == 1.0,
            Some(s) if odd_views.contains(&i) => {
                s.wi == w.get(i) && bits(s.weight) == bits(weight.get(i)) && s.pdf == sp[i] && s.eta == eta[i]
            }
            Some(s) => {
                s.wi == w.get(i)
                    && s.eta == eta[i]
                    && excess(weight.get(i), s.weight, weight_rel, 0.0) <= 1.0
                    && (sp[i] - s.pdf).abs() <= bounds.pdf_rel * s.pdf + bounds.pdf_abs
            }
        };
        assert!(
            ok,
            "{label}: sample {i} of {}: {s:?}, batch ({}, {}, {})",
            wo[i],
            w.get(i),
            weight.get(i),
            sp[i]
        );
    }
}
