//! `EnergyByOrder`: the energy per scattering order against the albedo.

use super::fixtures::*;
use super::weights::{MAX_REL_SE, proposal_pdf, proposal_sample, view_out};

/// Batches of `energy_by_order`: the table of all walks, and per-batch statistics of the
/// total and of the first order (for their standard errors).
fn energy_batches<S: MicrosurfaceSlope, M: Material + SpecularLimit>(
    b: &Mf<S, M>,
    wo: Vec3,
    batches: usize,
    walks: usize,
    seed: u64,
) -> (Stats, Stats) {
    let mut rng = validation::rng(seed);
    let (mut total, mut first) = (Stats::default(), Stats::default());
    for _ in 0..batches {
        let t = b.energy_by_order(wo, walks, &mut rng);
        assert_eq!(t.walks, walks);
        assert!(t.per_order.iter().all(|&e| e >= 0.0 && e.is_finite()) && t.beyond >= 0.0, "{t:?}");
        assert_eq!(t.left_out(0), t.total());
        let mut previous = t.left_out(0);
        for n in 1..=12 {
            let l = t.left_out(n);
            assert!(l <= previous + 1e-12 && l >= -1e-12, "left_out({n}) = {l} after {previous}: {t:?}");
            previous = l;
        }
        assert!((t.left_out(8) - t.beyond).abs() <= 1e-12 && (t.left_out(20) - t.beyond).abs() <= 1e-12);
        assert!((t.left_out(1) - (t.total() - t.per_order[0])).abs() <= 1e-12);
        total.push(t.total());
        first.push(t.per_order[0]);
    }
    (total, first)
}

/// Statistics of the channel-averaged albedo ∫ eval·|cos θi| dωi.
fn albedo_mean_stats<S: MicrosurfaceSlope, M: Material + SpecularLimit>(
    b: &Mf<S, M>,
    wo: Vec3,
    n: usize,
    seed: u64,
) -> Stats {
    let mut rng = validation::rng(seed);
    let mut st = Stats::default();
    for _ in 0..n {
        let w = proposal_sample(b, wo, &mut rng);
        let p = proposal_pdf(b, wo, w);
        let f = b.eval_rng(wo, w, &mut rng).f;
        st.push(if p > 0.0 { f64::from(f.element_sum()) / 3.0 * f64::from(w.z.abs()) / p } else { 0.0 });
    }
    st
}

/// The table's total equals the albedo of the technique (the random walk's for single
/// scattering, as documented), its first order equals the single-scattering albedo, and
/// left_out is a non-increasing tail sum with left_out(0) = total.
#[test]
fn energy_by_order_matches_the_albedo() {
    let z = family_z(0.01, 6);
    let wo = view_out();
    let g = ggx(ALPHA_MS, ALPHA_MS);
    let bk = beckmann(ALPHA_MS, ALPHA_MS);
    let walk = Technique::RandomWalk;
    let ss = Technique::SingleScattering;
    let check = |label: &str, e: &Stats, a: &Stats| {
        println!("{label}: table {:.5} ± {:.5}, albedo {:.5} ± {:.5}", e.mean(), e.se(), a.mean(), a.se());
        assert_two_sample(label, e, a, z, MAX_REL_SE * a.mean().max(0.25));
    };

    let b = mf(g, gold());
    let (total, first) = energy_batches(&b.with_technique(walk), wo, 20, 3000, 5100);
    check("walk GGX gold: total", &total, &albedo_mean_stats(&b.with_technique(walk), wo, 60_000, 5101));
    check("walk GGX gold: order 1", &first, &albedo_mean_stats(&b.with_technique(ss), wo, 60_000, 5102));
    // single scattering tabulates the random walk
    let (total_ss, _) = energy_batches(&b.with_technique(ss), wo, 20, 3000, 5103);
    assert_two_sample("single GGX gold: table of the walk", &total_ss, &total, z, 0.01);

    let b = mf(bk, diffuse()).with_technique(walk);
    let (total, _) = energy_batches(&b, wo, 20, 3000, 5110);
    check("walk Beckmann diffuse: total", &total, &albedo_mean_stats(&b, wo, 60_000, 5111));

    // the table ignores the transport factor: compare with importance transport
    let b = mf(g, dielectric()).with_technique(walk).with_transport(Transport::Importance);
    let (total, _) = energy_batches(&b, wo, 20, 3000, 5120);
    check("walk GGX dielectric: total", &total, &albedo_mean_stats(&b, wo, 60_000, 5121));

    let b = mf(bk, gold()).with_technique(BDPT_UNCORRELATED);
    let (total, _) = energy_batches(&b, wo, 20, 3000, 5130);
    check("pf-bdpt-uncorr Beckmann gold: total", &total, &albedo_mean_stats(&b, wo, 30_000, 5131));
}
