//! Benchmarks of the renderer-facing `Bsdf` trait against the research-layer calls it wraps,
//! for every technique (single scattering, random walk, position-free PT and BDPT) on gold and
//! glass (GGX, α = 0.5), with static dispatch (the concrete `MicrofacetBsdf`) and dynamic
//! dispatch (`&dyn Bsdf`) side by side; and single-scattering `Bsdf::sample` of the GGX
//! conductor against the spherical-cap `sample_d_wi` it is built on.
//!
//! One call per iteration. The inputs — `N` view directions uniform on the upper hemisphere,
//! `N` light directions (upper hemisphere for gold, whole sphere for glass) and `N` triples of
//! uniforms — are pre-generated from fixed seeds and rotated through with a wrapping counter
//! behind `std::hint::black_box`. The research calls draw from a `Pcg64Mcg` that runs on
//! across iterations; the trait calls seed their own generators from the hash of their
//! arguments (that cost is part of what is measured) and take the counter as key.
//!
//! Per hit (`per_hit` group): construction from per-hit parameters (roughness, complex index or
//! relative index varying per call) plus `sample` and `eval_with_pdf`, against the same two
//! calls on a BSDF built once, for every renderer type, static and dynamic dispatch.
//!
//! Benchmark ids: `{material}/{technique}/{eval|pdf|sample}/{research|static|dyn}`,
//! `{material}/{walk|pt|bdpt}/sample/research+pdf` (the research sample and the density of its
//! direction, what the trait's sample computes),
//! `{material}/single/eval_with_pdf/{research|static|dyn}` (the research call is
//! `SingleScattering::eval_with_pdf`; its `sample` returns the density too),
//! `gold/single/sample-vs-vndf/{sample_d_wi|bounded_cap|static}`, and
//! `per_hit/{material} {technique}/{prebuilt|per-hit} {static|dyn}`.

use criterion::{Criterion, criterion_group, criterion_main};
use microsurface::glam::Vec3;
use microsurface::research::{Estimator, Material, Microsurface, Shadowing, SpecularLimit, UniformHeight};
use microsurface::slope::MicrosurfaceSlope;
use microsurface::{
    Bsdf, Compensated, Compensation, ComplexIor, Conductor, Dielectric, Ggx, MicrofacetBsdf, Technique,
};
use rand::SeedableRng;
use rand_pcg::Pcg64Mcg;
use std::hint::black_box;

use validation::clock::{Clock, config};
use validation::inputs::{N, inputs};
use validation::research::Research;

/// The roughness of every configuration.
const ALPHA: f32 = 0.5;

/// The next index of the rotation through the `N` inputs.
#[inline(always)]
fn next(i: &mut usize) -> usize {
    let k = *i & (N - 1);
    *i = i.wrapping_add(1);
    k
}

const TECHNIQUES: [(&str, Technique); 4] = [
    ("single", Technique::SingleScattering),
    ("walk", Technique::RandomWalk),
    ("pt", Technique::PositionFree { estimator: Estimator::Pt, shadowing: Shadowing::Correlated }),
    ("bdpt", Technique::PositionFree { estimator: Estimator::Bdpt, shadowing: Shadowing::Correlated }),
];

fn bench_material<M: Material + SpecularLimit>(c: &mut Criterion<Clock>, name: &str, material: M, seed: u64) {
    let slope = Ggx::isotropic(ALPHA).expect("valid roughness");
    let x = inputs(M::TRANSMITS, seed);
    for (tname, technique) in TECHNIQUES {
        let bsdf =
            MicrofacetBsdf::new(slope, material).expect("α ≤ MAX_WALK_ALPHA").with_technique(technique);
        let dynamic: &dyn Bsdf = &bsdf;
        let research = Research { surface: Microsurface::new(UniformHeight, slope, material), technique };
        let mut rng = Pcg64Mcg::seed_from_u64(seed + 1);

        let mut g = c.benchmark_group(format!("{name}/{tname}/eval"));
        g.bench_function("research", |b| {
            let mut i = 0;
            b.iter(|| {
                let k = next(&mut i);
                black_box(&research).eval(black_box(x.wo[k]), black_box(x.wi[k]), &mut rng)
            })
        });
        g.bench_function("static", |b| {
            let mut i = 0;
            b.iter(|| {
                let k = next(&mut i);
                black_box(&bsdf).eval_keyed(black_box(x.wo[k]), black_box(x.wi[k]), i as u64)
            })
        });
        g.bench_function("dyn", |b| {
            let mut i = 0;
            b.iter(|| {
                let k = next(&mut i);
                black_box(dynamic).eval_keyed(black_box(x.wo[k]), black_box(x.wi[k]), i as u64)
            })
        });
        g.finish();

        let mut g = c.benchmark_group(format!("{name}/{tname}/pdf"));
        g.bench_function("research", |b| {
            let mut i = 0;
            b.iter(|| {
                let k = next(&mut i);
                black_box(&research).pdf(black_box(x.wo[k]), black_box(x.wi[k]))
            })
        });
        g.bench_function("static", |b| {
            let mut i = 0;
            b.iter(|| {
                let k = next(&mut i);
                black_box(&bsdf).pdf(black_box(x.wo[k]), black_box(x.wi[k]))
            })
        });
        g.bench_function("dyn", |b| {
            let mut i = 0;
            b.iter(|| {
                let k = next(&mut i);
                black_box(dynamic).pdf(black_box(x.wo[k]), black_box(x.wi[k]))
            })
        });
        g.finish();

        if technique == Technique::SingleScattering {
            // eval and pdf in one call: the research layer's shares the half vector and D
            let single = research.single();
            let mut g = c.benchmark_group(format!("{name}/{tname}/eval_with_pdf"));
            g.bench_function("research", |b| {
                let mut i = 0;
                b.iter(|| {
                    let k = next(&mut i);
                    black_box(&single).eval_with_pdf(black_box(x.wo[k]), black_box(x.wi[k]), &mut rng)
                })
            });
            g.bench_function("static", |b| {
                let mut i = 0;
                b.iter(|| {
                    let k = next(&mut i);
                    black_box(&bsdf).eval_with_pdf_keyed(black_box(x.wo[k]), black_box(x.wi[k]), i as u64)
                })
            });
            g.bench_function("dyn", |b| {
                let mut i = 0;
                b.iter(|| {
                    let k = next(&mut i);
                    black_box(dynamic).eval_with_pdf_keyed(black_box(x.wo[k]), black_box(x.wi[k]), i as u64)
                })
            });
            g.finish();
        }

        let mut g = c.benchmark_group(format!("{name}/{tname}/sample"));
        g.bench_function("research", |b| {
            let mut i = 0;
            b.iter(|| {
                let k = next(&mut i);
                black_box(&research).sample(black_box(x.wo[k]), &mut rng)
            })
        });
        if technique != Technique::SingleScattering {
            // the comparison for the stochastic techniques: sample + pdf
            g.bench_function("research+pdf", |b| {
                let mut i = 0;
                b.iter(|| {
                    let k = next(&mut i);
                    black_box(&research).sample_with_pdf(black_box(x.wo[k]), &mut rng)
                })
            });
        }
        g.bench_function("static", |b| {
            let mut i = 0;
            b.iter(|| {
                let k = next(&mut i);
                black_box(&bsdf).sample(black_box(x.wo[k]), black_box(x.uc[k]), black_box(x.u[k]))
            })
        });
        g.bench_function("dyn", |b| {
            let mut i = 0;
            b.iter(|| {
                let k = next(&mut i);
                black_box(dynamic).sample(black_box(x.wo[k]), black_box(x.uc[k]), black_box(x.u[k]))
            })
        });
        g.finish();
    }
}

/// Single-scattering `Bsdf::sample` of a GGX conductor against the visible-normal samplers:
/// the spherical cap (`sample_d_wi`) and the bounded cap it draws its reflections from (the
/// target: at most 2× the spherical cap).
fn sample_vs_vndf(c: &mut Criterion<Clock>) {
    let slope = Ggx::isotropic(ALPHA).expect("valid roughness");
    let gold = MicrofacetBsdf::new(slope, Conductor::new(ComplexIor::GOLD))
        .expect("α ≤ MAX_WALK_ALPHA")
        .with_technique(Technique::SingleScattering);
    let x = inputs(false, 77);
    let mut g = c.benchmark_group("gold/single/sample-vs-vndf");
    g.bench_function("sample_d_wi", |b| {
        let mut i = 0;
        b.iter(|| {
            let k = next(&mut i);
            black_box(&slope).sample_d_wi(black_box(x.wo[k]), black_box(x.u[k].x), black_box(x.u[k].y))
        })
    });
    let bounded = microsurface::vndf::GgxBoundedCap(slope);
    g.bench_function("bounded_cap", |b| {
        let mut i = 0;
        b.iter(|| {
            let k = next(&mut i);
            let u = [x.u[k].x, x.u[k].y, 0.0];
            microsurface::vndf::VisibleNormalSampler::sample(
                black_box(&bounded),
                black_box(x.wo[k]),
                black_box(u),
            )
        })
    });
    g.bench_function("static", |b| {
        let mut i = 0;
        b.iter(|| {
            let k = next(&mut i);
            black_box(&gold).sample(black_box(x.wo[k]), black_box(x.uc[k]), black_box(x.u[k]))
        })
    });
    g.finish();
}

/// The energy-compensated gold (`Compensated`: Kulla–Conty, Turquin, the walk's orders) against
/// the single-scattering gold it is built on, static dispatch. Ids
/// `gold/compensated/{eval|pdf|sample}/{single|kulla-conty|turquin|walk}`.
fn compensated(c: &mut Criterion<Clock>) {
    let slope = Ggx::isotropic(ALPHA).expect("valid roughness");
    let gold = Conductor::new(ComplexIor::GOLD);
    let single = MicrofacetBsdf::new(slope, gold)
        .expect("α ≤ MAX_WALK_ALPHA")
        .with_technique(Technique::SingleScattering);
    let kc = Compensated::with_scheme(slope, gold, Compensation::KullaConty).expect("α ≤ 1");
    let turquin = Compensated::with_scheme(slope, gold, Compensation::Turquin).expect("α ≤ 1");
    let per_order = Compensated::with_scheme(slope, gold, Compensation::Walk).expect("α ≤ 1");
    let x = inputs(false, 300);
    macro_rules! bench {
        ($g:expr, $name:expr, $model:expr, $call:ident) => {
            $g.bench_function($name, |b| {
                let mut i = 0;
                b.iter(|| {
                    let k = next(&mut i);
                    bench!(@call black_box($model), $call, k)
                })
            });
        };
        (@call $m:expr, eval, $k:expr) => { $m.eval(black_box(x.wo[$k]), black_box(x.wi[$k])) };
        (@call $m:expr, pdf, $k:expr) => { $m.pdf(black_box(x.wo[$k]), black_box(x.wi[$k])) };
        (@call $m:expr, sample, $k:expr) => { $m.sample(black_box(x.wo[$k]), black_box(x.uc[$k]), black_box(x.u[$k])) };
    }
    let mut g = c.benchmark_group("gold/compensated/eval");
    bench!(g, "single", &single, eval);
    bench!(g, "kulla-conty", &kc, eval);
    bench!(g, "turquin", &turquin, eval);
    bench!(g, "walk", &per_order, eval);
    g.finish();
    let mut g = c.benchmark_group("gold/compensated/pdf");
    bench!(g, "single", &single, pdf);
    bench!(g, "kulla-conty", &kc, pdf);
    bench!(g, "turquin", &turquin, pdf);
    bench!(g, "walk", &per_order, pdf);
    g.finish();
    let mut g = c.benchmark_group("gold/compensated/sample");
    bench!(g, "single", &single, sample);
    bench!(g, "kulla-conty", &kc, sample);
    bench!(g, "turquin", &turquin, sample);
    bench!(g, "walk", &per_order, sample);
    g.finish();
}

/// The energy-compensated glass (η = 1.5, `Compensated`: the walk's higher orders as reflection
/// and transmission lobes, and Turquin's scaling) against the single-scattering glass, static
/// dispatch, views above the surface and light directions on the whole sphere. Ids
/// `glass/compensated/{eval|pdf|sample}/{single|walk|turquin}`.
fn compensated_glass(c: &mut Criterion<Clock>) {
    let slope = Ggx::isotropic(ALPHA).expect("valid roughness");
    let glass = Dielectric::new(1.5).expect("valid index");
    let single = MicrofacetBsdf::new(slope, glass)
        .expect("α ≤ MAX_WALK_ALPHA")
        .with_technique(Technique::SingleScattering);
    let kc = Compensated::new(slope, glass).expect("in the tables' range");
    let turquin =
        Compensated::with_scheme(slope, glass, Compensation::Turquin).expect("in the tables' range");
    let x = inputs(true, 310);
    macro_rules! bench {
        ($g:expr, $name:expr, $model:expr, $call:ident) => {
            $g.bench_function($name, |b| {
                let mut i = 0;
                b.iter(|| {
                    let k = next(&mut i);
                    bench!(@call black_box($model), $call, k)
                })
            });
        };
        (@call $m:expr, eval, $k:expr) => { $m.eval(black_box(x.wo[$k]), black_box(x.wi[$k])) };
        (@call $m:expr, pdf, $k:expr) => { $m.pdf(black_box(x.wo[$k]), black_box(x.wi[$k])) };
        (@call $m:expr, sample, $k:expr) => { $m.sample(black_box(x.wo[$k]), black_box(x.uc[$k]), black_box(x.u[$k])) };
    }
    let mut g = c.benchmark_group("glass/compensated/eval");
    bench!(g, "single", &single, eval);
    bench!(g, "walk", &kc, eval);
    bench!(g, "turquin", &turquin, eval);
    g.finish();
    let mut g = c.benchmark_group("glass/compensated/pdf");
    bench!(g, "single", &single, pdf);
    bench!(g, "walk", &kc, pdf);
    bench!(g, "turquin", &turquin, pdf);
    g.finish();
    let mut g = c.benchmark_group("glass/compensated/sample");
    bench!(g, "single", &single, sample);
    bench!(g, "walk", &kc, sample);
    bench!(g, "turquin", &turquin, sample);
    g.finish();
}

/// The per-hit parameters: roughness α ∈ [0.05, 1], a conductor index between gold and copper,
/// a relative index η ∈ [1.2, 2.2], `N` of each from a fixed seed.
struct HitParameters {
    alpha: Vec<f32>,
    ior: Vec<(Vec3, Vec3)>,
    eta: Vec<f32>,
}

fn hit_parameters(seed: u64) -> HitParameters {
    use rand::RngExt;
    let mut rng = Pcg64Mcg::seed_from_u64(seed);
    let (gold, copper) = (ComplexIor::GOLD, ComplexIor::COPPER);
    let mut alpha = Vec::with_capacity(N);
    let mut ior = Vec::with_capacity(N);
    let mut eta = Vec::with_capacity(N);
    for _ in 0..N {
        alpha.push(0.05 + 0.95 * rng.random::<f32>());
        let t: f32 = rng.random();
        ior.push((gold.eta().lerp(copper.eta(), t), gold.k().lerp(copper.k(), t)));
        eta.push(1.2 + rng.random::<f32>());
    }
    HitParameters { alpha, ior, eta }
}

/// `sample` + `eval_with_pdf` at input k (the light direction of the eval is the sample's, or
/// the input's where the sample fails).
#[inline(always)]
fn calls(b: &dyn Bsdf, x: &validation::inputs::Inputs, k: usize, i: usize) -> f32 {
    let wo = black_box(x.wo[k]);
    let s = b.sample(wo, black_box(x.uc[k]), black_box(x.u[k]));
    let wi = s.map_or(x.wi[k], |s| s.wi);
    let (f, pdf) = b.eval_with_pdf_keyed(wo, wi, i as u64);
    f.f.x + pdf + s.map_or(0.0, |s| s.pdf)
}

/// [`calls`] with static dispatch.
#[inline(always)]
fn calls_static<B: Bsdf>(b: &B, x: &validation::inputs::Inputs, k: usize, i: usize) -> f32 {
    let wo = black_box(x.wo[k]);
    let s = b.sample(wo, black_box(x.uc[k]), black_box(x.u[k]));
    let wi = s.map_or(x.wi[k], |s| s.wi);
    let (f, pdf) = b.eval_with_pdf_keyed(wo, wi, i as u64);
    f.f.x + pdf + s.map_or(0.0, |s| s.pdf)
}

/// One renderer type per hit: `prebuilt` (the two calls on the BSDF of the hit's parameters,
/// built ahead of time: one per input) and `per-hit` (`build` from the hit's parameters, then
/// the two calls), static and `dyn`. The difference of the two is the construction alone.
fn per_hit_case<B: Bsdf + 'static>(
    c: &mut Criterion<Clock>,
    name: &str,
    build: impl Fn(usize) -> B,
    x: &validation::inputs::Inputs,
) {
    let prebuilt: Vec<B> = (0..N).map(&build).collect();
    let mut g = c.benchmark_group(format!("per_hit/{name}"));
    g.bench_function("prebuilt static", |b| {
        let mut i = 0;
        b.iter(|| {
            let k = next(&mut i);
            calls_static(black_box(&prebuilt[k]), x, k, i)
        })
    });
    g.bench_function("per-hit static", |b| {
        let mut i = 0;
        b.iter(|| {
            let k = next(&mut i);
            let bsdf = build(k);
            calls_static(&bsdf, x, k, i)
        })
    });
    g.bench_function("prebuilt dyn", |b| {
        let mut i = 0;
        b.iter(|| {
            let k = next(&mut i);
            let d: &dyn Bsdf = &prebuilt[k];
            calls(black_box(d), x, k, i)
        })
    });
    g.bench_function("per-hit dyn", |b| {
        let mut i = 0;
        b.iter(|| {
            let k = next(&mut i);
            let bsdf = build(k);
            calls(black_box(&bsdf as &dyn Bsdf), x, k, i)
        })
    });
    g.finish();
}

/// Every renderer type built per hit (`per_hit/…`): single scattering, the random walk and the
/// position-free PT and BDPT, and every compensated scheme (a dielectric's Kulla–Conty is its
/// walk split), gold-to-copper conductors and glass of η ∈ [1.2, 2.2], GGX α ∈ [0.05, 1]; the
/// prebuilt BSDFs have the same parameters per input.
fn per_hit(c: &mut Criterion<Clock>) {
    let p = hit_parameters(400);
    // the hit's parameters read from memory at an index the compiler cannot see, as a renderer
    // reads its texture results (black-boxing the values instead copies them to the stack and
    // reads them back in other pieces, which the processor cannot forward from the stores: a
    // stall of the benchmark's own, before the construction starts)
    let slope = |k: usize| Ggx::isotropic(p.alpha[black_box(k)]).expect("α in (0, 1]");
    let conductor = |k: usize| {
        let (eta, kappa) = p.ior[black_box(k)];
        Conductor::new(ComplexIor::new(eta, kappa).expect("a metal's index"))
    };
    let glass = |k: usize| Dielectric::new(p.eta[black_box(k)]).expect("η > 0");
    let (xg, xd) = (inputs(false, 410), inputs(true, 420));
    for (tname, technique) in TECHNIQUES {
        let build =
            |k: usize| MicrofacetBsdf::new(slope(k), conductor(k)).expect("α ≤ 10").with_technique(technique);
        per_hit_case(c, &format!("gold {tname}"), build, &xg);
    }
    for (tname, technique) in &TECHNIQUES[..2] {
        let technique = *technique;
        let build =
            |k: usize| MicrofacetBsdf::new(slope(k), glass(k)).expect("α ≤ 10").with_technique(technique);
        per_hit_case(c, &format!("glass {tname}"), build, &xd);
    }
    for (sname, scheme) in [
        ("walk", Compensation::Walk),
        ("kulla-conty", Compensation::KullaConty),
        ("turquin", Compensation::Turquin),
    ] {
        let build = |k: usize| Compensated::with_scheme(slope(k), conductor(k), scheme).expect("α ≤ 1");
        per_hit_case(c, &format!("gold compensated {sname}"), build, &xg);
    }
    for (sname, scheme) in [("walk", Compensation::Walk), ("turquin", Compensation::Turquin)] {
        let build =
            |k: usize| Compensated::with_scheme(slope(k), glass(k), scheme).expect("in the tables' range");
        per_hit_case(c, &format!("glass compensated {sname}"), build, &xd);
    }
}

fn bsdfs(c: &mut Criterion<Clock>) {
    per_hit(c);
    compensated(c);
    compensated_glass(c);
    sample_vs_vndf(c);
    bench_material(c, "gold", Conductor::new(ComplexIor::GOLD), 100);
    bench_material(c, "glass", Dielectric::new(1.5).expect("valid index"), 200);
}

criterion_group! {
    name = benches;
    config = config();
    targets = bsdfs
}
criterion_main!(benches);
