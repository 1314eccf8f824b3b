//! The random walk in lanes (`Microsurface::sample_batch`) has the scalar walk's distribution:
//! two-sample tests per scattering order of the share of walks leaving after k bounces and of
//! their mean weight and exit direction, for GGX gold and perfect mirrors (the lanes) and for a
//! dielectric and Beckmann (the scalar walk per query); views from below and invalid queries
//! answered by the scalar walk; slices of unequal length rejected.

use microsurface::glam::Vec3;
use microsurface::research::{Material, Microsurface, UniformHeight, WalkOutputs};
use microsurface::slope::MicrosurfaceSlope;
use microsurface::{Beckmann, Channels, ComplexIor, Conductor, Dielectric, Directions, Error, Ggx};
use rand::SeedableRng;
use rand_pcg::Pcg64Mcg;
use validation::{Stats, assert_two_sample, family_z};

/// Walks per sample and configuration: enough that a 10 % error in the closed-form escape
/// probability of the lanes' walk (a/(a + 1.1Λ)) fails the order-1 share of gold at α = 0.5
/// (|Δ| = 8.5e-3 against z·SE = 6.9e-3).
const N: usize = 200_000;
/// Orders compared one by one; longer walks are pooled.
const ORDERS: usize = 5;
/// Configurations × directions × (orders + tail) × quantities (share, weight, ωo.z, ωo.x).
const COMPARISONS: usize = 5 * 3 * (ORDERS + 1) * 4;

struct Walks {
    wo: [Vec<f32>; 3],
    weight: [Vec<f32>; 3],
    bounces: Vec<u32>,
}

impl Walks {
    fn new(n: usize) -> Self {
        Self {
            wo: [vec![0.0; n], vec![0.0; n], vec![0.0; n]],
            weight: [vec![0.0; n], vec![0.0; n], vec![0.0; n]],
            bounces: vec![9; n],
        }
    }
}

fn batch<S: MicrosurfaceSlope, M: Material>(
    surface: &Microsurface<UniformHeight, S, M>,
    wi: &[Vec3],
    seed: u64,
) -> Walks {
    let (x, y, z): (Vec<f32>, Vec<f32>, Vec<f32>) = (
        wi.iter().map(|w| w.x).collect(),
        wi.iter().map(|w| w.y).collect(),
        wi.iter().map(|w| w.z).collect(),
    );
    let mut walks = Walks::new(wi.len());
    {
        let [wx, wy, wz] = &mut walks.wo;
        let [r, g, b] = &mut walks.weight;
        let mut out = WalkOutputs {
            wo: Channels::new(wx, wy, wz),
            weight: Channels::new(r, g, b),
            bounces: &mut walks.bounces,
        };
        surface.sample_batch(&Directions::new(&x, &y, &z).expect("equal"), seed, &mut out).expect("lengths");
    }
    walks
}

/// Per order k = 1 … ORDERS and the tail: the share of walks, and the means of weight.x,
/// ωo.z and ωo.x times the indicator of the order.
fn order_stats(samples: impl Iterator<Item = Option<(Vec3, Vec3, u32)>>) -> Vec<[Stats; 4]> {
    let mut stats = vec![[Stats::default(); 4]; ORDERS + 1];
    for s in samples {
        for (k, st) in stats.iter_mut().enumerate() {
            let hit = s.filter(|&(_, _, b)| (b as usize).min(ORDERS + 1) == k + 1);
            let (wo, w) = hit.map_or((Vec3::ZERO, Vec3::ZERO), |(wo, w, _)| (wo, w));
            st[0].push(f64::from(u8::from(hit.is_some())));
            st[1].push(f64::from(w.x));
            st[2].push(f64::from(wo.z));
            st[3].push(f64::from(wo.x));
        }
    }
    stats
}

fn compare<S: MicrosurfaceSlope, M: Material>(
    label: &str,
    surface: Microsurface<UniformHeight, S, M>,
    seed: u64,
) {
    let z = family_z(1e-3, COMPARISONS);
    for (j, theta) in [0.0f32, 60.0, 85.0].into_iter().enumerate() {
        let t = theta.to_radians();
        let wi = Vec3::new(t.sin(), 0.0, t.cos());
        let mut rng = Pcg64Mcg::seed_from_u64(seed + j as u64);
        let scalar =
            order_stats((0..N).map(|_| surface.sample(wi, &mut rng).map(|s| (s.wo, s.weight, s.bounces))));
        let walks = batch(&surface, &vec![wi; N], seed + 100 + j as u64);
        let lanes = order_stats((0..N).map(|i| {
            (walks.bounces[i] > 0).then(|| {
                let wo = Vec3::new(walks.wo[0][i], walks.wo[1][i], walks.wo[2][i]);
                let w = Vec3::new(walks.weight[0][i], walks.weight[1][i], walks.weight[2][i]);
                (wo, w, walks.bounces[i])
            })
        }));
        for k in 0..=ORDERS {
            for (q, name) in ["share", "weight", "ωo.z", "ωo.x"].into_iter().enumerate() {
                let l = format!(
                    "{label}, θi = {theta}°, order {}{}: {name}",
                    k + 1,
                    if k == ORDERS { "+" } else { "" }
                );
                assert_two_sample(&l, &scalar[k][q], &lanes[k][q], z, 4e-3);
            }
        }
    }
}

#[test]
fn lanes_walk_has_the_scalar_walks_distribution_per_order() {
    let gold = Conductor::new(ComplexIor::GOLD);
    compare("gold GGX 0.5", Microsurface::new(UniformHeight, Ggx::isotropic(0.5).expect("α"), gold), 11);
    compare(
        "mirror GGX (1.5, 0.5)",
        Microsurface::new(UniformHeight, Ggx::new(1.5, 0.5).expect("α"), Conductor::perfect()),
        12,
    );
    compare("gold GGX 0.1", Microsurface::new(UniformHeight, Ggx::isotropic(0.1).expect("α"), gold), 13);
    // no lane kernels: the scalar walk per query
    compare(
        "glass GGX 0.5",
        Microsurface::new(UniformHeight, Ggx::isotropic(0.5).expect("α"), Dielectric::new(1.5).expect("η")),
        14,
    );
    compare(
        "mirror Beckmann 0.7",
        Microsurface::new(UniformHeight, Beckmann::isotropic(0.7).expect("α"), Conductor::perfect()),
        15,
    );
}

/// Views from below and invalid directions among the lanes' queries get the scalar walk (a
/// sample leaving upwards, and no sample); the lanes' neighbours are unaffected; a batch is a
/// function of (seed, query) only; unequal slices are rejected.
#[test]
fn lanes_walk_queries_outside_the_lanes() {
    let surface = Microsurface::new(UniformHeight, Ggx::isotropic(0.5).expect("α"), Conductor::perfect());
    let up = Vec3::new(0.6, 0.0, 0.8);
    let below = Vec3::new(0.6, 0.0, -0.8);
    let mut wi = vec![up; 37];
    wi[3] = below;
    wi[9] = Vec3::NAN;
    wi[10] = Vec3::new(0.0, 0.0, 2.0);
    let walks = batch(&surface, &wi, 5);
    for (i, w) in wi.iter().enumerate() {
        if !(w.length_squared() - 1.0).abs().le(&1e-3) {
            assert_eq!(walks.bounces[i], 0, "invalid query {i} was walked");
        } else {
            // F = 1: every walk leaves upwards with weight 1
            assert!(walks.bounces[i] >= 1 && walks.wo[2][i] > 0.0 && walks.weight[0][i] == 1.0, "query {i}");
        }
    }
    // the same queries in another order of lanes give the same walks for the same indices
    let again = batch(&surface, &wi, 5);
    assert_eq!(again.bounces, walks.bounces);
    assert_eq!(again.wo, walks.wo);
    let x = vec![0.0f32; 4];
    let z = vec![1.0f32; 4];
    let mut w = Walks::new(3);
    let [wx, wy, wz] = &mut w.wo;
    let [r, g, b] = &mut w.weight;
    let mut out = WalkOutputs {
        wo: Channels::new(wx, wy, wz),
        weight: Channels::new(r, g, b),
        bounces: &mut w.bounces,
    };
    let dirs = Directions::new(&x, &x, &z).expect("equal");
    assert!(matches!(surface.sample_batch(&dirs, 1, &mut out), Err(Error::LengthMismatch { .. })));
}
