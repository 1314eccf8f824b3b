//! Exact densities: chi-square, weights, ∫pdf ≤ 1; normal mapping (backfacing views in the
//! shading frame, Tokuyoshi).

use super::fixtures::*;
use super::weights::{albedo_stats, check_weight_vs_albedo};

/// Samples per chi-square test.
const CHI2_N: usize = 200_000;

/// 20 × 40 equal-area cells of the sphere. Expected counts are ~N/800 = 250: a quadrature
/// error of 1e-5 over the sphere (1.25e-8 per cell) is far below their Poisson noise.
fn chi2_grid() -> Chi2Grid {
    Chi2Grid { quad_tol: 1e-5, max_depth: 7, ..Chi2Grid::sphere(20, 40) }
}

/// ∫ pdf(wo, ·) over the sphere by adaptive quadrature.
fn pdf_mass<B: Bsdf>(b: &B, wo: Vec3) -> f64 {
    integrate_sphere(&mut |w| f64::from(b.pdf(wo, w)), 16, 32, Domain::Sphere, 1e-5, 7)
}

/// For a BSDF with an exact density: ∫pdf ≤ 1; `sample` passes the chi-square test against
/// `pdf` (scaled by `pdf_scale`, 1 except in the negative controls), its refusals (`None`)
/// match the mass ∫pdf leaves out (binomial, z·SE + the quadrature's 1e-3), and every
/// sample's weight is eval·|cos θi|/pdf (relative 1e-4): [`validation::chi2::bsdf_chi2`], with
/// ∫pdf from 16 × 32 panels to 1e-5. Returns (p-value, ∫pdf).
pub(crate) fn chi2_exact<B: Bsdf>(
    label: &str,
    b: &B,
    wo: Vec3,
    seed: u64,
    z: f64,
    pdf_scale: f64,
) -> (f64, f64) {
    chi2_exact_refined(label, b, wo, seed, z, pdf_scale, 0)
}

/// [`chi2_exact`] with the cells' quadrature split `min_depth` times before its adaptive test
/// (`Chi2Grid::min_depth`): for densities with a jump along a curve the cells do not follow.
pub(crate) fn chi2_exact_refined<B: Bsdf>(
    label: &str,
    b: &B,
    wo: Vec3,
    seed: u64,
    z: f64,
    pdf_scale: f64,
    min_depth: u32,
) -> (f64, f64) {
    let mut rng = validation::rng(seed);
    let mut eval_rng = validation::rng(seed + 7);
    let grid = Chi2Grid { min_depth, ..chi2_grid() };
    let settings = BsdfChi2 { grid, mass: (16, 32, 1e-5, 7), n: CHI2_N, pdf_scale, pdf_consistency: None };
    let out = bsdf_chi2(
        label,
        b,
        wo,
        settings,
        || b.sample_rng(wo, &mut rng),
        |wi| b.eval_rng(wo, wi, &mut eval_rng),
        |_| {},
        chi2_alpha(),
        z,
    );
    (out.chi2.p_value, out.mass)
}

/// The classic BRDFs of one NDF: both maskings at θo = 0.8, and the exact masking near
/// grazing (θo = 1.35, where most specular samples leave below the horizon).
pub(crate) fn classic_models(ndf: ClassicNdf) -> Vec<(String, ClassicBrdf, Vec3)> {
    let (kd, ks) = (Vec3::new(0.3, 0.4, 0.5), Vec3::new(0.6, 0.5, 0.4));
    let mut v = vec![];
    for masking in [ClassicMasking::Exact, ClassicMasking::Rational] {
        let b = ClassicBrdf::new(kd, ks, ndf, masking).unwrap();
        v.push((format!("classic {ndf:?} {masking:?}"), b, dir(0.8, 0.3)));
    }
    let b = ClassicBrdf::new(kd, ks, ndf, ClassicMasking::Exact).unwrap();
    v.push((format!("classic {ndf:?} grazing"), b, dir(1.35, 2.0)));
    v
}

fn classic_sampling_matches_pdf(ndf: ClassicNdf, seed: u64) {
    let models = classic_models(ndf);
    let z = family_z(0.01, models.len());
    for (i, (label, b, wo)) in models.iter().enumerate() {
        let (_, mass) = chi2_exact(label, b, *wo, seed + i as u64, z, 1.0);
        assert!(mass > 0.5, "{label}: ∫pdf = {mass}");
    }
}

#[test]
fn classic_phong_sampling_matches_pdf() {
    classic_sampling_matches_pdf(ClassicNdf::Phong(30.0), 1000);
}

#[test]
fn classic_beckmann_sampling_matches_pdf() {
    classic_sampling_matches_pdf(ClassicNdf::Beckmann(0.3), 1010);
}

#[test]
fn classic_ggx_sampling_matches_pdf() {
    classic_sampling_matches_pdf(ClassicNdf::Ggx(0.3), 1020);
}

/// Single scattering on conductors and dielectrics: anisotropic roughness, views from
/// outside at two angles and from inside the dielectric.
#[test]
fn single_scattering_sampling_matches_pdf() {
    let ss = Technique::SingleScattering;
    let g = ggx(0.25, 0.45);
    let bk = beckmann(0.45, 0.25);
    let z = family_z(0.01, 16);
    let mut p = vec![];
    let mut seed = 2000;
    let mut run = |pv: (f64, f64)| p.push(pv.0);
    for (sname, theta) in [("GGX", 0.5), ("GGX", 1.3), ("Beckmann", 0.5), ("Beckmann", 1.3)] {
        let wo = dir(theta, 0.6);
        seed += 10;
        if sname == "GGX" {
            let b = mf(g, Conductor::perfect()).with_technique(ss);
            run(chi2_exact(&format!("single {sname} F=1 θo={theta}"), &b, wo, seed, z, 1.0));
            let b = mf(ggx(0.5, 0.5), gold()).with_technique(ss);
            run(chi2_exact(&format!("single {sname} gold θo={theta}"), &b, wo, seed + 1, z, 1.0));
        } else {
            let b = mf(bk, Conductor::perfect()).with_technique(ss);
            run(chi2_exact(&format!("single {sname} F=1 θo={theta}"), &b, wo, seed, z, 1.0));
            let b = mf(beckmann(0.5, 0.5), gold()).with_technique(ss);
            run(chi2_exact(&format!("single {sname} gold θo={theta}"), &b, wo, seed + 1, z, 1.0));
        }
    }
    for (sname, wo_r, wo_i) in
        [("GGX", dir(0.5, 0.6), dir(1.2, 2.0)), ("Beckmann", dir(0.5, 0.6), dir(1.2, 2.0))]
    {
        for (transport, wo_out, wo_in) in
            [(Transport::Radiance, wo_r, -dir(0.9, 1.0)), (Transport::Importance, wo_i, -dir(0.5, 1.0))]
        {
            for wo in [wo_out, wo_in] {
                seed += 10;
                let label = format!("single {sname} dielectric {transport:?} wo = {wo}");
                let pv = if sname == "GGX" {
                    let b = mf(g, dielectric()).with_technique(ss);
                    chi2_exact(&label, &b.with_transport(transport), wo, seed, z, 1.0)
                } else {
                    let b = mf(bk, dielectric()).with_technique(ss);
                    chi2_exact(&label, &b.with_transport(transport), wo, seed, z, 1.0)
                };
                run(pv);
            }
        }
    }
    assert_eq!(p.len(), 16);
    println!("single scattering: worst p = {:.4}", p.iter().cloned().fold(1.0, f64::min));
}

/// GGX conductors sampled from the bounded cap where the crate goes beyond Eto and Tokuyoshi's
/// clamp to k = 0: roughness above 1 (k < 0 from a = min(αx, αy) > 1) and a mixed anisotropy
/// (0.6, 3). A bound that dropped normals reflecting above the horizon would leave directions
/// with pdf > 0 unsampled (chi-square) and refuse less than 1 − ∫pdf.
#[test]
fn rough_ggx_conductors_sample_their_bounded_density() {
    let cases = [((2.0f32, 2.0f32), 0.2f64), ((4.0, 4.0), 1.0), ((0.6, 3.0), 0.7), ((10.0, 10.0), 1.45)];
    let z = family_z(0.01, cases.len());
    for (k, ((ax, ay), theta)) in cases.into_iter().enumerate() {
        let b = mf(ggx(ax, ay), gold()).with_technique(Technique::SingleScattering);
        let label = format!("single GGX gold α = ({ax}, {ay}) θo = {theta}");
        chi2_exact(&label, &b, dir(theta, 0.6), 2500 + 10 * k as u64, z, 1.0);
    }
}

// ---------------------------------------------------------------------------------------------
// Normal mapping: backfacing views in the shading frame (Tokuyoshi)
// ---------------------------------------------------------------------------------------------

/// The backfacing configurations: slope, polar angle of wo (> π/2).
fn backfacing_views() -> [(&'static str, f64); 4] {
    [("GGX", 1.8), ("GGX", 2.2), ("Beckmann", 1.8), ("Beckmann", 2.2)]
}

/// The backfacing BSDF over GGX or Beckmann (one of the two is `Some`).
type EitherSlope<M> = (Option<Mf<Ggx, M>>, Option<Mf<Beckmann, M>>);

fn backfacing_bsdf<M: Material + SpecularLimit>(sname: &str, m: M) -> EitherSlope<M> {
    let ss = Technique::SingleScattering;
    if sname == "GGX" {
        (Some(mf(ggx(0.5, 0.5), m).with_technique(ss)), None)
    } else {
        (None, Some(mf(beckmann(0.5, 0.5), m).with_technique(ss)))
    }
}

/// A visible normal m (m.z > 0, wo·m > 0) seen from below the horizon reflects wo to
/// 2(wo·m)m − wo, whose z = 2(wo·m)m.z − wo.z > 0: every sample leaves upwards, so the
/// density of a backfacing view integrates to one (and a model that returns zero light for
/// backfacing views fails here rather than passing the unbiasedness test vacuously).
#[test]
fn normal_mapping_pdf_integrates_to_one() {
    for (sname, theta) in backfacing_views() {
        let wo = dir(theta, 0.3);
        let mass = match backfacing_bsdf(sname, Conductor::perfect()) {
            (Some(b), _) => pdf_mass(&b, wo),
            (_, Some(b)) => pdf_mass(&b, wo),
            _ => unreachable!(),
        };
        assert!(
            (mass - 1.0).abs() <= 1e-3,
            "single {sname} conductor, backfacing θo = {theta}: ∫pdf = {mass}"
        );
    }
}

#[test]
fn normal_mapping_sampling_matches_pdf() {
    let z = family_z(0.01, 4);
    for (i, (sname, theta)) in backfacing_views().into_iter().enumerate() {
        let wo = dir(theta, 0.3);
        let label = format!("single {sname} conductor F=1, backfacing θo = {theta}");
        let (_, mass) = match backfacing_bsdf(sname, Conductor::perfect()) {
            (Some(b), _) => chi2_exact(&label, &b, wo, 3000 + i as u64, z, 1.0),
            (_, Some(b)) => chi2_exact(&label, &b, wo, 3000 + i as u64, z, 1.0),
            _ => unreachable!(),
        };
        assert!(mass > 0.5, "{label}: ∫pdf = {mass}: the chi-square test would pass vacuously");
    }
}

#[test]
fn normal_mapping_weight_is_unbiased() {
    let z = family_z(0.01, 4 * 3);
    for (i, (sname, theta)) in backfacing_views().into_iter().enumerate() {
        let wo = dir(theta, 0.3);
        let label = format!("single {sname} gold, backfacing θo = {theta}");
        let seed = 3100 + 2 * i as u64;
        let albedo = match backfacing_bsdf(sname, gold()) {
            (Some(b), _) => {
                check_weight_vs_albedo(&label, &b, wo, true, 60_000, 60_000, seed, z);
                albedo_stats(&label, &b, wo, true, 2_000, &mut validation::rng(seed + 5))
            }
            (_, Some(b)) => {
                check_weight_vs_albedo(&label, &b, wo, true, 60_000, 60_000, seed, z);
                albedo_stats(&label, &b, wo, true, 2_000, &mut validation::rng(seed + 5))
            }
            _ => unreachable!(),
        };
        let mean = albedo.iter().map(Stats::mean).sum::<f64>() / 3.0;
        assert!(
            mean > 0.05,
            "{label}: albedo {mean}: a backfacing view reflects nothing, the test is vacuous"
        );
    }
}

/// The chi-square test has power: a density scaled by 0.9 (with the matching expected mass)
/// is rejected, for a front-facing and a backfacing view.
#[test]
fn chi2_negative_control() {
    let rejects = |f: &mut dyn FnMut()| {
        let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(f));
        match r {
            Ok(()) => false,
            Err(e) => {
                let msg = e
                    .downcast_ref::<String>()
                    .cloned()
                    .or_else(|| e.downcast_ref::<&str>().map(|s| s.to_string()))
                    .unwrap_or_default();
                assert!(msg.contains("chi-square rejects"), "unexpected failure: {msg}");
                true
            }
        }
    };
    let z = family_z(0.01, 1);
    let b = mf(ggx(0.5, 0.5), Conductor::perfect()).with_technique(Technique::SingleScattering);
    for (wo, what) in [(dir(0.5, 0.3), "front-facing"), (dir(1.8, 0.3), "backfacing")] {
        let rejected = rejects(&mut || {
            chi2_exact(&format!("negative control {what}"), &b, wo, 3900, z, 0.9);
        });
        assert!(rejected, "{what}: a density scaled by 0.9 passed the chi-square test");
    }
}

/// The stochastic techniques' MIS density on conductors of a tabulated slope family (the F = 1
/// walk's exit density: exact single scattering plus a Kulla–Conty lobe from the albedo
/// tables) integrates to one: single scattering's part to the exact E(μo), the lobe's to
/// 1 − E(μo) of the table, up to the table's interpolation error (1.3e-3) and the lobe's
/// normalization by the table's E_avg (the interpolated E's own average differs from it by
/// less than 4e-4 of 1 − E_avg). Bound: 2e-3, with the quadrature's 1e-5.
#[test]
fn walk_mis_density_integrates_to_one() {
    let mut worst = 0.0f64;
    for alpha in [0.05, 0.2, 0.5, 1.0] {
        for theta in [0.0, 0.8, 1.3, 1.5] {
            let wo = dir(theta, 0.4);
            let ggx = MicrofacetBsdf::new(Ggx::isotropic(alpha).unwrap(), Conductor::perfect()).unwrap();
            let beckmann =
                MicrofacetBsdf::new(Beckmann::isotropic(alpha).unwrap(), Conductor::perfect()).unwrap();
            for (name, mass) in [("GGX", pdf_mass(&ggx, wo)), ("Beckmann", pdf_mass(&beckmann, wo))] {
                worst = worst.max((mass - 1.0).abs());
                assert!((mass - 1.0).abs() <= 2e-3, "{name} α = {alpha}, θo = {theta}: ∫pdf = {mass}");
            }
        }
    }
    println!("walk MIS density: largest |∫pdf − 1| = {worst:.2e}");
}
