//! Russian roulette with `BsdfSample::eta` as its documentation says (throughput × η² over
//! the path's transmissions, pbrt-v4's `etaScale`), in a white glass furnace: an infinite slab
//! of rough glass (GGX α = 0.3, η = 1.5) between two parallel interfaces, lit by a uniform
//! environment of radiance 1 and traced from above. A path leaves the slab at its first event
//! that sends it into the air, and then sees the environment.

use super::fixtures::*;

/// The environment's radiance.
const L_ENV: f64 = 1.0;
/// The longest path (events); the tracer with and without roulette share it, so that both
/// estimate the same truncated sum.
const MAX_EVENTS: usize = 400;

/// How the tracer decides its roulette.
#[derive(Clone, Copy, PartialEq)]
enum Roulette {
    /// No roulette.
    Off,
    /// Survival probability min(1, max(throughput) × Π η²): the documented rule.
    TimesEtaSq,
    /// Survival probability min(1, max(throughput) / Π η²): the rule the documentation once
    /// gave.
    OverEtaSq,
}

/// One path's radiance estimate and whether it reached `MAX_EVENTS`; the survival
/// probability of its first roulette decision goes to `first`.
fn trace(
    b: &dyn Bsdf,
    wo_top: Vec3,
    roulette: Roulette,
    rng: &mut TestRng,
    first: &mut Stats,
) -> (f64, bool) {
    let mut decided = false;
    let mut d = -wo_top;
    let mut inside = false;
    let mut throughput = Vec3::ONE;
    let mut eta_scale = 1.0f32;
    for _ in 0..MAX_EVENTS {
        // the interface hit: its normal points to the air side (+z for the top one)
        let n = if inside && d.z < 0.0 { Vec3::NEG_Z } else { Vec3::Z };
        let frame = ShadingFrame::from_normal(n).unwrap();
        let s = match b.sample_rng(frame.to_local(-d), rng) {
            Some(s) => s,
            None => return (0.0, false),
        };
        throughput *= s.weight;
        if s.flags.transmission {
            eta_scale *= s.eta * s.eta;
        }
        if s.wi.z > 0.0 {
            // into the air: the environment
            return (f64::from(throughput.x) * L_ENV, false);
        }
        inside = true;
        d = frame.to_world(s.wi);
        let q = match roulette {
            Roulette::Off => continue,
            Roulette::TimesEtaSq => throughput.max_element() * eta_scale,
            Roulette::OverEtaSq => throughput.max_element() / eta_scale,
        }
        .min(1.0);
        if !decided {
            first.push(f64::from(q));
            decided = true;
        }
        if uniform32(rng) >= q {
            return (0.0, false);
        }
        throughput /= q;
    }
    (0.0, true)
}

/// The random walk conserves energy: in the furnace every path that leaves carries radiance
/// exactly 1 (1/η² entering the glass, η² leaving it), so the estimate is 1. Following the
/// documentation, the roulette's survival probability throughput × Π η² is the energy the
/// path carries, 1, at every event inside the glass: no path is killed. The rule that divides
/// by η² gives the first decision inside the glass a survival probability of 1/η⁴ ≈ 0.2 (it
/// kills 80 % of the paths that enter, which all carry their full energy) and stays unbiased,
/// with a larger variance.
#[test]
fn roulette_as_documented_tracks_the_energy_in_a_glass_furnace() {
    const N: usize = 20_000;
    let b = mf(ggx(0.3, 0.3), dielectric());
    let z = family_z(0.01, 2);
    for (label, rule) in [("× η²", Roulette::TimesEtaSq), ("/ η²", Roulette::OverEtaSq)] {
        let mut rng = validation::rng(9100);
        let (mut est, mut q, mut truncated) = (Stats::default(), Stats::default(), 0);
        for _ in 0..N {
            let wo = dir(1.4 * uniform64(&mut rng), 2.0 * PI * uniform64(&mut rng));
            let (l, cut) = trace(&b, wo, rule, &mut rng, &mut q);
            est.push(l);
            truncated += usize::from(cut);
        }
        let dev = (est.mean() - L_ENV).abs();
        println!(
            "{label}: N {N}, mean {:.5} ± {:.1e}, first survival {:.4} ({} paths entered)",
            est.mean(),
            est.se(),
            q.mean(),
            q.n
        );
        assert!(truncated <= N / 1000, "{label}: {truncated} paths reached {MAX_EVENTS} events");
        assert!(q.n > N as u64 / 2, "{label}: only {} paths entered the glass", q.n);
        if rule == Roulette::TimesEtaSq {
            // every survival probability is the energy, 1 (to f32 rounding): the estimate is
            // the share of paths that leave before the walk's bounce cap, within 1e-3 of 1
            assert!(q.mean() >= 1.0 - 1e-6, "{label}: mean survival {}", q.mean());
            assert!(dev <= 1e-3, "{label}: mean {} ≠ 1", est.mean());
        } else {
            let expected = 1.0 / 1.5f64.powi(4);
            assert!(
                (q.mean() - expected).abs() <= 1e-5,
                "{label}: first survival {} ≠ 1/η⁴ = {expected}",
                q.mean()
            );
            assert!(est.se() <= 0.02, "{label}: SE {} too large to test the mean", est.se());
            assert!(dev <= z * est.se(), "{label}: mean {} ± {} ≠ 1 (z = {z})", est.mean(), est.se());
        }
    }
}

/// Single scattering loses the energy of the higher orders at every event: the roulette then
/// decides on throughput × Π η², the energy the path still carries, and the tracer stays
/// unbiased: its estimate equals that of the same tracer without roulette.
#[test]
fn roulette_as_documented_is_unbiased_for_lossy_glass() {
    const N: usize = 40_000;
    let b = mf(ggx(0.3, 0.3), dielectric()).with_technique(Technique::SingleScattering);
    let mut stats = [Roulette::Off, Roulette::TimesEtaSq].map(|rule| {
        let mut rng = validation::rng(9200 + rule as u64);
        let (mut est, mut q) = (Stats::default(), Stats::default());
        for _ in 0..N {
            let wo = dir(1.4 * uniform64(&mut rng), 2.0 * PI * uniform64(&mut rng));
            est.push(trace(&b, wo, rule, &mut rng, &mut q).0);
        }
        (est, q)
    });
    let (q_on, q_off) = (stats[1].1.mean(), stats[0].1.n);
    println!(
        "no roulette {:.5} ± {:.1e}; roulette {:.5} ± {:.1e}, first survival {q_on:.4} ({} paths entered)",
        stats[0].0.mean(),
        stats[0].0.se(),
        stats[1].0.mean(),
        stats[1].0.se(),
        stats[1].1.n
    );
    assert_eq!(q_off, 0);
    // the lossy glass kills some paths, and keeps most (the energy lost per event is small)
    assert!(stats[1].1.n > N as u64 / 2 && q_on < 1.0 && q_on > 0.5, "survival {q_on}");
    let [(a, _), (b_, _)] = &mut stats;
    assert_two_sample(
        "single-scattering glass furnace: roulette against none",
        a,
        b_,
        family_z(0.01, 1),
        0.01,
    );
}
