//! Chi-square tests of the position-free `sample` against the averaged evaluation: the exit
//! directions of `PositionFree::sample` (weight 1 for non-absorptive materials) must follow
//! E[eval_bdpt(ωi, ωo)] = f·|cos θo| as a density of ωo, for both shadowing models
//! (Wang et al. 2022, §4.3).

use glam::Vec3;
use microsurface::research::{Material, PositionFree, ScatteringOrder, Shadowing};
use microsurface::{Conductor, Dielectric, Ggx};
use validation::par_map;
use validation::stochastic::stochastic_chi2;

/// Samples per test.
const N: usize = 50_000;

fn run<M: Material>(
    label: &str,
    material: M,
    alpha: f32,
    shadowing: Shadowing,
    seed: u64,
    alpha_test: f64,
) -> f64 {
    let pf = PositionFree::new(Ggx::isotropic(alpha).unwrap(), material, shadowing);
    let wi = validation::dir(0.5, 0.3);
    let mut eval_rng = validation::rng(seed);
    let mut sample_rng = validation::rng(seed + 1);
    let transmits = M::TRANSMITS;
    let z_lo = if transmits { -1.0 } else { 0.0 };
    let (nz, nphi) = if transmits { (16, 16) } else { (8, 16) };
    let out = stochastic_chi2(
        label,
        z_lo,
        nz,
        nphi,
        &mut |wo: Vec3| f64::from(pf.eval_bdpt(wi, wo, ScatteringOrder::All, &mut eval_rng).x),
        &mut || {
            let s = pf.sample(wi, &mut sample_rng)?;
            assert_eq!(s.weight, Vec3::ONE, "{label}: non-absorptive weights are 1");
            Some(s.wo)
        },
        N,
        alpha_test,
    );
    out.p_value
}

#[test]
fn position_free_sampling_matches_the_averaged_evaluation() {
    let cases: Vec<(bool, f32, Shadowing)> = [false, true]
        .into_iter()
        .flat_map(|dielectric| {
            [0.5f32, 1.0].into_iter().flat_map(move |alpha| {
                [Shadowing::Uncorrelated, Shadowing::Correlated]
                    .into_iter()
                    .map(move |sh| (dielectric, alpha, sh))
            })
        })
        .collect();
    let alpha_test = validation::sidak(0.01, cases.len());
    let p = par_map(&cases, |i, &(dielectric, alpha, sh)| {
        let seed = 9_000 + 10 * i as u64;
        if dielectric {
            let label = format!("dielectric η=1.5 GGX α={alpha} {sh:?}");
            run(&label, Dielectric::new(1.5).unwrap(), alpha, sh, seed, alpha_test)
        } else {
            let label = format!("conductor F=1 GGX α={alpha} {sh:?}");
            run(&label, Conductor::perfect(), alpha, sh, seed, alpha_test)
        }
    });
    println!("position-free sampling: p-values {p:.4?} (per-test α = {alpha_test:.2e})");
}
