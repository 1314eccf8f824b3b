//! The technique chooser (`microsurface::techniques`): a larger budget never picks a costlier
//! technique, its stated error bounds hold against the walk at sampled points, and its
//! single-scattering errors on the table grid are the tables' node values.

use microsurface::compensation::{ALBEDO_ROUGHNESSES, AlbedoTable, AlbedoTabulated, MAX_TABULATED_ALPHA};
use microsurface::glam::{Vec2, Vec3};
use microsurface::techniques::{Budgeted, Candidates, Choice, ChosenTechnique};
use microsurface::{
    Beckmann, Bsdf, ComplexIor, Conductor, Dielectric, Error, Ggx, MicrofacetBsdf, SMOOTH_ALPHA, Technique,
    Transport,
};
use validation::{Stats, family_z, uniform32};

fn conductors() -> [Conductor; 4] {
    [
        Conductor::perfect(),
        Conductor::new(ComplexIor::GOLD),
        Conductor::new(ComplexIor::COPPER),
        Conductor::new(ComplexIor::ALUMINIUM),
    ]
}

/// The budgets of the monotonicity test: 0, then 10⁻⁴ … 0.5.
fn budgets() -> Vec<f32> {
    std::iter::once(0.0).chain((0..=40).map(|k| 1e-4 * 5000f32.powf(k as f32 / 40.0))).collect()
}

/// Over increasing budgets the technique and the cost never increase, and the stated error is
/// within the budget.
fn assert_monotone<S: AlbedoTabulated, M: Budgeted>(label: &str, slope: &S, m: &M) {
    let mut last: Option<Choice> = None;
    for b in budgets() {
        let c = Choice::new(slope, m, b).unwrap();
        assert!(c.error <= b && c.error >= 0.0 && c.cost >= 1.0, "{label} budget {b}: {c:?}");
        if let Some(p) = last {
            assert!(c.technique <= p.technique && c.cost <= p.cost, "{label} budget {b}: {c:?} after {p:?}");
        }
        last = Some(c);
    }
}

#[test]
fn a_larger_budget_never_picks_a_costlier_technique() {
    let alphas: Vec<f32> = (0..=40).map(|k| 1e-4 * 1e5f32.powf(k as f32 / 40.0)).collect(); // 1e-4 … 10
    for &a in &alphas {
        for (i, c) in conductors().iter().enumerate() {
            assert_monotone(&format!("ggx conductor {i} α {a}"), &Ggx::isotropic(a).unwrap(), c);
            assert_monotone(&format!("beckmann conductor {i} α {a}"), &Beckmann::isotropic(a).unwrap(), c);
            assert_monotone(&format!("ggx anisotropic {i} α {a}"), &Ggx::new(a, 0.3 * a).unwrap(), c);
        }
        for eta in [1.0001, 1.33, 1.5, 2.0, 2.9, 4.0, 0.7] {
            let d = Dielectric::new(eta).unwrap();
            assert_monotone(&format!("ggx glass {eta} α {a}"), &Ggx::isotropic(a).unwrap(), &d);
            assert_monotone(&format!("beckmann glass {eta} α {a}"), &Beckmann::isotropic(a).unwrap(), &d);
        }
    }
}

#[test]
fn choices_on_the_table_grid_follow_the_shipped_tables() {
    for (table, name) in [(AlbedoTable::GGX, "ggx"), (AlbedoTable::BECKMANN, "beckmann")] {
        for (j, &e_avg) in table.average_nodes().iter().enumerate().skip(1) {
            let r = j as f32 / (ALBEDO_ROUGHNESSES - 1) as f32;
            let alpha = r * r;
            for c in conductors() {
                let cand = if name == "ggx" {
                    Candidates::new(&Ggx::isotropic(alpha).unwrap(), &c)
                } else {
                    Candidates::new(&Beckmann::isotropic(alpha).unwrap(), &c)
                }
                .unwrap();
                let single = cand.single.expect("within the tables");
                // the node value plus the interpolation error of Ē (7.4e-5, `AlbedoTable::average`),
                // up to the interpolation weight of a node computed through √α; below
                // `SMOOTH_ALPHA` (the row r = 1/62) a Dirac mirror, which loses nothing
                let expected = if alpha < SMOOTH_ALPHA { 0.0 } else { 1.0 - e_avg + 7.4e-5 };
                assert!((single - expected).abs() <= 1e-6, "{name} node {j}: {single} vs {expected}");
                let comp = cand.compensated.expect("isotropic, within the tables");
                assert!(comp >= 0.0 && comp.is_finite());
                // the rule on the node values
                for b in [0.0, 0.002, 0.005, 0.01, 0.03, 0.1, 0.3] {
                    let chosen = if name == "ggx" {
                        Choice::new(&Ggx::isotropic(alpha).unwrap(), &c, b)
                    } else {
                        Choice::new(&Beckmann::isotropic(alpha).unwrap(), &c, b)
                    }
                    .unwrap();
                    let expected = if single <= b {
                        ChosenTechnique::SingleScattering
                    } else if comp <= b {
                        ChosenTechnique::Compensated
                    } else {
                        ChosenTechnique::RandomWalk
                    };
                    assert_eq!(chosen.technique, expected, "{name} node {j} budget {b}");
                }
            }
        }
    }
    // beyond the tables: the walk, whatever the budget; beyond the walk: refused
    let rough = Ggx::isotropic(MAX_TABULATED_ALPHA * 1.5).unwrap();
    assert_eq!(
        Choice::new(&rough, &Conductor::perfect(), 1.0).unwrap().technique,
        ChosenTechnique::RandomWalk
    );
    let dense = Dielectric::new(3.5).unwrap();
    assert_eq!(
        Choice::new(&Ggx::isotropic(0.3).unwrap(), &dense, 1.0).unwrap().technique,
        ChosenTechnique::RandomWalk
    );
    assert!(matches!(
        Choice::new(&Ggx::isotropic(11.0).unwrap(), &Conductor::perfect(), 0.01),
        Err(Error::InvalidParameter { name: "alpha", .. })
    ));
    for b in [-0.01, f32::NAN, f32::INFINITY] {
        assert!(matches!(
            Choice::new(&Ggx::isotropic(0.3).unwrap(), &Conductor::perfect(), b),
            Err(Error::InvalidParameter { name: "budget", .. })
        ));
    }
    // smooth surfaces are Dirac lobes: single scattering loses nothing
    let smooth = Choice::new(&Ggx::isotropic(1e-4).unwrap(), &Conductor::perfect(), 0.0).unwrap();
    assert_eq!((smooth.technique, smooth.error), (ChosenTechnique::SingleScattering, 0.0));
}

/// Per channel: the hemispherical albedo Ā = 2∫A(μ)μ dμ of a BSDF, one sample per
/// cosine-weighted view (from below for `below`).
fn hemispherical(bsdf: &dyn Bsdf, below: bool, n: usize, seed: u64) -> [Stats; 3] {
    let mut rng = validation::rng(seed);
    let mut stats = [Stats::default(); 3];
    for _ in 0..n {
        let mu = uniform32(&mut rng).sqrt().max(1e-4);
        let wo = Vec3::new((1.0 - mu * mu).sqrt(), 0.0, if below { -mu } else { mu });
        let (uc, u) = (uniform32(&mut rng), Vec2::new(uniform32(&mut rng), uniform32(&mut rng)));
        let w = bsdf.sample(wo, uc, u).map_or(Vec3::ZERO, |s| s.weight);
        for c in 0..3 {
            stats[c].push(f64::from(w[c]));
        }
    }
    stats
}

/// A sampled point of the bound test: the three BSDFs (single scattering, compensated, walk),
/// the sides to look from, the chooser's candidates.
struct Point {
    label: &'static str,
    bsdfs: [Box<dyn Bsdf>; 3],
    sides: &'static [bool],
    candidates: Candidates,
    /// Views per technique and side (the dielectrics' weights vary more).
    n: usize,
}

/// The BSDF of a technique for a slope and a material, built by the chooser's `build`.
fn built<S: AlbedoTabulated + 'static, M: Budgeted + 'static>(
    technique: ChosenTechnique,
    slope: S,
    m: M,
    transport: Transport,
) -> Box<dyn Bsdf> {
    let choice = Choice { technique, error: 0.0, cost: 1.0 };
    Box::new(choice.build(slope, m).unwrap().with_transport(transport))
}

fn point<S: AlbedoTabulated + 'static, M: Budgeted + 'static>(
    label: &'static str,
    slope: S,
    m: M,
    transmits: bool,
) -> Point {
    let t = Transport::Importance; // flux: the walk conserves it
    Point {
        label,
        bsdfs: [
            built(ChosenTechnique::SingleScattering, slope, m, t),
            built(ChosenTechnique::Compensated, slope, m, t),
            built(ChosenTechnique::RandomWalk, slope, m, t),
        ],
        sides: if transmits { &[false, true] } else { &[false] },
        candidates: Candidates::new(&slope, &m).unwrap(),
        // the dielectrics' weights vary more
        n: if transmits { 1 << 17 } else { 1 << 16 },
    }
}

/// At roughnesses and materials off the study's grid, the measured hemispherical albedo error
/// of single scattering and of the compensated lobe against the walk is within the chooser's
/// stated error: measured ≤ stated + z·SE per channel and side (one-sided; z Šidák over the
/// family).
#[test]
fn stated_errors_hold_against_the_walk() {
    let points = [
        point("ggx gold α 0.35", Ggx::isotropic(0.35).unwrap(), Conductor::new(ComplexIor::GOLD), false),
        point(
            "beckmann copper α 0.8",
            Beckmann::isotropic(0.8).unwrap(),
            Conductor::new(ComplexIor::COPPER),
            false,
        ),
        point("ggx F = 1 α 0.6", Ggx::isotropic(0.6).unwrap(), Conductor::perfect(), false),
        point("ggx silver α 0.9", Ggx::isotropic(0.9).unwrap(), Conductor::new(ComplexIor::SILVER), false),
        point("ggx glass 1.5 α 0.45", Ggx::isotropic(0.45).unwrap(), Dielectric::new(1.5).unwrap(), true),
        point(
            "beckmann glass 1.7 α 0.25",
            Beckmann::isotropic(0.25).unwrap(),
            Dielectric::new(1.7).unwrap(),
            true,
        ),
    ];
    let tests: usize = points.iter().map(|p| 2 * 3 * p.sides.len()).sum();
    // one-sided tests: the two-sided z at twice the level
    let z = family_z(2.0 * 1e-3, tests);
    for (k, p) in points.iter().enumerate() {
        let stated = [p.candidates.single.unwrap(), p.candidates.compensated.unwrap()];
        for &below in p.sides {
            let seed = 100 * k as u64 + u64::from(below);
            let n = p.n;
            let walk = hemispherical(p.bsdfs[2].as_ref(), below, n, seed);
            for (t, name) in [(0, "single scattering"), (1, "compensated")] {
                let est = hemispherical(p.bsdfs[t].as_ref(), below, n, seed + 50);
                for c in 0..3 {
                    let diff = (est[c].mean() - walk[c].mean()).abs();
                    let se = est[c].se().hypot(walk[c].se());
                    assert!(se <= 1.5e-3, "{}: {name} SE {se} too large to test a bound", p.label);
                    assert!(
                        diff <= f64::from(stated[t]) + z * se,
                        "{} (below: {below}) channel {c}: {name} |Ā − Ā_walk| = {diff:.5} (N = {n}, walk {:.5}, \
                         σ {:.4}, SE {se:.5}) exceeds the stated {:.5} by z = {:.2} > {z:.2}",
                        p.label,
                        walk[c].mean(),
                        est[c].std(),
                        stated[t],
                        (diff - f64::from(stated[t])) / se
                    );
                }
            }
        }
    }
}

#[test]
fn the_built_bsdf_is_the_chosen_technique() {
    let slope = Ggx::isotropic(0.5).unwrap();
    let gold = Conductor::new(ComplexIor::GOLD);
    let wo = Vec3::new(0.6, 0.0, 0.8);
    let wi = Vec3::new(-0.3, 0.2, 0.9327379);
    for (technique, exact) in [
        (ChosenTechnique::SingleScattering, true),
        (ChosenTechnique::Compensated, true),
        (ChosenTechnique::RandomWalk, false),
    ] {
        let choice = Choice { technique, error: 0.0, cost: 1.0 };
        let bsdf = choice.build(slope, gold).unwrap();
        let v = bsdf.eval(wo, wi);
        assert_eq!(v.exact, exact, "{technique:?}");
        let reference: Box<dyn Bsdf> = match technique {
            ChosenTechnique::SingleScattering => Box::new(
                MicrofacetBsdf::new(slope, gold).unwrap().with_technique(Technique::SingleScattering),
            ),
            ChosenTechnique::Compensated => Box::new(microsurface::Compensated::new(slope, gold).unwrap()),
            ChosenTechnique::RandomWalk => Box::new(MicrofacetBsdf::new(slope, gold).unwrap()),
        };
        assert_eq!(v, reference.eval(wo, wi), "{technique:?}");
        assert_eq!(bsdf.sample(wo, 0.3, Vec2::new(0.2, 0.9)), reference.sample(wo, 0.3, Vec2::new(0.2, 0.9)));
    }
}
