//! `MicrofacetBsdf` over correlated slopes (`Elliptical`, ρ ≠ 0, φα ≠ 0): single scattering's
//! samples against its pdf (χ², weight = f·|cos θi|/pdf), and E[weight] = albedo for the walk
//! and the position-free PT and BDPT estimators.

use super::densities::chi2_exact;
use super::fixtures::*;
use super::weights::check_weight_vs_albedo;
use microsurface::Elliptical;

/// The correlated GGX of the tests: marginals (0.6, 0.35), ρ = 0.5 (φα ≈ 0.46).
fn elliptical_ggx() -> Elliptical<Ggx> {
    Elliptical::from_bivariate(0.6, 0.35, 0.5).unwrap()
}

/// The correlated Beckmann of the tests: the ellipse (0.25, 0.55) at φα = −0.8.
fn elliptical_beckmann() -> Elliptical<Beckmann> {
    Elliptical::from_ellipse(0.25, 0.55, -0.8).unwrap()
}

/// Four of the binary's `CHI2_FAMILY` χ² tests: GGX and Beckmann, gold and the dielectric.
#[test]
fn elliptical_single_scattering_sampling_matches_pdf() {
    let ss = Technique::SingleScattering;
    let z = family_z(0.01, 4);
    let wo = dir(0.9, 2.1);
    let b = mf(elliptical_ggx(), gold()).with_technique(ss);
    chi2_exact("single elliptical GGX gold", &b, wo, 7100, z, 1.0);
    let b = mf(elliptical_ggx(), dielectric()).with_technique(ss);
    chi2_exact("single elliptical GGX dielectric", &b, wo, 7110, z, 1.0);
    let b = mf(elliptical_beckmann(), gold()).with_technique(ss);
    chi2_exact("single elliptical Beckmann gold", &b, wo, 7120, z, 1.0);
    let b = mf(elliptical_beckmann(), dielectric()).with_technique(ss);
    chi2_exact("single elliptical Beckmann dielectric", &b, wo, 7130, z, 1.0);
}

/// E[weight] = albedo (independently estimated from `eval`) for the walk and position-free PT
/// and BDPT, over both correlated slopes: gold (3 channels) and the perfect conductor, whose
/// albedo is the furnace (energy-conserving multiple scattering).
#[test]
fn elliptical_weight_matches_albedo() {
    let techniques =
        [("walk", Technique::RandomWalk), ("pf-pt-corr", PT_CORRELATED), ("pf-bdpt-corr", BDPT_CORRELATED)];
    // per technique and slope: gold (3 channels) + the perfect conductor (1)
    let z = family_z(0.01, techniques.len() * 2 * 4);
    let wo = dir(0.7, -1.9);
    let mut seed = 7200;
    for (tname, t) in techniques {
        let n_eval = if t == Technique::RandomWalk { 60_000 } else { 30_000 };
        seed += 10;
        let g = elliptical_ggx();
        let label = format!("{tname} elliptical GGX");
        check_weight_vs_albedo(
            &format!("{label} gold"),
            &mf(g, gold()).with_technique(t),
            wo,
            true,
            60_000,
            n_eval,
            seed,
            z,
        );
        check_weight_vs_albedo(
            &format!("{label} F=1"),
            &mf(g, Conductor::perfect()).with_technique(t),
            wo,
            false,
            60_000,
            n_eval,
            seed + 2,
            z,
        );
        let bk = elliptical_beckmann();
        let label = format!("{tname} elliptical Beckmann");
        check_weight_vs_albedo(
            &format!("{label} gold"),
            &mf(bk, gold()).with_technique(t),
            wo,
            true,
            60_000,
            n_eval,
            seed + 4,
            z,
        );
        check_weight_vs_albedo(
            &format!("{label} F=1"),
            &mf(bk, Conductor::perfect()).with_technique(t),
            wo,
            false,
            60_000,
            n_eval,
            seed + 6,
            z,
        );
    }
}

/// The compensated lobes accept correlated slopes (their tables are read at √(α₁ α₂)).
#[test]
fn compensated_lobes_accept_elliptical_slopes() {
    use microsurface::{Compensated, Compensation};
    for scheme in [Compensation::KullaConty, Compensation::Turquin, Compensation::Walk] {
        let c = Compensated::with_scheme(elliptical_ggx(), gold(), scheme).unwrap();
        let v = c.eval(dir(0.6, 0.3), dir(0.8, 2.0));
        assert!(v.f.is_finite() && v.f.min_element() > 0.0, "{scheme:?} conductor GGX: {}", v.f);
        let c = Compensated::with_scheme(elliptical_beckmann(), gold(), scheme).unwrap();
        assert!(c.eval(dir(0.6, 0.3), dir(0.8, 2.0)).f.min_element() > 0.0, "{scheme:?} conductor Beckmann");
    }
    for scheme in [Compensation::Turquin, Compensation::Walk] {
        let d = Compensated::with_scheme(elliptical_ggx(), dielectric(), scheme);
        assert!(d.is_ok(), "{scheme:?} dielectric GGX: {d:?}");
        let d = Compensated::with_scheme(elliptical_beckmann(), dielectric(), scheme);
        assert!(d.is_ok(), "{scheme:?} dielectric Beckmann: {d:?}");
    }
}
