//! Property tests over the whole documented domain of every public function and model.
//!
//! Domain: α ∈ [1e-4, 4] log-uniform (αx and αy independent, so anisotropy ratios up to 4e4),
//! plus the end points; directions uniform on the sphere, plus exactly grazing (z = 0,
//! ±1e-7), exactly normal (±z), z = ±1e-4 and unit vectors within sin θ = 1e-10…1e-30 of a pole;
//! uniforms in [0, 1) plus 0 and the largest f32 below 1 (1 − ε/2); η ∈ [1/4, 4] log-uniform,
//! within 1e-6 of 1, and exactly 1; both height distributions; every material.
//!
//! Properties: results finite; densities ≥ 0; sampled directions unit (|‖ω‖ − 1| ≤ 1e-5);
//! sampled normals in the upper hemisphere; weights ≥ 0 and, for non-absorptive or absorptive
//! materials whose per-sample weight is a reflectance or albedo, ≤ 1 + 1e-5; no panic.
//!
//! Determinism: every property runs with `RngSeed::Fixed` and no failure persistence, so
//! CI runs the same cases every time (override the count with `PROPTEST_CASES` if needed).
//! Case counts: 384 per property, 96 for the random walks and position-free estimators.
use glam::{Vec2, Vec3};
use microsurface::Ggx;
use microsurface::fresnel::{fresnel_conductor, fresnel_dielectric, fresnel_schlick};
use microsurface::research::MAX_BOUNCES;
use microsurface::research::{
    Estimator, GaussianHeight, HeightSample, Material, Microsurface, MicrosurfaceGeometry,
    MicrosurfaceHeight, PositionFree, ScatteringOrder, Shadowing, SpecularLimit, UniformHeight,
};
use microsurface::research::{Interaction, Side};
use microsurface::slope::MicrosurfaceSlope;
use microsurface::special::{beta, erf, erfc, erfinv, ln_beta, ln_gamma};
use microsurface::vndf::{
    BeckmannNewton, GgxBoundedCap, GgxDisk, GgxSphericalCap, SmithVndf, VCavity, VCavitySlope,
    VisibleNormalSampler, smith_normalization,
};
use microsurface::{
    Beckmann, Bsdf, ClassicBrdf, ClassicMasking, ClassicNdf, ComplexIor, Conductor, Dielectric, Diffuse,
    MicrofacetBsdf, Technique, Transport,
};
use proptest::prelude::*;
use proptest::test_runner::{Config, RngSeed, TestCaseResult};
use rand::SeedableRng;
use std::f64::consts::TAU;

type Rng = rand_pcg::Pcg64Mcg;

const UNIT_TOL: f32 = 1e-5;
const WEIGHT_TOL: f32 = 1e-5;

fn config(cases: u32, seed: u64) -> Config {
    Config { cases, rng_seed: RngSeed::Fixed(seed), failure_persistence: None, ..Config::default() }
}

// ---------------------------------------------------------------------------------------------
// Strategies
// ---------------------------------------------------------------------------------------------

fn alpha() -> impl Strategy<Value = f32> {
    prop_oneof![
        6 => (-4.0f64..4f64.log10()).prop_map(|e| 10f64.powf(e) as f32),
        1 => Just(1e-4f32),
        1 => Just(4.0f32),
    ]
}

fn dir(z: f64, phi: f64) -> Vec3 {
    let s = (1.0 - z * z).max(0.0).sqrt();
    Vec3::new((s * phi.cos()) as f32, (s * phi.sin()) as f32, z as f32)
}

/// Any unit direction, with the special ones over-represented.
fn direction() -> impl Strategy<Value = Vec3> {
    prop_oneof![
        4 => (-1.0f64..=1.0, 0.0..TAU).prop_map(|(z, p)| dir(z, p)),
        3 => (prop::sample::select(vec![0.0, 1e-7, -1e-7, 1.0, -1.0, 1e-4, -1e-4, 0.5, -0.5]), 0.0..TAU)
            .prop_map(|(z, p)| dir(z, p)),
        1 => (prop::sample::select(vec![1e-10f64, 1e-20, 1e-30]), 0.0..TAU, any::<bool>()).prop_map(|(s, p, up)| {
            Vec3::new((s * p.cos()) as f32, (s * p.sin()) as f32, if up { 1.0 } else { -1.0 })
        }),
    ]
}

fn upper_direction() -> impl Strategy<Value = Vec3> {
    direction().prop_map(|w| if w.z < 0.0 { -w } else { w })
}

fn uniform() -> impl Strategy<Value = f32> {
    prop_oneof![4 => 0.0f32..1.0, 1 => Just(0.0f32), 1 => Just(1.0 - f32::EPSILON / 2.0)]
}

fn eta() -> impl Strategy<Value = f32> {
    prop_oneof![
        4 => (0.25f64.ln()..4f64.ln()).prop_map(|l| l.exp() as f32),
        2 => (-1e-6f32..1e-6).prop_map(|d| 1.0 + d),
        1 => Just(1.0f32),
    ]
}

#[derive(Debug, Clone, Copy)]
enum Mat {
    Perfect,
    Gold,
    Diffuse(f32),
    Dielectric(f32),
}

fn material() -> impl Strategy<Value = Mat> {
    prop_oneof![
        Just(Mat::Perfect),
        Just(Mat::Gold),
        prop_oneof![0.0f32..=1.0, Just(1.0f32)].prop_map(Mat::Diffuse),
        eta().prop_map(Mat::Dielectric),
    ]
}

// ---------------------------------------------------------------------------------------------
// Helpers
// ---------------------------------------------------------------------------------------------

fn unit(w: Vec3) -> bool {
    w.is_finite() && (w.length() - 1.0).abs() <= UNIT_TOL
}

fn density(x: f32) -> bool {
    x.is_finite() && x >= 0.0
}

fn non_negative(v: Vec3) -> bool {
    v.is_finite() && v.min_element() >= 0.0
}

fn bounded_weight(v: Vec3) -> bool {
    non_negative(v) && v.max_element() <= 1.0 + WEIGHT_TOL
}

/// Calls `visit` with the model's static types.
trait Visit {
    fn visit<H: MicrosurfaceHeight, S: MicrosurfaceSlope, M: Material + SpecularLimit>(
        &self,
        h: H,
        s: S,
        m: M,
    ) -> TestCaseResult;
}

fn dispatch_material<V: Visit, H: MicrosurfaceHeight, S: MicrosurfaceSlope>(
    v: &V,
    h: H,
    s: S,
    mat: Mat,
) -> TestCaseResult {
    match mat {
        Mat::Perfect => v.visit(h, s, Conductor::perfect()),
        Mat::Gold => v.visit(h, s, Conductor::new(ComplexIor::GOLD)),
        Mat::Diffuse(a) => v.visit(h, s, Diffuse::new(Vec3::new(a, 0.5 * a, 1.0)).unwrap()),
        Mat::Dielectric(e) => v.visit(h, s, Dielectric::new(e).unwrap()),
    }
}

fn dispatch<V: Visit>(v: &V, gaussian: bool, beckmann: bool, ax: f32, ay: f32, mat: Mat) -> TestCaseResult {
    match (gaussian, beckmann) {
        (false, false) => dispatch_material(v, UniformHeight, Ggx::new(ax, ay).unwrap(), mat),
        (false, true) => dispatch_material(v, UniformHeight, Beckmann::new(ax, ay).unwrap(), mat),
        (true, false) => dispatch_material(v, GaussianHeight, Ggx::new(ax, ay).unwrap(), mat),
        (true, true) => dispatch_material(v, GaussianHeight, Beckmann::new(ax, ay).unwrap(), mat),
    }
}

// ---------------------------------------------------------------------------------------------
// Slopes, heights, geometry
// ---------------------------------------------------------------------------------------------

fn slope_props<S: MicrosurfaceSlope>(
    s: S,
    w: Vec3,
    m: Vec3,
    u1: f32,
    u2: f32,
    sx: f32,
    sy: f32,
) -> TestCaseResult {
    let lambda = s.lambda(w);
    prop_assert!(lambda.is_finite(), "Λ({w}) = {lambda}");
    if w.z > 0.0 {
        prop_assert!(lambda >= 0.0, "Λ({w}) = {lambda} < 0 above the horizon");
    } else if w.z < 0.0 {
        prop_assert!(lambda <= -1.0, "Λ({w}) = {lambda} > −1 below the horizon");
    }
    prop_assert!(density(s.d(m)), "D({m}) = {}", s.d(m));
    prop_assert!(density(s.projected_area(w)), "A({w}) = {}", s.projected_area(w));
    prop_assert!(density(s.d_wi(w, m)), "D_ωi({w}, {m}) = {}", s.d_wi(w, m));
    prop_assert!(density(s.p22(sx, sy)), "P22({sx}, {sy}) = {}", s.p22(sx, sy));
    let n = s.sample_d_wi(w, u1, u2);
    prop_assert!(n.is_finite() && n.z >= 0.0, "sample_d_wi({w}, {u1}, {u2}) = {n}");
    let pdf = s.d_wi(w, n);
    prop_assert!(density(pdf), "D_ωi at its own sample: {pdf}");
    Ok(())
}

proptest! {
    #![proptest_config(config(384, 0x5107_e001))]

    #[test]
    fn slopes(
        beckmann in any::<bool>(), ax in alpha(), ay in alpha(), w in direction(), m in direction(),
        u1 in uniform(), u2 in uniform(), sx in -1e6f32..1e6, sy in -1e6f32..1e6,
    ) {
        if beckmann {
            slope_props(Beckmann::new(ax, ay).unwrap(), w, m, u1, u2, sx, sy)?;
        } else {
            slope_props(Ggx::new(ax, ay).unwrap(), w, m, u1, u2, sx, sy)?;
        }
    }

    #[test]
    fn heights(gaussian in any::<bool>(), u in uniform(), h in -30.0f32..30.0) {
        fn check<H: MicrosurfaceHeight>(height: H, u: f32, h: f32) -> TestCaseResult {
            for x in [h, f32::INFINITY, f32::NEG_INFINITY, 0.0] {
                let c = height.c1(x);
                prop_assert!((0.0..=1.0).contains(&c), "C1({x}) = {c}");
            }
            prop_assert!(density(height.p1(h)), "P1({h}) = {}", height.p1(h));
            let x = height.inv_c1(u);
            prop_assert!(x.is_finite(), "invC1({u}) = {x}");
            let back = height.c1(x);
            prop_assert!((back - u).abs() <= 1e-6 + 1e-5 * u, "C1(invC1({u})) = {back}");
            Ok(())
        }
        if gaussian { check(GaussianHeight, u, h)?; } else { check(UniformHeight, u, h)?; }
    }

    #[test]
    fn geometry(
        gaussian in any::<bool>(), beckmann in any::<bool>(), ax in alpha(), ay in alpha(), w in direction(),
        u0 in uniform(), u in uniform(), above in any::<bool>(),
    ) {
        fn check<H: MicrosurfaceHeight, S: MicrosurfaceSlope>(g: MicrosurfaceGeometry<H, S>, w: Vec3, h0: f32, u: f32) -> TestCaseResult {
            let g1 = g.g1(w);
            prop_assert!((0.0..=1.0).contains(&g1), "G1({w}) = {g1}");
            let g1h = g.g1_at(w, h0);
            prop_assert!((0.0..=1.0).contains(&g1h), "G1({w}, {h0}) = {g1h}");
            match g.sample_height(w, h0, u) {
                HeightSample::Hit(h) => prop_assert!(h.is_finite(), "sample_height({w}, {h0}, {u}) = {h}"),
                HeightSample::Escape => prop_assert!(w.z >= 0.0, "a downward ray from {h0} escaped"),
            }
            Ok(())
        }
        let s_g = Ggx::new(ax, ay).unwrap();
        let s_b = Beckmann::new(ax, ay).unwrap();
        macro_rules! run { ($h:expr) => {{
            let h0 = if above { f32::INFINITY } else { $h.inv_c1(u0) };
            if beckmann { check(MicrosurfaceGeometry::new($h, s_b), w, h0, u)?; }
            else { check(MicrosurfaceGeometry::new($h, s_g), w, h0, u)?; }
        }}}
        if gaussian { run!(GaussianHeight) } else { run!(UniformHeight) }
    }
}

// ---------------------------------------------------------------------------------------------
// Materials
// ---------------------------------------------------------------------------------------------

struct PhaseProps {
    wi: Vec3,
    wo: Vec3,
    seed: u64,
}

impl Visit for PhaseProps {
    fn visit<H: MicrosurfaceHeight, S: MicrosurfaceSlope, M: Material + SpecularLimit>(
        &self,
        h: H,
        s: S,
        m: M,
    ) -> TestCaseResult {
        let (wi, wo) = (self.wi, self.wo);
        let mut rng = Rng::seed_from_u64(self.seed);
        for (io, oo) in [(true, true), (true, false), (false, true), (false, false)] {
            if !(M::TRANSMITS || io && oo) {
                continue;
            }
            let p = m.eval_phase(&s, &Interaction::new(wi, wo, side(io), side(oo)), &mut rng);
            prop_assert!(non_negative(p), "{m:?} eval_phase({wi}, {wo}, {io}, {oo}) = {p}");
            let pdf = m.pdf_phase(&s, &Interaction::new(wi, wo, side(io), side(oo)));
            prop_assert!(density(pdf), "{m:?} pdf_phase = {pdf}");
            let v = m.vertex(&s, &Interaction::new(wi, wo, side(io), side(oo)), &mut rng);
            prop_assert!(non_negative(v), "{m:?} vertex({wi}, {wo}, {io}, {oo}) = {v}");
        }
        for io in [true, false] {
            if !M::TRANSMITS && !io {
                continue;
            }
            let smp = m.sample_phase(&s, wi, side(io), &mut rng);
            prop_assert!(unit(smp.wo), "{m:?} sample_phase({wi}, {io}).wo = {}", smp.wo);
            prop_assert!(
                bounded_weight(smp.weight),
                "{m:?} sample_phase({wi}, {io}).weight = {}",
                smp.weight
            );
        }
        let ss = m.eval_single_scattering(&s, wi, wo, &mut rng);
        prop_assert!(non_negative(ss), "{m:?} eval_single_scattering({wi}, {wo}) = {ss}");
        let surface = Microsurface::new(h, s, m);
        prop_assert!(non_negative(surface.eval_phase(wi, wo, &mut rng)));
        prop_assert!(non_negative(surface.eval_single_scattering(wi, wo, &mut rng)));
        let sp = surface.sample_phase(wi, &mut rng);
        prop_assert!(unit(sp.wo) && bounded_weight(sp.weight), "Microsurface::sample_phase({wi}) = {sp:?}");
        Ok(())
    }
}

proptest! {
    #![proptest_config(config(384, 0x5107_e002))]

    #[test]
    fn materials(
        beckmann in any::<bool>(), ax in alpha(), ay in alpha(), mat in material(),
        wi in direction(), wo in direction(), seed in any::<u64>(),
    ) {
        dispatch(&PhaseProps { wi, wo, seed }, false, beckmann, ax, ay, mat)?;
    }
}

// ---------------------------------------------------------------------------------------------
// Walks, position-free estimators, renderer BSDFs
// ---------------------------------------------------------------------------------------------

struct WalkProps {
    wi: Vec3,
    wo: Vec3,
    seed: u64,
}

impl Visit for WalkProps {
    fn visit<H: MicrosurfaceHeight, S: MicrosurfaceSlope, M: Material + SpecularLimit>(
        &self,
        h: H,
        s: S,
        m: M,
    ) -> TestCaseResult {
        let (wi, wo) = (self.wi, self.wo);
        let mut rng = Rng::seed_from_u64(self.seed);
        let surface = Microsurface::new(h, s, m);
        for order in
            [ScatteringOrder::All, ScatteringOrder::only(1).unwrap(), ScatteringOrder::up_to(3).unwrap()]
        {
            let v = surface.eval(wi, wo, order, &mut rng);
            prop_assert!(non_negative(v), "{m:?} walk eval({wi}, {wo}, {order:?}) = {v}");
        }
        if let Some(smp) = surface.sample(wi, &mut rng) {
            prop_assert!(unit(smp.wo), "{m:?} walk sample({wi}).wo = {}", smp.wo);
            prop_assert!(bounded_weight(smp.weight), "{m:?} walk sample weight {}", smp.weight);
            prop_assert!((1..=MAX_BOUNCES).contains(&smp.bounces));
        }
        Ok(())
    }
}

struct PfProps {
    wi: Vec3,
    wo: Vec3,
    seed: u64,
}

impl Visit for PfProps {
    fn visit<H: MicrosurfaceHeight, S: MicrosurfaceSlope, M: Material + SpecularLimit>(
        &self,
        _h: H,
        s: S,
        m: M,
    ) -> TestCaseResult {
        let (wi, wo) = (self.wi, self.wo);
        let mut rng = Rng::seed_from_u64(self.seed);
        for sh in [Shadowing::Uncorrelated, Shadowing::Correlated] {
            let pf = PositionFree::new(s, m, sh);
            let order = ScatteringOrder::All;
            let pt = pf.eval_pt(wi, wo, order, &mut rng);
            prop_assert!(non_negative(pt), "{m:?} {sh:?} eval_pt({wi}, {wo}) = {pt}");
            let bd = pf.eval_bdpt(wi, wo, order, &mut rng);
            prop_assert!(non_negative(bd), "{m:?} {sh:?} eval_bdpt({wi}, {wo}) = {bd}");
            let single = pf.eval_single_scattering(wi, wo, &mut rng);
            prop_assert!(non_negative(single), "{m:?} {sh:?} eval_single_scattering = {single}");
            prop_assert!(density(pf.pdf(wi, wo)), "{m:?} {sh:?} pdf({wi}, {wo}) = {}", pf.pdf(wi, wo));
            prop_assert!(density(pf.pdf_single(wi, wo)));
            if let Some(smp) = pf.sample(wi, &mut rng) {
                prop_assert!(unit(smp.wo), "{m:?} {sh:?} sample({wi}).wo = {}", smp.wo);
                prop_assert!(bounded_weight(smp.weight), "{m:?} {sh:?} sample weight {}", smp.weight);
            }
            if let Some((w, weight)) = pf.sample_single(wi, &mut rng) {
                prop_assert!(unit(w) && non_negative(weight), "{m:?} {sh:?} sample_single = {w}, {weight}");
            }
        }
        Ok(())
    }
}

struct BsdfProps {
    wo: Vec3,
    wi: Vec3,
    seed: u64,
}

impl Visit for BsdfProps {
    fn visit<H: MicrosurfaceHeight, S: MicrosurfaceSlope, M: Material + SpecularLimit>(
        &self,
        _: H,
        s: S,
        m: M,
    ) -> TestCaseResult {
        let (wo, wi) = (self.wo, self.wi);
        let mut rng = Rng::seed_from_u64(self.seed);
        let mut uniform = || (rand::Rng::next_u32(&mut rng) >> 8) as f32 / 16_777_216.0;
        let techniques = [
            Technique::SingleScattering,
            Technique::RandomWalk,
            Technique::PositionFree { estimator: Estimator::Pt, shadowing: Shadowing::Correlated },
            Technique::PositionFree { estimator: Estimator::Bdpt, shadowing: Shadowing::Uncorrelated },
        ];
        for technique in techniques {
            for transport in [Transport::Radiance, Transport::Importance] {
                let b =
                    MicrofacetBsdf::new(s, m).unwrap().with_technique(technique).with_transport(transport);
                let f = b.eval(wo, wi).f;
                prop_assert!(non_negative(f), "{m:?} {technique:?} eval({wo}, {wi}) = {f}");
                prop_assert!(density(b.pdf(wo, wi)), "{m:?} {technique:?} pdf = {}", b.pdf(wo, wi));
                if let Some(smp) = b.sample(wo, uniform(), Vec2::new(uniform(), uniform())) {
                    prop_assert!(unit(smp.wi), "{m:?} {technique:?} sample({wo}).wi = {}", smp.wi);
                    prop_assert!(smp.pdf > 0.0 && smp.pdf.is_finite(), "pdf {}", smp.pdf);
                    prop_assert!(non_negative(smp.weight), "{m:?} {technique:?} weight {}", smp.weight);
                    // the walks' weights are reflectances/albedos; radiance transport through a
                    // dielectric scales by η², and single scattering by G2/G1 ≤ 1
                    if transport == Transport::Importance || !M::TRANSMITS {
                        prop_assert!(bounded_weight(smp.weight), "{m:?} {technique:?} weight {}", smp.weight);
                    }
                }
            }
        }
        Ok(())
    }
}

proptest! {
    #![proptest_config(config(96, 0x5107_e003))]

    #[test]
    fn walks(
        gaussian in any::<bool>(), beckmann in any::<bool>(), ax in alpha(), ay in alpha(), mat in material(),
        wi in direction(), wo in direction(), seed in any::<u64>(),
    ) {
        dispatch(&WalkProps { wi, wo, seed }, gaussian, beckmann, ax, ay, mat)?;
    }

    #[test]
    fn position_free(
        beckmann in any::<bool>(), ax in alpha(), ay in alpha(), mat in material(),
        wi in direction(), wo in direction(), seed in any::<u64>(),
    ) {
        dispatch(&PfProps { wi, wo, seed }, false, beckmann, ax, ay, mat)?;
    }

    #[test]
    fn microfacet_bsdf(
        gaussian in any::<bool>(), beckmann in any::<bool>(), ax in alpha(), ay in alpha(), mat in material(),
        wo in direction(), wi in direction(), seed in any::<u64>(),
    ) {
        dispatch(&BsdfProps { wo, wi, seed }, gaussian, beckmann, ax, ay, mat)?;
    }
}

// ---------------------------------------------------------------------------------------------
// Visible-normal samplers, classic BRDF, Fresnel, special functions
// ---------------------------------------------------------------------------------------------

fn sampler_props<V: VisibleNormalSampler>(v: V, wi: Vec3, m: Vec3, u: [f32; 3]) -> TestCaseResult {
    let n = v.sample(wi, u);
    prop_assert!(unit(n) && n.z >= 0.0, "{v:?}.sample({wi}, {u:?}) = {n}");
    let p = v.pdf(wi, n);
    prop_assert!(density(p), "{v:?}.pdf({wi}, own sample {n}) = {p}");
    prop_assert!(density(v.pdf(wi, m)), "{v:?}.pdf({wi}, {m}) = {}", v.pdf(wi, m));
    Ok(())
}

fn vcavity_props<S: VCavitySlope>(s: S, wi: Vec3, m: Vec3, u: [f32; 3]) -> TestCaseResult {
    sampler_props(SmithVndf(s), wi, m, u)?;
    sampler_props(VCavity(s), wi, m, u)?;
    let h = VCavity(s).hit_probability(wi);
    prop_assert!((0.0..=1.0 + 1e-6).contains(&h), "H({wi}) = {h}");
    let g = VCavity(s).masking(wi, m);
    prop_assert!((0.0..=1.0).contains(&g), "G({wi}, {m}) = {g}");
    Ok(())
}

fn classic_ndf() -> impl Strategy<Value = ClassicNdf> {
    prop_oneof![
        prop_oneof![0.0f32..1e4, Just(0.0f32), Just(1e6f32)].prop_map(ClassicNdf::Phong),
        alpha().prop_map(ClassicNdf::Beckmann),
        alpha().prop_map(ClassicNdf::Ggx),
    ]
}

proptest! {
    #![proptest_config(config(384, 0x5107_e004))]

    #[test]
    fn vndf_samplers(
        beckmann in any::<bool>(), ax in alpha(), ay in alpha(), wi in direction(), m in direction(),
        u0 in uniform(), u1 in uniform(), u2 in uniform(),
    ) {
        let u = [u0, u1, u2];
        if beckmann {
            let s = Beckmann::new(ax, ay).unwrap();
            vcavity_props(s, wi, m, u)?;
        } else {
            let s = Ggx::new(ax, ay).unwrap();
            vcavity_props(s, wi, m, u)?;
            sampler_props(GgxSphericalCap(s), wi, m, u)?;
            sampler_props(GgxBoundedCap(s), wi, m, u)?;
            sampler_props(GgxDisk(s), wi, m, u)?;
        }
    }

    #[test]
    fn beckmann_newton_sampler(
        ax in alpha(), ay in alpha(), wi in direction(), m in direction(), u0 in uniform(), u1 in uniform(),
    ) {
        sampler_props(BeckmannNewton(Beckmann::new(ax, ay).unwrap()), wi, m, [u0, u1, 0.0])?;
    }

    #[test]
    fn alpha_i_is_positive(beckmann in any::<bool>(), ax in alpha(), ay in alpha(), w in direction()) {
        let ai = if beckmann { Beckmann::new(ax, ay).unwrap().alpha_i(w) } else { Ggx::new(ax, ay).unwrap().alpha_i(w) };
        prop_assert!(ai.is_finite() && ai >= ax.min(ay) * (1.0 - 1e-6) && ai <= ax.max(ay) * (1.0 + 1e-6), "αᵢ({w}) = {ai}");
    }

    #[test]
    fn sample_d_wi_is_unit(beckmann in any::<bool>(), ax in alpha(), ay in alpha(), w in direction(), u1 in uniform(), u2 in uniform()) {
        let n = if beckmann { Beckmann::new(ax, ay).unwrap().sample_d_wi(w, u1, u2) } else { Ggx::new(ax, ay).unwrap().sample_d_wi(w, u1, u2) };
        prop_assert!(unit(n), "sample_d_wi({w}, {u1}, {u2}) = {n}");
    }

    #[test]
    fn classic_d_is_finite_at_grazing(ndf in classic_ndf(), z in prop::sample::select(vec![0.0f32, 1e-12, 1e-20, 1e-30, 1e-38]), phi in 0.0f64..TAU) {
        let b = ClassicBrdf::new(Vec3::splat(0.5), Vec3::splat(0.5), ndf, ClassicMasking::Exact).unwrap();
        let m = Vec3::new(phi.cos() as f32, phi.sin() as f32, z);
        prop_assert!(density(b.d(m)), "{ndf:?} D({m}) = {}", b.d(m));
    }

    #[test]
    fn smith_normalization_is_finite(beckmann in any::<bool>(), ax in alpha(), ay in alpha(), w in direction(), m in direction()) {
        let g = if beckmann {
            smith_normalization(&Beckmann::new(ax, ay).unwrap(), w, m)
        } else {
            smith_normalization(&Ggx::new(ax, ay).unwrap(), w, m)
        };
        prop_assert!(g.is_finite() && g >= 0.0, "smith_normalization({w}, {m}) = {g}");
    }

    #[test]
    fn classic_brdf(
        ndf in classic_ndf(), rational in any::<bool>(), kd in 0.0f32..=1.0, ks in 0.0f32..=1.0,
        wo in direction(), wi in direction(), m in upper_direction(), seed in any::<u64>(),
    ) {
        prop_assume!(kd + ks > 0.0);
        let masking = if rational { ClassicMasking::Rational } else { ClassicMasking::Exact };
        let b = ClassicBrdf::new(Vec3::splat(kd), Vec3::splat(ks), ndf, masking).unwrap();
        let mut rng = Rng::seed_from_u64(seed);
        prop_assert!(density(b.d(m)), "{ndf:?} D({m}) = {}", b.d(m));
        let g1 = b.g1(wi);
        prop_assert!((0.0..=1.0 + 1e-6).contains(&g1), "{ndf:?} G1({wi}) = {g1}");
        let mut uniform = || (rand::Rng::next_u32(&mut rng) >> 8) as f32 / 16_777_216.0;
        let f = b.eval(wo, wi).f;
        prop_assert!(non_negative(f), "{ndf:?} eval({wo}, {wi}) = {f}");
        prop_assert!(density(b.pdf(wo, wi)), "{ndf:?} pdf = {}", b.pdf(wo, wi));
        if let Some(s) = b.sample(wo, uniform(), Vec2::new(uniform(), uniform())) {
            prop_assert!(unit(s.wi) && s.wi.z > 0.0, "{ndf:?} sample({wo}).wi = {}", s.wi);
            prop_assert!(s.pdf > 0.0 && s.pdf.is_finite() && non_negative(s.weight), "{ndf:?} sample {s:?}");
        }
    }

    #[test]
    fn fresnel(c in -1.0f32..=1.0, e in eta(), k in 0.0f32..10.0, f0 in 0.0f32..=1.0) {
        for c in [c, 0.0, 1.0, 1e-7] {
            let fd = fresnel_dielectric(c, e);
            prop_assert!((0.0..=1.0).contains(&fd), "fresnel_dielectric({c}, {e}) = {fd}");
            let ior = ComplexIor::new(Vec3::splat(e), Vec3::splat(k)).unwrap();
            let fc = fresnel_conductor(c, &ior);
            prop_assert!(fc.is_finite() && fc.min_element() >= 0.0 && fc.max_element() <= 1.0, "fresnel_conductor({c}, {e}, {k}) = {fc}");
            let fs = fresnel_schlick(c, Vec3::splat(f0));
            prop_assert!(fs.min_element() >= 0.0 && fs.max_element() <= 1.0, "fresnel_schlick({c}, {f0}) = {fs}");
        }
    }

    #[test]
    fn special_functions(x in prop::num::f32::NORMAL | prop::num::f32::ZERO, y in -1.0f32..=1.0, a in 1e-3f64..1e7, b in 1e-3f64..1e7) {
        for x in [x, f32::INFINITY, f32::NEG_INFINITY] {
            let (e, c) = (erf(x), erfc(x));
            prop_assert!((-1.0..=1.0).contains(&e), "erf({x}) = {e}");
            prop_assert!((0.0..=2.0).contains(&c), "erfc({x}) = {c}");
        }
        for y in [y, 1.0, -1.0, 1.0 - f32::EPSILON / 2.0] {
            prop_assert!(erfinv(y).is_finite(), "erfinv({y}) = {}", erfinv(y));
        }
        prop_assert!(ln_gamma(a).is_finite() && ln_beta(a, b).is_finite(), "ln Γ({a}), ln B({a}, {b})");
        let bt = beta(a, b);
        prop_assert!(bt.is_finite() && bt >= 0.0, "B({a}, {b}) = {bt}");
    }
}

// ---------------------------------------------------------------------------------------------
// Minimal reproductions of the defects found (ignored until fixed)
// ---------------------------------------------------------------------------------------------

#[test]
fn repro_beckmann_newton_u0() {
    let s = BeckmannNewton(Beckmann::isotropic(1.0).unwrap());
    let n = s.sample(Vec3::new(0.495_680_45, 0.0, 0.868_504_94), [0.0, 0.0, 0.0]);
    assert!(unit(n), "{n}");
}

#[test]
fn repro_smith_normalization_overflow() {
    let g = smith_normalization(
        &Ggx::isotropic(1.0).unwrap(),
        Vec3::new(1e-20, 0.0, -1.0),
        Vec3::new(0.073, 0.0, -0.997),
    );
    assert!(g.is_finite(), "{g}");
}

#[test]
fn repro_alpha_i_near_pole() {
    let s = Ggx::new(1e-4, 1.41e-4).unwrap();
    let ai = s.alpha_i(Vec3::new(1e-20, 0.0, -1.0));
    assert!((ai - 1e-4).abs() <= 1e-10, "αᵢ = {ai}, expected αx = 1e-4 at φ = 0");
}

#[test]
fn repro_sample_d_wi_not_unit() {
    let s = Ggx::new(1.0, 0.003_743_211).unwrap();
    let n = s.sample_d_wi(Vec3::new(2.309_54e-21, 9.729_646_5e-21, -1.0), 0.0, 0.0);
    assert!(unit(n), "{n}");
}

#[test]
fn repro_classic_d_grazing() {
    let b = ClassicBrdf::new(Vec3::splat(0.5), Vec3::splat(0.5), ClassicNdf::Ggx(0.5), ClassicMasking::Exact)
        .unwrap();
    let d = b.d(Vec3::new(1.0, 0.0, 1e-12));
    assert!(
        d.is_finite() && (d - 0.25 / std::f32::consts::PI).abs() < 1e-6,
        "GGX D at cos θm = 1e-12: {d}, expected α²/π"
    );
    let b = ClassicBrdf::new(
        Vec3::splat(0.5),
        Vec3::splat(0.5),
        ClassicNdf::Beckmann(0.5),
        ClassicMasking::Exact,
    )
    .unwrap();
    assert_eq!(b.d(Vec3::new(1.0, 0.0, 1e-20)), 0.0);
}

/// The side of the interface for the test tables' `outside` flags.
fn side(outside: bool) -> Side {
    if outside { Side::Outside } else { Side::Inside }
}

// ---------------------------------------------------------------------------------------------
// Flags an integrator can trust (every `Bsdf` type, the whole domain)
// ---------------------------------------------------------------------------------------------

/// The violations of the flags contract found by [`check_flags`], per kind.
#[derive(Default)]
struct FlagsReport {
    cases: usize,
    samples: usize,
    failures: Vec<String>,
}

/// A random direction for the flags fuzz: uniform on the sphere, grazing, at a pole, or
/// drifted in length within the renderer layer's tolerance (renormalized on entry).
fn fuzz_direction(rng: &mut Rng) -> Vec3 {
    use rand::RngExt;
    let z: f64 = match rng.random_range(0..8) {
        0 => *[0.0, 1e-7, -1e-7, 1e-4, -1e-4, 1.0, -1.0].get(rng.random_range(0..7)).unwrap(),
        _ => rng.random_range(-1.0..=1.0),
    };
    let w = dir(z, rng.random_range(0.0..TAU));
    if rng.random_range(0..8) == 0 { w * (1.0 + rng.random_range(-5e-3f32..5e-3)) } else { w }
}

/// A random uniform for the flags fuzz, with 0, 1 − 2⁻²⁴ and exactly 1 over-represented.
fn fuzz_uniform(rng: &mut Rng) -> f32 {
    use rand::RngExt;
    match rng.random_range(0..10) {
        0 => 0.0,
        1 => 1.0 - f32::EPSILON / 2.0,
        2 => 1.0,
        _ => rng.random_range(0.0..1.0),
    }
}

/// The flags contract at one (wo, wi, uniforms) case: with no non-specular lobe, eval and pdf
/// are 0 and every sample is specular; a non-zero eval or pdf needs a non-specular lobe; a
/// sample's flags agree with `flags()` and with eval/pdf at its direction (specular: both 0;
/// otherwise a positive pdf).
fn check_flags(r: &mut FlagsReport, label: &str, b: &dyn Bsdf, rng: &mut Rng) {
    let flags = b.flags();
    let (wo, wi) = (fuzz_direction(rng), fuzz_direction(rng));
    let (uc, u) = (fuzz_uniform(rng), Vec2::new(fuzz_uniform(rng), fuzz_uniform(rng)));
    let key = rand::Rng::next_u64(rng);
    r.cases += 1;
    let mut fail = |what: String| r.failures.push(format!("{label}: {what} ({flags:?})"));
    let f = b.eval_keyed(wo, wi, key).f;
    let p = b.pdf(wo, wi);
    let (v2, p2) = b.eval_with_pdf_keyed(wo, wi, key);
    if (f != Vec3::ZERO || p != 0.0 || v2.f != Vec3::ZERO || p2 != 0.0) && !flags.has_non_specular() {
        fail(format!("no non-specular lobe, yet eval {f} / {} and pdf {p} / {p2} at wo {wo}, wi {wi}", v2.f));
    }
    if let Some(s) = b.sample_keyed(wo, uc, u, key) {
        r.samples += 1;
        let (f_at, p_at) = (b.eval_keyed(wo, s.wi, key).f, b.pdf(wo, s.wi));
        if s.flags.specular {
            if !flags.specular {
                fail(format!("a specular sample {s:?} for wo {wo}, flags without a specular lobe"));
            }
            if f_at != Vec3::ZERO || p_at != 0.0 {
                fail(format!("specular sample {s:?} for wo {wo}: eval {f_at}, pdf {p_at} at its direction"));
            }
        } else {
            if !flags.has_non_specular() {
                fail(format!("a non-specular sample {s:?} for wo {wo}, flags without such a lobe"));
            }
            if p_at.is_nan() || p_at <= 0.0 {
                fail(format!("non-specular sample {s:?} for wo {wo}: pdf {p_at} at its direction"));
            }
        }
        if (s.flags.transmission && !flags.transmission) || (s.flags.reflection && !flags.reflection) {
            fail(format!("sample {s:?} for wo {wo}: event not in the flags"));
        }
    }
}

/// The flags contract (see [`check_flags`]) over the whole domain for every type implementing
/// `Bsdf`: `MicrofacetBsdf` with every technique on conductors, dielectrics (η = 1 included)
/// and diffuse facets, GGX and Beckmann, αx and αy log-uniform in [1e-4, 10] (the smooth limit
/// included), both hemispheres of wo and wi, grazing and drifted directions, uniforms 0 and 1;
/// `ClassicBrdf`; the compensated lobes (α within their tables); `NoncentralBsdf`. A fixed-seed
/// fuzz: every case counts, none may fail.
#[test]
fn flags_agree_with_every_call() {
    use microsurface::{Compensated, Compensation};
    use rand::RngExt;
    const CONFIGS: usize = 48;
    const CASES: usize = 40;
    let mut rng = Rng::seed_from_u64(0xF1A6);
    let mut r = FlagsReport::default();
    let techniques = [
        Technique::SingleScattering,
        Technique::RandomWalk,
        Technique::PositionFree { estimator: Estimator::Pt, shadowing: Shadowing::Correlated },
        Technique::PositionFree { estimator: Estimator::Bdpt, shadowing: Shadowing::Uncorrelated },
    ];
    let log_alpha = |rng: &mut Rng| 10f32.powf(rng.random_range(-4.0f32..=1.0));
    let run = |r: &mut FlagsReport, label: &str, b: &dyn Bsdf, rng: &mut Rng| {
        for _ in 0..CASES {
            check_flags(r, label, b, rng);
        }
    };
    for k in 0..CONFIGS {
        let (ax, ay) = (log_alpha(&mut rng), log_alpha(&mut rng));
        let (ax, ay) = if k % 4 == 0 { (ax, ax) } else { (ax, ay) };
        let eta = match k % 3 {
            0 => 1.0,
            1 => rng.random_range(1.0f32..3.0),
            _ => 1.0 / rng.random_range(1.0f32..3.0),
        };
        let dielectric = Dielectric::new(eta).unwrap();
        let gold = Conductor::new(ComplexIor::GOLD);
        let diffuse = Diffuse::new(Vec3::new(0.8, 0.5, 0.2)).unwrap();
        let ggx = Ggx::new(ax, ay).unwrap();
        let beckmann = Beckmann::new(ax, ay).unwrap();
        for t in techniques {
            let l = format!("α ({ax}, {ay}) η {eta} {t:?}");
            run(
                &mut r,
                &format!("GGX gold {l}"),
                &MicrofacetBsdf::new(ggx, gold).unwrap().with_technique(t),
                &mut rng,
            );
            run(
                &mut r,
                &format!("Beckmann gold {l}"),
                &MicrofacetBsdf::new(beckmann, gold).unwrap().with_technique(t),
                &mut rng,
            );
            run(
                &mut r,
                &format!("GGX glass {l}"),
                &MicrofacetBsdf::new(ggx, dielectric).unwrap().with_technique(t),
                &mut rng,
            );
            run(
                &mut r,
                &format!("Beckmann glass {l}"),
                &MicrofacetBsdf::new(beckmann, dielectric).unwrap().with_technique(t),
                &mut rng,
            );
            run(
                &mut r,
                &format!("GGX diffuse {l}"),
                &MicrofacetBsdf::new(ggx, diffuse).unwrap().with_technique(t),
                &mut rng,
            );
        }
        let classic =
            ClassicBrdf::new(Vec3::splat(0.3), Vec3::splat(0.5), ClassicNdf::Ggx(ax), ClassicMasking::Exact)
                .unwrap();
        run(&mut r, &format!("classic α {ax}"), &classic, &mut rng);
        for scheme in [Compensation::KullaConty, Compensation::Turquin, Compensation::Walk] {
            if let Ok(b) = Compensated::with_scheme(ggx, gold, scheme) {
                run(&mut r, &format!("compensated gold {scheme:?} α ({ax}, {ay})"), &b, &mut rng);
            }
        }
        if let Ok(b) = Compensated::with_scheme(ggx, dielectric, Compensation::Turquin) {
            run(&mut r, &format!("Turquin glass α ({ax}, {ay}) η {eta}"), &b, &mut rng);
        }
        if let Ok(b) = Compensated::with_scheme(ggx, dielectric, Compensation::Walk) {
            run(&mut r, &format!("Kulla-Conty glass α ({ax}, {ay}) η {eta}"), &b, &mut rng);
        }
        #[cfg(feature = "leadr")]
        {
            use microsurface::leadr::{Noncentral, NoncentralBsdf};
            let mean = Vec2::new(rng.random_range(-1.0f32..1.0), rng.random_range(-1.0f32..1.0));
            let b = NoncentralBsdf::new(Noncentral::new(ggx, mean).unwrap(), gold).unwrap();
            run(&mut r, &format!("noncentral α ({ax}, {ay}) mean {mean}"), &b, &mut rng);
        }
    }
    println!("flags: {} cases, {} samples, {} violations", r.cases, r.samples, r.failures.len());
    assert!(
        r.cases >= CONFIGS * CASES * 20 && r.samples > r.cases / 4,
        "{} cases, {} samples",
        r.cases,
        r.samples
    );
    assert!(
        r.failures.is_empty(),
        "{} of {} cases broke the flags contract; the first:\n{}",
        r.failures.len(),
        r.cases,
        r.failures.iter().take(20).cloned().collect::<Vec<_>>().join("\n")
    );
}
