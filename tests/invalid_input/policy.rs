//! The invalid-input policy (README, “Conventions: invalid input”): every public entry point of
//! the research layer and every free function, called with a direction that is NaN, ±∞ in a
//! component, zero or not unit beyond `DIRECTION_TOLERANCE`, or with a NaN or out-of-range
//! scalar (uniform, cosine, η, height, slope), returns its documented *nothing* in release
//! builds (0 for values and densities, `None` or a NaN direction with zero weight for samples,
//! NaN for the other quantities) and trips the debug assertion in debug builds.
//!
//! Every check runs in both modes: [`expect_nothing`] asserts the release result when debug
//! assertions are off (as in CI, `cargo test --release`) and the panic when they are on
//! (`cargo test`). Valid edge input (grazing, exactly horizontal and below-horizon unit
//! directions, signed zeros, lengths within the tolerance) must pass the checks.

use glam::{DVec3, Vec2, Vec3};
use microsurface::Elliptical;
use microsurface::fresnel::{fresnel_conductor, fresnel_dielectric, fresnel_schlick};
use microsurface::leadr::{Noncentral, NoncentralMaterial};
use microsurface::research::Invariance;
use microsurface::research::{
    Estimator, GaussianHeight, HeightSample, Material, Microsurface, MicrosurfaceGeometry,
    MicrosurfaceHeight, PhaseSample, PositionFree, ScatteringOrder, Shadowing, UniformHeight,
    concentric_disk, orthonormal_basis, sample_cosine_hemisphere,
};
use microsurface::research::{Interaction, Side};
use microsurface::slope::MicrosurfaceSlope;
use microsurface::vndf::{
    BeckmannNewton, GgxBoundedCap, GgxDisk, GgxSphericalCap, SmithVndf, VCavity, VCavitySlope,
    VisibleNormalSampler, smith_normalization,
};
use microsurface::{Beckmann, ComplexIor, Conductor, DIRECTION_TOLERANCE, Dielectric, Diffuse, Ggx};
use rand::SeedableRng;
use rand_pcg::Pcg64Mcg;
use std::fmt::Debug;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::Once;

/// The start of the panic message of a contract violation.
const MESSAGE: &str = "invalid input";

/// Silences the panics of contract violations (they are expected by the thousand in debug
/// builds); every other panic is reported by the default hook.
pub(super) fn quiet_violations() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        let default = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            let text = info
                .payload()
                .downcast_ref::<String>()
                .map(String::as_str)
                .or_else(|| info.payload().downcast_ref::<&str>().copied())
                .unwrap_or("");
            if !text.starts_with(MESSAGE) {
                default(info);
            }
        }));
    });
}

/// The failures collected by a test, reported together at its end.
#[derive(Default)]
pub(super) struct Report {
    checked: usize,
    failures: Vec<String>,
}

impl Report {
    /// Checks one call with invalid input: in a debug build it must panic with the
    /// contract-violation message, in a release build it must return a value `is_nothing`
    /// accepts.
    pub(super) fn expect_nothing<T: Debug>(
        &mut self,
        label: &str,
        f: impl FnOnce() -> T,
        is_nothing: impl Fn(&T) -> bool,
    ) {
        self.expect_nothing_saying(label, f, is_nothing, &[]);
    }

    /// [`Report::expect_nothing`], and in a debug build the panic message must contain each of
    /// `needles` (the argument's name and value).
    pub(super) fn expect_nothing_saying<T: Debug>(
        &mut self,
        label: &str,
        f: impl FnOnce() -> T,
        is_nothing: impl Fn(&T) -> bool,
        needles: &[&str],
    ) {
        self.checked += 1;
        if cfg!(debug_assertions) {
            match catch_unwind(AssertUnwindSafe(f)) {
                Ok(v) => self.failures.push(format!("{label}: no debug assertion, returned {v:?}")),
                Err(payload) => {
                    let text = payload
                        .downcast_ref::<String>()
                        .cloned()
                        .or_else(|| payload.downcast_ref::<&str>().map(|s| s.to_string()))
                        .unwrap_or_default();
                    if !text.starts_with(MESSAGE) || !needles.iter().all(|n| text.contains(n)) {
                        self.failures.push(format!("{label}: panicked with an unexpected message: {text}"));
                    }
                }
            }
        } else {
            let v = f();
            if !is_nothing(&v) {
                self.failures.push(format!("{label}: returned {v:?}, not the documented nothing"));
            }
        }
    }

    /// Checks one call with valid input: it must not panic (in either mode) and its result must
    /// satisfy `ok`.
    pub(super) fn expect_valid<T: Debug>(
        &mut self,
        label: &str,
        f: impl FnOnce() -> T,
        ok: impl Fn(&T) -> bool,
    ) {
        self.checked += 1;
        match catch_unwind(AssertUnwindSafe(f)) {
            Ok(v) if ok(&v) => {}
            Ok(v) => self.failures.push(format!("{label}: valid input gave {v:?}")),
            Err(_) => self.failures.push(format!("{label}: valid input panicked")),
        }
    }

    pub(super) fn finish(self, name: &str, at_least: usize) {
        println!("{name}: {} calls checked", self.checked);
        assert!(self.checked >= at_least, "{name}: only {} calls checked", self.checked);
        assert!(
            self.failures.is_empty(),
            "{name}: {} of {} calls broke the policy:\n{}",
            self.failures.len(),
            self.checked,
            self.failures.join("\n")
        );
    }
}

fn zero(v: &Vec3) -> bool {
    *v == Vec3::ZERO
}
fn zero32(v: &f32) -> bool {
    *v == 0.0
}
fn zero64(v: &f64) -> bool {
    *v == 0.0
}
fn nan32(v: &f32) -> bool {
    v.is_nan()
}
fn nan64(v: &f64) -> bool {
    v.is_nan()
}
fn nan_vec(v: &Vec3) -> bool {
    v.x.is_nan() && v.y.is_nan() && v.z.is_nan()
}
fn nan_vec2(v: &Vec2) -> bool {
    v.x.is_nan() && v.y.is_nan()
}
fn no_phase_sample(s: &PhaseSample) -> bool {
    nan_vec(&s.wo) && s.weight == Vec3::ZERO
}

/// A unit direction above the horizon and one below it.
fn good() -> Vec3 {
    Vec3::new(0.36, 0.48, 0.8)
}
fn good_below() -> Vec3 {
    Vec3::new(-0.3, 0.2, -0.5).normalize()
}

/// Directions that violate the contract: NaN and ±∞ components, zero (both signs), and
/// lengths outside the tolerance (just outside it, twice, half, tiny, huge).
fn bad_directions() -> Vec<Vec3> {
    let w = good();
    vec![
        Vec3::NAN,
        Vec3::new(f32::NAN, 0.0, 1.0),
        Vec3::new(0.0, 0.0, f32::NAN),
        Vec3::new(f32::INFINITY, 0.0, 0.0),
        Vec3::new(f32::NEG_INFINITY, 0.0, 1.0),
        Vec3::new(0.0, 0.0, f32::INFINITY),
        Vec3::new(0.0, 0.0, f32::NEG_INFINITY),
        Vec3::ZERO,
        Vec3::new(-0.0, 0.0, -0.0),
        2.0 * w,
        0.5 * w,
        (1.0 + DIRECTION_TOLERANCE) * w,
        (1.0 - DIRECTION_TOLERANCE) * w,
        Vec3::ONE,
        Vec3::new(1e-30, 0.0, 1e-30),
        Vec3::new(0.0, 1e30, 1e30),
    ]
}

/// Uniforms outside [0, 1].
const BAD_UNIFORMS: [f32; 5] = [f32::NAN, -0.25, 1.5, f32::INFINITY, f32::NEG_INFINITY];
/// Cosines beyond ±(1 + tolerance).
const BAD_COSINES: [f32; 5] = [f32::NAN, 1.5, -2.0, f32::INFINITY, f32::NEG_INFINITY];
/// Relative indices that are not finite and > 0.
const BAD_ETAS: [f32; 6] = [f32::NAN, 0.0, -0.0, -1.5, f32::INFINITY, f32::NEG_INFINITY];

fn rng() -> Pcg64Mcg {
    Pcg64Mcg::seed_from_u64(12)
}

fn check_slope<S: MicrosurfaceSlope>(r: &mut Report, name: &str, s: S) {
    for b in bad_directions() {
        let l = format!("{name} ω = {b}");
        r.expect_nothing(&format!("{l}: d"), || s.d(b), zero32);
        r.expect_nothing(&format!("{l}: d64"), || s.d64(b.as_dvec3()), zero64);
        r.expect_nothing(&format!("{l}: lambda"), || s.lambda(b), nan32);
        r.expect_nothing(&format!("{l}: projected_area"), || s.projected_area(b), nan32);
        r.expect_nothing(&format!("{l}: alpha_i"), || s.alpha_i(b), nan32);
        r.expect_nothing(&format!("{l}: d_wi(bad, good)"), || s.d_wi(b, good()), zero32);
        r.expect_nothing(&format!("{l}: d_wi(good, bad)"), || s.d_wi(good(), b), zero32);
        r.expect_nothing(&format!("{l}: d_wi64(bad, good)"), || s.d_wi64(b, good().as_dvec3()), zero64);
        r.expect_nothing(&format!("{l}: d_wi64(good, bad)"), || s.d_wi64(good(), b.as_dvec3()), zero64);
        r.expect_nothing(&format!("{l}: sample_d_wi"), || s.sample_d_wi(b, 0.5, 0.5), nan_vec);
    }
    r.expect_nothing(&format!("{name}: d64 of a NaN DVec3"), || s.d64(DVec3::NAN), zero64);
    for u in BAD_UNIFORMS {
        let l = format!("{name} u = {u}");
        r.expect_nothing(&format!("{l}: sample_d_wi u1"), || s.sample_d_wi(good(), u, 0.5), nan_vec);
        r.expect_nothing(&format!("{l}: sample_d_wi u2"), || s.sample_d_wi(good(), 0.5, u), nan_vec);
    }
    r.expect_nothing(&format!("{name}: p22(NaN, 0)"), || s.p22(f32::NAN, 0.0), zero32);
    r.expect_nothing(&format!("{name}: p22(0, NaN)"), || s.p22(0.0, f32::NAN), zero32);
    // infinite slopes are valid (horizontal normals): density 0
    r.expect_valid(&format!("{name}: p22(∞, 0)"), || s.p22(f32::INFINITY, 0.0), zero32);
}

/// The stretched-space primitive `sample_p22_11` of the axis-aligned slopes (an inherent
/// method: it is not part of the `MicrosurfaceSlope` contract).
fn check_p22_11(r: &mut Report, name: &str, f: impl Fn(f32, f32, f32, f32) -> Vec2) {
    for b in bad_directions() {
        // (sin θ, cos θ) pairs of a bad direction in the plane y = 0
        r.expect_nothing(&format!("{name} ω = {b}: sample_p22_11"), || f(b.z, b.x.abs(), 0.5, 0.5), nan_vec2);
    }
    r.expect_nothing(&format!("{name}: sample_p22_11 with sin θ < 0"), || f(0.8, -0.6, 0.5, 0.5), nan_vec2);
    for u in BAD_UNIFORMS {
        let l = format!("{name} u = {u}");
        r.expect_nothing(&format!("{l}: sample_p22_11 u1"), || f(0.8, 0.6, u, 0.5), nan_vec2);
        r.expect_nothing(&format!("{l}: sample_p22_11 u2"), || f(0.8, 0.6, 0.5, u), nan_vec2);
    }
}

/// The inherent queries of a noncentral slope (Dupuy 2015, thesis §3.2): D, G1, D_ωi, the
/// sampler and single scattering with each material.
fn check_noncentral<S: MicrosurfaceSlope>(r: &mut Report, name: &str, s: Noncentral<S>) {
    for b in bad_directions() {
        let l = format!("{name} ω = {b}");
        r.expect_nothing(&format!("{l}: d"), || s.d(b), zero32);
        r.expect_nothing(&format!("{l}: d64"), || s.d64(b.as_dvec3()), zero64);
        r.expect_nothing(&format!("{l}: g1"), || s.g1(b), nan32);
        r.expect_nothing(&format!("{l}: projected_area"), || s.projected_area(b), nan32);
        r.expect_nothing(&format!("{l}: d_wi(bad, good)"), || s.d_wi(b, good()), zero32);
        r.expect_nothing(&format!("{l}: d_wi(good, bad)"), || s.d_wi(good(), b), zero32);
        r.expect_nothing(&format!("{l}: sample_d_wi"), || s.sample_d_wi(b, 0.5, 0.5), nan_vec);
    }
    for u in BAD_UNIFORMS {
        let l = format!("{name} u = {u}");
        r.expect_nothing(&format!("{l}: sample_d_wi u1"), || s.sample_d_wi(good(), u, 0.5), nan_vec);
        r.expect_nothing(&format!("{l}: sample_d_wi u2"), || s.sample_d_wi(good(), 0.5, u), nan_vec);
    }
    check_noncentral_material(r, &format!("{name} gold"), &s, &Conductor::new(ComplexIor::GOLD));
    check_noncentral_material(r, &format!("{name} glass"), &s, &Dielectric::new(1.5).unwrap());
    check_noncentral_material(r, &format!("{name} diffuse"), &s, &Diffuse::white());
}

/// Single scattering of a material on a noncentral slope with bad directions.
fn check_noncentral_material<S: MicrosurfaceSlope, M: NoncentralMaterial>(
    r: &mut Report,
    name: &str,
    s: &Noncentral<S>,
    material: &M,
) {
    for b in bad_directions() {
        let l = format!("{name} ω = {b}");
        for (wi, wo, slot) in [(b, good(), "ωi"), (good(), b, "ωo")] {
            r.expect_nothing(
                &format!("{l} {slot}: eval_single_scattering"),
                || s.eval_single_scattering(material, wi, wo, &mut Pcg64Mcg::seed_from_u64(1)),
                zero,
            );
            r.expect_nothing(
                &format!("{l} {slot}: pdf_single_scattering"),
                || s.pdf_single_scattering(material, wi, wo),
                zero32,
            );
        }
        r.expect_nothing(
            &format!("{l}: sample_single_scattering"),
            || s.sample_single_scattering(material, b, &mut Pcg64Mcg::seed_from_u64(2)),
            Option::is_none,
        );
    }
    // valid directions below the base plane: the model's 0 or the dielectric's inside view
    let f = s.eval_single_scattering(material, good_below(), good(), &mut Pcg64Mcg::seed_from_u64(3));
    r.expect_valid(&format!("{name}: eval from below"), || f, |f| f.is_finite());
}

fn check_height<H: MicrosurfaceHeight>(r: &mut Report, name: &str, h: H) {
    r.expect_nothing(&format!("{name}: p1(NaN)"), || h.p1(f32::NAN), zero32);
    r.expect_nothing(&format!("{name}: c1(NaN)"), || h.c1(f32::NAN), nan32);
    for u in BAD_UNIFORMS {
        r.expect_nothing(&format!("{name}: inv_c1({u})"), || h.inv_c1(u), nan32);
    }
    r.expect_valid(&format!("{name}: c1(+∞)"), || h.c1(f32::INFINITY), |c| *c == 1.0);
    r.expect_valid(&format!("{name}: c1(−∞)"), || h.c1(f32::NEG_INFINITY), |c| *c == 0.0);
    let g = MicrosurfaceGeometry::new(h, Ggx::isotropic(0.5).unwrap());
    let no_height = |s: &HeightSample| matches!(s, HeightSample::Hit(x) if x.is_nan());
    for b in bad_directions() {
        let l = format!("{name} geometry ω = {b}");
        r.expect_nothing(&format!("{l}: g1"), || g.g1(b), nan32);
        r.expect_nothing(&format!("{l}: g1_at"), || g.g1_at(b, 0.0), nan32);
        r.expect_nothing(&format!("{l}: sample_height"), || g.sample_height(b, 0.0, 0.5), no_height);
    }
    r.expect_nothing(&format!("{name}: g1_at(h = NaN)"), || g.g1_at(good(), f32::NAN), nan32);
    r.expect_nothing(
        &format!("{name}: sample_height(h0 = NaN)"),
        || g.sample_height(good(), f32::NAN, 0.5),
        no_height,
    );
    for u in BAD_UNIFORMS {
        r.expect_nothing(
            &format!("{name}: sample_height(u = {u})"),
            || g.sample_height(good(), 0.0, u),
            no_height,
        );
    }
    r.expect_valid(&format!("{name}: g1_at(h = +∞)"), || g.g1_at(good(), f32::INFINITY), |v| *v == 1.0);
}

fn check_material<S: MicrosurfaceSlope, M: Material>(r: &mut Report, name: &str, s: S, m: M) {
    let mut rng = rng();
    let surface = Microsurface::new(UniformHeight, s, m);
    let pf = |shadowing| PositionFree::new(s, m, shadowing);
    let invariance = Invariance::new(s, m).ok();
    let all = ScatteringOrder::All;
    for b in bad_directions() {
        for (wi, wo, slot) in [(b, good(), "ωi"), (good(), b, "ωo")] {
            let l = format!("{name} {slot} = {b}");
            let ws = [(true, true), (true, false), (false, true), (false, false)];
            for (io, oo) in ws {
                if !(M::TRANSMITS || io && oo) {
                    continue;
                }
                let l = format!("{l} sides ({io}, {oo})");
                r.expect_nothing(
                    &format!("{l}: eval_phase"),
                    || m.eval_phase(&s, &Interaction::new(wi, wo, side(io), side(oo)), &mut rng),
                    zero,
                );
                r.expect_nothing(
                    &format!("{l}: pdf_phase"),
                    || m.pdf_phase(&s, &Interaction::new(wi, wo, side(io), side(oo))),
                    zero32,
                );
                r.expect_nothing(
                    &format!("{l}: vertex"),
                    || m.vertex(&s, &Interaction::new(wi, wo, side(io), side(oo)), &mut rng),
                    zero,
                );
                r.expect_nothing(
                    &format!("{l}: connection"),
                    || m.connection(&s, &Interaction::new(wi, wo, side(io), side(oo)), &mut rng),
                    |c| *c == (Vec3::ZERO, 0.0, 0.0),
                );
            }
            r.expect_nothing(
                &format!("{l}: material eval_single_scattering"),
                || m.eval_single_scattering(&s, wi, wo, &mut rng),
                zero,
            );
            r.expect_nothing(
                &format!("{l}: Microsurface::eval"),
                || surface.eval(wi, wo, all, &mut rng),
                zero,
            );
            r.expect_nothing(
                &format!("{l}: Microsurface::eval(only 1)"),
                || surface.eval(wi, wo, ScatteringOrder::only(1).unwrap(), &mut rng),
                zero,
            );
            if let Some(inv) = &invariance {
                r.expect_nothing(&format!("{l}: Invariance::eval"), || inv.eval(wi, wo, all, &mut rng), zero);
            }
            r.expect_nothing(
                &format!("{l}: Microsurface::eval_phase"),
                || surface.eval_phase(wi, wo, &mut rng),
                zero,
            );
            r.expect_nothing(
                &format!("{l}: Microsurface::eval_single_scattering"),
                || surface.eval_single_scattering(wi, wo, &mut rng),
                zero,
            );
            for shadowing in [Shadowing::Uncorrelated, Shadowing::Correlated] {
                let p = pf(shadowing);
                let l = format!("{l} {shadowing:?}");
                r.expect_nothing(&format!("{l}: eval_pt"), || p.eval_pt(wi, wo, all, &mut rng), zero);
                r.expect_nothing(&format!("{l}: eval_bdpt"), || p.eval_bdpt(wi, wo, all, &mut rng), zero);
                for e in [Estimator::Pt, Estimator::Bdpt] {
                    r.expect_nothing(&format!("{l}: eval({e:?})"), || p.eval(wi, wo, e, all, &mut rng), zero);
                }
                r.expect_nothing(
                    &format!("{l}: eval_single_scattering"),
                    || p.eval_single_scattering(wi, wo, &mut rng),
                    zero,
                );
                r.expect_nothing(&format!("{l}: pdf"), || p.pdf(wi, wo), zero32);
                r.expect_nothing(&format!("{l}: pdf_single"), || p.pdf_single(wi, wo), zero32);
            }
        }
        let l = format!("{name} ωi = {b}");
        for outside in [true, false] {
            if !M::TRANSMITS && !outside {
                continue;
            }
            r.expect_nothing(
                &format!("{l}: sample_phase({outside})"),
                || m.sample_phase(&s, b, side(outside), &mut rng),
                no_phase_sample,
            );
        }
        r.expect_nothing(
            &format!("{l}: Microsurface::sample"),
            || surface.sample(b, &mut rng),
            Option::is_none,
        );
        if let Some(inv) = &invariance {
            r.expect_nothing(
                &format!("{l}: Invariance::sample"),
                || inv.sample(b, &mut rng),
                Option::is_none,
            );
        }
        r.expect_nothing(
            &format!("{l}: Microsurface::sample_phase"),
            || surface.sample_phase(b, &mut rng),
            no_phase_sample,
        );
        for shadowing in [Shadowing::Uncorrelated, Shadowing::Correlated] {
            let p = pf(shadowing);
            r.expect_nothing(
                &format!("{l} {shadowing:?}: sample"),
                || p.sample(b, &mut rng),
                Option::is_none,
            );
            r.expect_nothing(
                &format!("{l} {shadowing:?}: sample_single"),
                || p.sample_single(b, &mut rng),
                Option::is_none,
            );
        }
    }
}

fn check_sampler<V: VisibleNormalSampler>(r: &mut Report, name: &str, v: V) {
    for b in bad_directions() {
        let l = format!("{name} {b}");
        r.expect_nothing(&format!("{l}: sample"), || v.sample(b, [0.5; 3]), nan_vec);
        r.expect_nothing(&format!("{l}: pdf(bad, good)"), || v.pdf(b, good()), zero32);
        r.expect_nothing(&format!("{l}: pdf(good, bad)"), || v.pdf(good(), b), zero32);
    }
    for u in BAD_UNIFORMS {
        for k in 0..3 {
            let mut us = [0.5; 3];
            us[k] = u;
            for wi in [good(), good_below()] {
                r.expect_nothing(
                    &format!("{name} wi = {wi} u = {us:?}: sample"),
                    || v.sample(wi, us),
                    nan_vec,
                );
            }
        }
    }
}

fn check_vcavity_slope<S: VCavitySlope>(r: &mut Report, name: &str, s: S) {
    let vc = VCavity(s);
    for b in bad_directions() {
        let l = format!("{name} {b}");
        r.expect_nothing(&format!("{l}: hit_probability"), || s.hit_probability(b), nan32);
        r.expect_nothing(&format!("{l}: VCavity::hit_probability"), || vc.hit_probability(b), nan32);
        r.expect_nothing(&format!("{l}: ln_hit_probability"), || s.ln_hit_probability(b), nan64);
        r.expect_nothing(
            &format!("{l}: projected_branch_probability"),
            || s.projected_branch_probability(b),
            nan64,
        );
        // defined for backfacing directions (and the horizon) only: above it, the nothing
        // (the Beckmann form evaluated erfcx outside its domain and panicked there)
        for above in [Vec3::Z, Vec3::new(0.6, 0.0, 0.8)] {
            r.expect_nothing(
                &format!("{name}: projected_branch_probability({above})"),
                || s.projected_branch_probability(above),
                nan64,
            );
        }
        r.expect_nothing(&format!("{l}: ln_d"), || s.ln_d(b), |x| *x == f64::NEG_INFINITY);
        r.expect_nothing(&format!("{l}: masking(bad, good)"), || vc.masking(b, good()), nan32);
        r.expect_nothing(&format!("{l}: masking(good, bad)"), || vc.masking(good(), b), nan32);
        r.expect_nothing(
            &format!("{l}: smith_normalization(bad, good)"),
            || smith_normalization(&s, b, good()),
            nan32,
        );
        r.expect_nothing(
            &format!("{l}: smith_normalization(good, bad)"),
            || smith_normalization(&s, good(), b),
            nan32,
        );
        r.expect_nothing(
            &format!("{l}: sample_unmasked"),
            || s.sample_unmasked(b, -Vec3::Z, 0.5, 0.5),
            nan_vec,
        );
        let len_sq = b.length_squared();
        if !(f32::MIN_POSITIVE..=f32::MAX).contains(&len_sq) {
            // plane normals may have any length whose square is a normal f32
            r.expect_nothing(&format!("{l}: frontfacing_proportion"), || s.frontfacing_proportion(b), nan32);
            r.expect_nothing(&format!("{l}: sample_projected"), || s.sample_projected(b, 0.5, 0.5), nan_vec);
            r.expect_nothing(
                &format!("{l}: sample_unmasked(k)"),
                || s.sample_unmasked(good_below(), b, 0.5, 0.5),
                nan_vec,
            );
        } else {
            r.expect_valid(
                &format!("{l}: frontfacing_proportion"),
                || s.frontfacing_proportion(b),
                |p| (0.0..=1.0).contains(p),
            );
        }
    }
    for u in BAD_UNIFORMS {
        r.expect_nothing(
            &format!("{name} u = {u}: sample_projected"),
            || s.sample_projected(Vec3::Z, u, 0.5),
            nan_vec,
        );
        r.expect_nothing(
            &format!("{name} u = {u}: sample_unmasked"),
            || s.sample_unmasked(good_below(), Vec3::new(0.3, 0.2, -1.5), 0.5, u),
            nan_vec,
        );
    }
}

#[test]
fn slopes_and_heights() {
    quiet_violations();
    let mut r = Report::default();
    check_slope(&mut r, "GGX", Ggx::new(0.5, 0.2).unwrap());
    check_slope(&mut r, "Beckmann", Beckmann::new(0.5, 0.2).unwrap());
    let (ggx, beckmann) = (Ggx::new(0.5, 0.2).unwrap(), Beckmann::new(0.5, 0.2).unwrap());
    check_p22_11(&mut r, "GGX", |c, s, u1, u2| ggx.sample_p22_11(c, s, u1, u2));
    check_p22_11(&mut r, "Beckmann", |c, s, u1, u2| beckmann.sample_p22_11(c, s, u1, u2));
    check_slope(&mut r, "elliptical GGX", Elliptical::<Ggx>::from_bivariate(0.5, 0.2, 0.6).unwrap());
    check_slope(&mut r, "elliptical Beckmann", Elliptical::<Beckmann>::from_ellipse(0.5, 0.2, 0.7).unwrap());
    check_noncentral(
        &mut r,
        "noncentral Beckmann",
        Noncentral::new(Beckmann::new(0.5, 0.2).unwrap(), Vec2::new(0.4, -0.3)).unwrap(),
    );
    check_noncentral(
        &mut r,
        "noncentral elliptical GGX",
        Noncentral::new(Elliptical::<Ggx>::from_bivariate(0.5, 0.2, -0.6).unwrap(), Vec2::new(-0.5, 0.2))
            .unwrap(),
    );
    check_height(&mut r, "uniform", UniformHeight);
    check_height(&mut r, "Gaussian", GaussianHeight);
    r.finish("slopes_and_heights", 500);
}

#[test]
fn materials_walks_and_position_free() {
    quiet_violations();
    let mut r = Report::default();
    let gold = ComplexIor::GOLD;
    let ggx = Ggx::isotropic(0.5).unwrap();
    let beckmann = Beckmann::isotropic(0.5).unwrap();
    check_material(&mut r, "GGX perfect conductor", ggx, Conductor::perfect());
    check_material(&mut r, "GGX gold", ggx, Conductor::new(gold));
    check_material(&mut r, "GGX diffuse", ggx, Diffuse::white());
    check_material(&mut r, "GGX dielectric", ggx, Dielectric::new(1.5).unwrap());
    check_material(&mut r, "Beckmann gold", beckmann, Conductor::new(gold));
    check_material(&mut r, "Beckmann dielectric", beckmann, Dielectric::new(1.0 / 1.5).unwrap());
    let elliptical = Elliptical::<Ggx>::from_bivariate(0.5, 0.3, 0.5).unwrap();
    check_material(&mut r, "elliptical GGX gold", elliptical, Conductor::new(gold));
    check_material(&mut r, "elliptical GGX dielectric", elliptical, Dielectric::new(1.5).unwrap());
    for c in BAD_COSINES {
        r.expect_nothing(&format!("Conductor::fresnel({c})"), || Conductor::new(gold).fresnel(c), nan_vec);
    }
    r.finish("materials_walks_and_position_free", 3000);
}

#[test]
fn visible_normal_samplers() {
    quiet_violations();
    let mut r = Report::default();
    let ggx = Ggx::new(0.5, 0.2).unwrap();
    let beckmann = Beckmann::new(0.5, 0.2).unwrap();
    check_sampler(&mut r, "SmithVndf<GGX>", SmithVndf(ggx));
    check_sampler(&mut r, "SmithVndf<Beckmann>", SmithVndf(beckmann));
    check_sampler(&mut r, "GgxSphericalCap", GgxSphericalCap(ggx));
    check_sampler(&mut r, "GgxBoundedCap", GgxBoundedCap(ggx));
    check_sampler(&mut r, "GgxDisk", GgxDisk(ggx));
    check_sampler(&mut r, "BeckmannNewton", BeckmannNewton(beckmann));
    check_sampler(&mut r, "VCavity<GGX>", VCavity(ggx));
    check_sampler(&mut r, "VCavity<Beckmann>", VCavity(beckmann));
    check_vcavity_slope(&mut r, "GGX", ggx);
    check_vcavity_slope(&mut r, "Beckmann", beckmann);
    r.finish("visible_normal_samplers", 500);
}

#[test]
fn fresnel_and_frame_helpers() {
    quiet_violations();
    let mut r = Report::default();
    for c in BAD_COSINES {
        r.expect_nothing(&format!("fresnel_dielectric({c}, 1.5)"), || fresnel_dielectric(c, 1.5), nan32);
        r.expect_nothing(
            &format!("fresnel_conductor({c}, gold)"),
            || fresnel_conductor(c, &ComplexIor::GOLD),
            nan_vec,
        );
        r.expect_nothing(
            &format!("fresnel_schlick({c}, 0.04)"),
            || fresnel_schlick(c, Vec3::splat(0.04)),
            nan_vec,
        );
    }
    for eta in BAD_ETAS {
        r.expect_nothing(&format!("fresnel_dielectric(0.5, {eta})"), || fresnel_dielectric(0.5, eta), nan32);
    }
    for f0 in [Vec3::NAN, Vec3::new(0.5, -0.1, 0.5), Vec3::new(0.5, 0.5, 1.5), Vec3::splat(f32::INFINITY)] {
        r.expect_nothing(&format!("fresnel_schlick(0.5, {f0})"), || fresnel_schlick(0.5, f0), nan_vec);
    }
    for b in bad_directions() {
        r.expect_nothing(
            &format!("orthonormal_basis({b})"),
            || orthonormal_basis(b),
            |(t, s)| nan_vec(t) && nan_vec(s),
        );
    }
    for u in BAD_UNIFORMS {
        r.expect_nothing(&format!("concentric_disk({u}, 0.5)"), || concentric_disk(u, 0.5), nan_vec2);
        r.expect_nothing(&format!("concentric_disk(0.5, {u})"), || concentric_disk(0.5, u), nan_vec2);
        r.expect_nothing(
            &format!("sample_cosine_hemisphere({u}, 0.5)"),
            || sample_cosine_hemisphere(u, 0.5),
            nan_vec,
        );
        r.expect_nothing(
            &format!("sample_cosine_hemisphere(0.5, {u})"),
            || sample_cosine_hemisphere(0.5, u),
            nan_vec,
        );
    }
    // valid edge cases of the same functions
    r.expect_valid(
        "fresnel_dielectric(1 + 1e-4, 1.5)",
        || fresnel_dielectric(1.0 + 1e-4, 1.5),
        |f| (0.0..=1.0).contains(f),
    );
    r.expect_valid(
        "fresnel_dielectric(−0.5, 1.5)",
        || fresnel_dielectric(-0.5, 1.5),
        |f| (0.0..=1.0).contains(f),
    );
    r.expect_valid("fresnel_dielectric(0, 1)", || fresnel_dielectric(0.0, 1.0), |f| (0.0..=1.0).contains(f));
    r.expect_valid(
        "orthonormal_basis(−z)",
        || orthonormal_basis(Vec3::NEG_Z),
        |(t, b)| t.is_finite() && b.is_finite(),
    );
    r.expect_valid("concentric_disk(1, 0)", || concentric_disk(1.0, 0.0), |d| d.is_finite());
    r.finish("fresnel_and_frame_helpers", 60);
}

/// Inputs outside the domain that a looser check would answer with a plausible number: each
/// must get the documented nothing.
#[test]
fn the_reported_cases_return_nothing() {
    quiet_violations();
    let mut r = Report::default();
    let mut rng = rng();
    let ggx = Ggx::isotropic(0.5).unwrap();
    let surface = Microsurface::new(UniformHeight, ggx, Conductor::new(ComplexIor::GOLD));
    let w = Vec3::new(0.3, 0.0, 0.954).normalize();
    // a NaN component with a valid z: the walk used to run and return ωo = +z, weight F
    let nan_x = Vec3::new(f32::NAN, 0.0, 1.0);
    r.expect_nothing(
        "Microsurface::sample((NaN, 0, 1))",
        || surface.sample(nan_x, &mut rng),
        Option::is_none,
    );
    r.expect_nothing("sample_phase(0)", || surface.sample_phase(Vec3::ZERO, &mut rng), no_phase_sample);
    let pf = PositionFree::new(ggx, Conductor::perfect(), Shadowing::Correlated);
    r.expect_nothing("PositionFree::pdf((NaN, 0, 1), +z)", || pf.pdf(nan_x, Vec3::Z), zero32);
    r.expect_nothing("eval(2ω, +z)", || surface.eval(2.0 * w, Vec3::Z, ScatteringOrder::All, &mut rng), zero);
    r.expect_nothing("fresnel_dielectric(NaN, 1.5)", || fresnel_dielectric(f32::NAN, 1.5), nan32);
    r.expect_nothing("fresnel_dielectric(0.5, −1.5)", || fresnel_dielectric(0.5, -1.5), nan32);
    r.expect_nothing("lambda(NaN)", || ggx.lambda(Vec3::NAN), nan32);
    r.finish("the_reported_cases_return_nothing", 7);
}

/// Valid edge input keeps working: grazing, exactly horizontal (both signed zeros) and
/// below-horizon unit directions, the poles, and lengths inside the tolerance, through every
/// kind of entry point. None may trip the check, and the results are finite (and positive
/// where the configuration has a contribution).
#[test]
fn valid_edge_directions_pass_the_checks() {
    quiet_violations();
    let mut r = Report::default();
    let mut rng = rng();
    let inside = (1.0 + 0.4 * DIRECTION_TOLERANCE) * good();
    let edges = [
        Vec3::new(0.6, 0.8, 0.0),
        Vec3::new(0.6, 0.8, -0.0),
        Vec3::new(0.6, 0.8, 1e-7).normalize(),
        Vec3::new(0.6, 0.8, -1e-7).normalize(),
        Vec3::Z,
        Vec3::NEG_Z,
        good_below(),
        inside,
        (1.0 - 0.4 * DIRECTION_TOLERANCE) * good(),
    ];
    let ggx = Ggx::isotropic(0.5).unwrap();
    let beckmann = Beckmann::isotropic(0.5).unwrap();
    let conductor = Microsurface::new(UniformHeight, ggx, Conductor::perfect());
    let dielectric = Microsurface::new(GaussianHeight, beckmann, Dielectric::new(1.5).unwrap());
    let pf = PositionFree::new(beckmann, Dielectric::new(1.5).unwrap(), Shadowing::Correlated);
    let finite = |v: &Vec3| v.is_finite() && v.min_element() >= 0.0;
    for w in edges {
        // (Λ at z = −0 is tested separately, tests/invalid_input/negative_zero.rs)
        if w.z != 0.0 || w.z.is_sign_positive() {
            r.expect_valid(&format!("GGX lambda({w})"), || ggx.lambda(w), |x| x.is_finite());
        }
        r.expect_valid(&format!("Beckmann lambda({w})"), || beckmann.lambda(w), |x| x.is_finite());
        r.expect_valid(
            &format!("GGX projected_area({w})"),
            || ggx.projected_area(w),
            |x| x.is_finite() && *x >= 0.0,
        );
        r.expect_valid(&format!("sample_d_wi({w})"), || beckmann.sample_d_wi(w, 0.3, 0.7), |m| m.is_finite());
        r.expect_valid(
            &format!("GgxDisk sample({w})"),
            || GgxDisk(ggx).sample(w, [0.3, 0.7, 0.1]),
            |m| m.is_finite(),
        );
        r.expect_valid(
            &format!("VCavity sample({w})"),
            || VCavity(beckmann).sample(w, [0.3, 0.7, 0.1]),
            |m| m.is_finite(),
        );
        r.expect_valid(
            &format!("orthonormal_basis({w})"),
            || orthonormal_basis(w),
            |(t, b)| t.is_finite() && b.is_finite(),
        );
        for wo in edges {
            r.expect_valid(
                &format!("conductor eval({w}, {wo})"),
                || conductor.eval(w, wo, ScatteringOrder::All, &mut rng),
                finite,
            );
            r.expect_valid(
                &format!("dielectric eval({w}, {wo})"),
                || dielectric.eval(w, wo, ScatteringOrder::All, &mut rng),
                finite,
            );
            r.expect_valid(
                &format!("dielectric eval_phase({w}, {wo})"),
                || dielectric.eval_phase(w, wo, &mut rng),
                finite,
            );
            r.expect_valid(
                &format!("pf eval_bdpt({w}, {wo})"),
                || pf.eval_bdpt(w, wo, ScatteringOrder::All, &mut rng),
                finite,
            );
            r.expect_valid(&format!("pf pdf({w}, {wo})"), || pf.pdf(w, wo), |p| p.is_finite() && *p >= 0.0);
        }
        r.expect_valid(
            &format!("dielectric sample_phase({w})"),
            || dielectric.sample_phase(w, &mut rng),
            |s| s.wo.is_finite(),
        );
        r.expect_valid(
            &format!("dielectric sample({w})"),
            || dielectric.sample(w, &mut rng),
            |s| s.is_none_or(|s| s.wo.is_finite()),
        );
    }
    // a length inside the tolerance is evaluated, not rejected: the single-scattering value at
    // (1 + 4e-4)·ω is within 1e-2 of the value at ω
    let exact = conductor.eval_single_scattering(good(), Vec3::Z, &mut rng).x;
    r.expect_valid(
        "eval_single_scattering((1 + 0.4 tol) ω)",
        || conductor.eval_single_scattering(inside, Vec3::Z, &mut rng).x,
        |v| exact > 0.0 && ((v - exact) / exact).abs() < 1e-2,
    );
    r.finish("valid_edge_directions_pass_the_checks", 400);
}

/// The side of the interface for the test tables' `outside` flags.
fn side(outside: bool) -> Side {
    if outside { Side::Outside } else { Side::Inside }
}
