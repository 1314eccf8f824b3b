//! Per-hit construction of every renderer type: a BSDF built at every hit from that hit's
//! parameters (roughness, complex index or relative index, scheme) allocates nothing once the
//! shared tables exist, and answers exactly as the same BSDF built ahead of time. The sizes of
//! the renderer types are printed (and bounded: no per-instance table).
//!
//! The binary counts the allocations of the calling thread with a counting global allocator.

use microsurface::glam::{Vec2, Vec3};
use microsurface::research::{Estimator, Shadowing};
use microsurface::slope::MicrosurfaceSlope;
use microsurface::{
    Beckmann, Bsdf, Compensated, Compensation, ComplexIor, Conductor, Dielectric, Ggx, MicrofacetBsdf,
    Technique,
};
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

/// The system allocator, counting the allocations of each thread.
struct Counting;

thread_local! {
    static ALLOCATIONS: Cell<usize> = const { Cell::new(0) };
}

// SAFETY: every call is forwarded to the system allocator unchanged; the thread-local counter
// is a `const`-initialized `Cell`, which allocates nothing.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let _ = ALLOCATIONS.try_with(|c| c.set(c.get() + 1));
        // SAFETY: forwarded with the caller's layout.
        unsafe { System.alloc(layout) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: forwarded with the caller's pointer and layout.
        unsafe { System.dealloc(ptr, layout) }
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        let _ = ALLOCATIONS.try_with(|c| c.set(c.get() + 1));
        // SAFETY: forwarded with the caller's layout.
        unsafe { System.alloc_zeroed(layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        let _ = ALLOCATIONS.try_with(|c| c.set(c.get() + 1));
        // SAFETY: forwarded with the caller's arguments.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

fn allocations() -> usize {
    ALLOCATIONS.with(Cell::get)
}

/// The hit parameters: a roughness, a metal and a relative index per hit.
#[derive(Debug, Clone, Copy)]
struct Hit {
    alpha: f32,
    metal: ComplexIor,
    eta: f32,
    wo: Vec3,
    uc: f32,
    u: Vec2,
}

/// `n` hits with parameters varying per hit (a fixed sequence).
fn hits(n: usize) -> Vec<Hit> {
    let mut state = 0x2545_f491_4f6c_dd1d_u64;
    let mut next = move || {
        state = state.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
        ((state >> 40) as f32 + 0.5) / (1u64 << 24) as f32
    };
    let metals = [ComplexIor::GOLD, ComplexIor::COPPER, ComplexIor::ALUMINIUM, ComplexIor::SILVER];
    (0..n)
        .map(|k| {
            let alpha = 0.02 + 0.97 * next();
            let eta = 1.05 + 1.5 * next();
            let z = 2.0 * next() - 1.0;
            let phi = core::f32::consts::TAU * next();
            let s = (1.0 - z * z).max(0.0).sqrt();
            Hit {
                alpha,
                metal: metals[k % metals.len()],
                eta: if k % 3 == 0 { 1.0 / eta } else { eta },
                wo: Vec3::new(s * phi.cos(), s * phi.sin(), z),
                uc: next(),
                u: Vec2::new(next(), next()),
            }
        })
        .collect()
}

/// The calls of a hit: `sample`, then `eval_with_pdf` at the sampled direction (or at the
/// mirrored view when nothing was sampled), as bits.
fn calls(b: &dyn Bsdf, h: &Hit) -> Vec<u32> {
    let s = b.sample(h.wo, h.uc, h.u);
    let wi = s.map_or(Vec3::new(-h.wo.x, -h.wo.y, h.wo.z), |s| s.wi);
    let (v, pdf) = b.eval_with_pdf(h.wo, wi);
    let mut out = vec![pdf.to_bits()];
    out.extend(v.f.to_array().map(f32::to_bits));
    if let Some(s) = s {
        out.extend(s.wi.to_array().map(f32::to_bits));
        out.extend(s.weight.to_array().map(f32::to_bits));
        out.push(s.pdf.to_bits());
    }
    out
}

/// The same calls without collecting (no allocation of the test's own): a checksum.
fn calls_sum(b: &impl Bsdf, h: &Hit) -> f32 {
    let s = b.sample(h.wo, h.uc, h.u);
    let wi = s.map_or(Vec3::new(-h.wo.x, -h.wo.y, h.wo.z), |s| s.wi);
    let (v, pdf) = b.eval_with_pdf(h.wo, wi);
    pdf + v.f.element_sum() + s.map_or(0.0, |s| s.weight.element_sum())
}

/// The same through `dyn Bsdf`.
fn calls_sum_dyn(b: &dyn Bsdf, h: &Hit) -> f32 {
    let s = b.sample(h.wo, h.uc, h.u);
    let wi = s.map_or(Vec3::new(-h.wo.x, -h.wo.y, h.wo.z), |s| s.wi);
    let (v, pdf) = b.eval_with_pdf(h.wo, wi);
    pdf + v.f.element_sum() + s.map_or(0.0, |s| s.weight.element_sum())
}

const SCHEMES: [Compensation; 3] = [Compensation::Walk, Compensation::KullaConty, Compensation::Turquin];

/// Every renderer type of one slope family, built per hit in the loop: zero allocations after
/// one warm-up hit per type (which builds the shared tables).
fn no_allocation_per_hit<S: microsurface::compensation::AlbedoTabulated + Copy>(
    family: &str,
    slope: impl Fn(f32) -> S,
) {
    let hits = hits(400);
    let techniques = [
        Technique::SingleScattering,
        Technique::RandomWalk,
        Technique::PositionFree { estimator: Estimator::Pt, shadowing: Shadowing::Correlated },
        Technique::PositionFree { estimator: Estimator::Bdpt, shadowing: Shadowing::Correlated },
    ];
    let mut sum = 0.0f32;
    for warm in [true, false] {
        let before = allocations();
        for h in if warm { &hits[..1] } else { &hits[..] } {
            for t in techniques {
                let gold =
                    MicrofacetBsdf::new(slope(h.alpha), Conductor::new(h.metal)).unwrap().with_technique(t);
                sum += calls_sum(&gold, h) + calls_sum_dyn(&gold, h);
                let glass = MicrofacetBsdf::new(slope(h.alpha), Dielectric::new(h.eta).unwrap())
                    .unwrap()
                    .with_technique(t);
                sum += calls_sum(&glass, h) + calls_sum_dyn(&glass, h);
            }
            for scheme in SCHEMES {
                let metal =
                    Compensated::with_scheme(slope(h.alpha), Conductor::new(h.metal), scheme).unwrap();
                sum += calls_sum(&metal, h) + calls_sum_dyn(&metal, h);
                let glass = Compensated::with_scheme(slope(h.alpha), Dielectric::new(h.eta).unwrap(), scheme)
                    .unwrap();
                sum += calls_sum(&glass, h) + calls_sum_dyn(&glass, h);
            }
        }
        let count = allocations() - before;
        if !warm {
            println!("{family}: {} hits × 14 renderer types, {count} allocations", hits.len());
            assert_eq!(count, 0, "{family}: {count} allocations in {} hits after the warm-up", hits.len());
        }
    }
    assert!(sum.is_finite(), "{family}: checksum {sum}");
}

#[test]
fn nothing_is_allocated_per_hit() {
    no_allocation_per_hit("GGX", |a| Ggx::isotropic(a).unwrap());
    no_allocation_per_hit("Beckmann", |a| Beckmann::isotropic(a).unwrap());
}

/// A compensated BSDF built at the hit answers bit for bit as the BSDF of the same parameters
/// built ahead of time (in another order, after other BSDFs were built): construction reads
/// only its arguments and the shared tables, and equal arguments give equal BSDFs
/// (`PartialEq`). 300 hits, GGX and Beckmann, every scheme, conductors and dielectrics, and the
/// single-scattering BSDF.
#[test]
fn per_hit_equals_prebuilt() {
    fn check<S: microsurface::compensation::AlbedoTabulated + Copy + PartialEq + core::fmt::Debug>(
        family: &str,
        slope: impl Fn(f32) -> S,
    ) {
        let hits = hits(300);
        // prebuilt, last hit first
        let mut metals = Vec::new();
        let mut glasses = Vec::new();
        let mut singles = Vec::new();
        for h in hits.iter().rev() {
            for scheme in SCHEMES {
                metals
                    .push(Compensated::with_scheme(slope(h.alpha), Conductor::new(h.metal), scheme).unwrap());
                glasses.push(
                    Compensated::with_scheme(slope(h.alpha), Dielectric::new(h.eta).unwrap(), scheme)
                        .unwrap(),
                );
            }
            singles.push(
                MicrofacetBsdf::new(slope(h.alpha), Conductor::new(h.metal))
                    .unwrap()
                    .with_technique(Technique::SingleScattering),
            );
        }
        let n = hits.len();
        for (k, h) in hits.iter().enumerate() {
            let r = n - 1 - k;
            for (s, scheme) in SCHEMES.into_iter().enumerate() {
                let metal =
                    Compensated::with_scheme(slope(h.alpha), Conductor::new(h.metal), scheme).unwrap();
                assert_eq!(metal, metals[3 * r + s], "{family} conductor {scheme:?} hit {k}");
                assert_eq!(
                    calls(&metal, h),
                    calls(&metals[3 * r + s], h),
                    "{family} conductor {scheme:?} hit {k}"
                );
                let glass = Compensated::with_scheme(slope(h.alpha), Dielectric::new(h.eta).unwrap(), scheme)
                    .unwrap();
                assert_eq!(glass, glasses[3 * r + s], "{family} glass {scheme:?} hit {k}");
                assert_eq!(
                    calls(&glass, h),
                    calls(&glasses[3 * r + s], h),
                    "{family} glass {scheme:?} hit {k}"
                );
            }
            let single = MicrofacetBsdf::new(slope(h.alpha), Conductor::new(h.metal))
                .unwrap()
                .with_technique(Technique::SingleScattering);
            assert_eq!(calls(&single, h), calls(&singles[r], h), "{family} single scattering hit {k}");
        }
    }
    check("GGX", |a| Ggx::isotropic(a).unwrap());
    check("Beckmann", |a| Beckmann::isotropic(a).unwrap());
}

/// The renderer types are small (no per-instance table): under 384 bytes each, the size of one
/// array of 32 RGB values.
#[test]
fn sizes_of_the_renderer_types() {
    let sizes = [
        ("MicrofacetBsdf<Ggx, Conductor>", size_of::<MicrofacetBsdf<Ggx, Conductor>>()),
        ("MicrofacetBsdf<Ggx, Dielectric>", size_of::<MicrofacetBsdf<Ggx, Dielectric>>()),
        ("MicrofacetBsdf<Beckmann, Conductor>", size_of::<MicrofacetBsdf<Beckmann, Conductor>>()),
        ("MicrofacetBsdf<Beckmann, Dielectric>", size_of::<MicrofacetBsdf<Beckmann, Dielectric>>()),
        ("Compensated<Ggx, Conductor>", size_of::<Compensated<Ggx, Conductor>>()),
        ("Compensated<Ggx, Dielectric>", size_of::<Compensated<Ggx, Dielectric>>()),
        ("Compensated<Beckmann, Conductor>", size_of::<Compensated<Beckmann, Conductor>>()),
        ("Compensated<Beckmann, Dielectric>", size_of::<Compensated<Beckmann, Dielectric>>()),
    ];
    for (name, size) in sizes {
        println!("size_of::<{name}>() = {size}");
        assert!(size < 384, "{name}: {size} bytes");
    }
    // the slope is what varies per hit: the trait's α accessors see it
    assert!(Ggx::isotropic(0.5).unwrap().alpha_x() == 0.5);
}
