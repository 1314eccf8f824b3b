//! The MERL isotropic BRDF format: round trip of files the crate writes from its own models,
//! MERL's nearest-bin lookup, bad files, and the extraction (Dupuy 2015 §4.2) run on a file.

use glam::Vec3;
use microsurface::research::{Microsurface, UniformHeight};
use microsurface::tabulated::{
    BackscatterShadowing, MerlBrdf, MerlError, TabulatedSlope, extract_isotropic_fn, half_diff_angles,
};
use microsurface::{Conductor, Ggx};
use std::f64::consts::{FRAC_PI_2, PI};
use validation::{dir, rng, uniform64};

fn ggx_brdf(alpha: f32) -> impl Fn(Vec3, Vec3) -> Vec3 {
    let surface = Microsurface::new(UniformHeight, Ggx::isotropic(alpha).unwrap(), Conductor::perfect());
    move |i, o| {
        let mut g = rng(0);
        surface.eval_single_scattering(i, o, &mut g) / o.z
    }
}

#[test]
fn round_trip_and_lookup() {
    let f = ggx_brdf(0.4);
    let merl = MerlBrdf::from_fn(&f);
    let bytes = merl.to_bytes();
    assert_eq!(bytes.len(), 12 + 3 * 90 * 90 * 180 * 8);
    let back = MerlBrdf::from_bytes(&bytes).unwrap();
    let mut g = rng(7);
    let mut checked = 0;
    for _ in 0..20_000 {
        let wi = dir((uniform64(&mut g) * FRAC_PI_2).min(1.55), uniform64(&mut g) * 2.0 * PI);
        let wo = dir((uniform64(&mut g) * FRAC_PI_2).min(1.55), uniform64(&mut g) * 2.0 * PI);
        let (Some(a), Some(b)) = (merl.eval(wi, wo), back.eval(wi, wo)) else { continue };
        // the written and re-read values agree to the f64 rounding of the scales
        assert!((a - b).abs().max_element() <= 1e-6 * a.abs().max_element().max(1e-30), "{a} vs {b}");
        checked += 1;
    }
    assert!(checked > 15_000, "only {checked} lookups had data");
    // at bin centres the lookup returns the tabulated function exactly (same directions)
    for (th, td, pd) in [(10usize, 3usize, 7usize), (40, 20, 100), (70, 60, 179)] {
        let theta_h = ((th as f64 + 0.5) / 90.0).powi(2) * FRAC_PI_2;
        let theta_d = (td as f64 + 0.5) / 90.0 * FRAC_PI_2;
        let phi_d = (pd as f64 + 0.5) / 180.0 * PI;
        let h = glam::DVec3::new(theta_h.sin(), 0.0, theta_h.cos());
        let d = glam::DVec3::new(theta_d.sin() * phi_d.cos(), theta_d.sin() * phi_d.sin(), theta_d.cos());
        // rotate d about y by θh
        let i = glam::DVec3::new(
            d.x * theta_h.cos() + d.z * theta_h.sin(),
            d.y,
            -d.x * theta_h.sin() + d.z * theta_h.cos(),
        );
        let o = 2.0 * i.dot(h) * h - i;
        if i.z <= 0.0 || o.z <= 0.0 {
            continue;
        }
        let (wi, wo) = (i.as_vec3(), o.as_vec3());
        let (a, b) = (back.eval(wi, wo).unwrap(), f(wi, wo));
        assert!((a - b).abs().max_element() <= 1e-6 * b.max_element(), "bin ({th}, {td}, {pd}): {a} vs {b}");
        let (h2, d2, _) = half_diff_angles(wi, wo).unwrap();
        assert!((h2 - theta_h).abs() < 1e-5 && (d2 - theta_d).abs() < 1e-5);
    }
    // reciprocity of the lookup: φd folded by +π
    let (wi, wo) = (dir(0.5, 0.3), dir(0.9, 2.0));
    assert_eq!(back.eval(wi, wo), back.eval(wo, wi));
    // below the horizon: nothing
    assert_eq!(back.eval(dir(1.7, 0.0), wo), None);
}

#[test]
fn bad_files_are_errors() {
    let good = MerlBrdf::from_fn(ggx_brdf(0.5)).to_bytes();
    assert!(matches!(MerlBrdf::from_bytes(&[]), Err(MerlError::Truncated { .. })));
    assert!(matches!(MerlBrdf::from_bytes(&good[..7]), Err(MerlError::Truncated { .. })));
    assert!(matches!(MerlBrdf::from_bytes(&good[..good.len() - 8]), Err(MerlError::Truncated { .. })));
    let mut longer = good.clone();
    longer.push(0);
    assert!(matches!(MerlBrdf::from_bytes(&longer), Err(MerlError::TrailingBytes(1))));
    let mut dims = good.clone();
    dims[0] = 91;
    assert!(matches!(MerlBrdf::from_bytes(&dims), Err(MerlError::Dimensions([91, 90, 180]))));
    let mut nan = good.clone();
    nan[12 + 8 * 5..12 + 8 * 6].copy_from_slice(&f64::NAN.to_le_bytes());
    assert!(matches!(MerlBrdf::from_bytes(&nan), Err(MerlError::NonFinite(5))));
    assert!(matches!(MerlBrdf::read("/nonexistent/file.binary"), Err(MerlError::Io(_))));
    // a file written to disk reads back
    let path = std::env::temp_dir().join(format!("microsurface-merl-{}.binary", std::process::id()));
    MerlBrdf::from_bytes(&good).unwrap().write(&path).unwrap();
    let read = MerlBrdf::read(&path).unwrap();
    std::fs::remove_file(&path).unwrap();
    assert_eq!(read.to_bytes(), good);
}

/// The extraction run on a MERL file of the crate's single-scattering GGX α = 0.5 (F = 1):
/// the backscattering comes from the θd = 0 bins (θd = 0.5°) and the θh bins (nearest
/// neighbour), so the extracted α is within 2 % and F0 within 2 % of 1.
#[test]
fn extraction_from_a_merl_file() {
    let alpha = 0.5f32;
    let merl = MerlBrdf::from_bytes(&MerlBrdf::from_fn(ggx_brdf(alpha)).to_bytes()).unwrap();
    let e = extract_isotropic_fn(alpha, 64, 8, BackscatterShadowing::HeightCorrelated, |theta| {
        merl.backscatter(theta).map_or(f64::NAN, |v| f64::from(v.x))
    })
    .unwrap();
    let truth = TabulatedSlope::from_slope(&Ggx::isotropic(alpha).unwrap(), alpha, 64).unwrap();
    println!(
        "from MERL: F0 = {:.5}, fitted GGX α = {:.5} (truth {alpha}; truth table {:.5})",
        e.f0,
        e.slope.alpha(),
        truth.alpha()
    );
    assert!((e.f0 - 1.0).abs() < 2e-2);
    assert!((e.slope.alpha() / alpha - 1.0).abs() < 2e-2);
}

/// The MERL path of the 2D grid: a MERL file of the crate's single-scattering gold conductor
/// on the isotropic GGX α = 0.5 (red channel), the grid extracted from its backscattering by
/// direction (`MerlBrdf::backscatter_toward`, 2 × 20 cells per axis, eight iterations) and the
/// Fresnel term from its BRDF on that grid (`extract_fresnel`, as for the radial table). The
/// grid is isotropic (its GGX-equivalent roughnesses along x and y within 1e-3: the file is
/// isotropic), its roughness within 5 % of α (measured 3.3 %), F0 within 3 % of gold's
/// (measured 1.2 %) and F(θd) for θd up to 60° within 8 % (measured 5.0 %): the coarse grid's D
/// at the lobe and the file's nearest-bin lookup (1° bins of θd, θh binned in √θh), against
/// 0.5 % for the 128-ring table from the same file.
#[test]
fn grid_extraction_from_a_merl_file() {
    use microsurface::fresnel::fresnel_conductor;
    use microsurface::slope::MicrosurfaceSlope;
    use microsurface::tabulated::{BackscatterShadowing, GridSlope, extract_anisotropic_fn, extract_fresnel};
    use microsurface::{ComplexIor, Conductor};
    let alpha = 0.5f32;
    let gold = ComplexIor::new(Vec3::new(0.143, 0.374, 1.442), Vec3::new(3.983, 2.385, 1.603)).unwrap();
    let surface = Microsurface::new(UniformHeight, Ggx::isotropic(alpha).unwrap(), Conductor::new(gold));
    let merl = MerlBrdf::from_bytes(
        &MerlBrdf::from_fn(|i, o| {
            let mut g = rng(0);
            surface.eval_single_scattering(i, o, &mut g) / o.z
        })
        .to_bytes(),
    )
    .unwrap();
    let hc = BackscatterShadowing::HeightCorrelated;
    let e = extract_anisotropic_fn(alpha, alpha, 20, 8, hc, |o| {
        merl.backscatter_toward(o).map_or(f64::NAN, |v| f64::from(v.x))
    })
    .unwrap();
    let grid: &GridSlope = &e.slope;
    let (ax, ay) = (grid.alpha_x(), grid.alpha_y());
    let bins = 6;
    let fresnel =
        extract_fresnel(grid, hc, bins, 12, 12, |i, o| merl.eval(i, o).map_or(f64::NAN, |v| f64::from(v.x)));
    let f_normal = f64::from(fresnel_conductor(1.0, &gold).x);
    let mut worst = 0.0f64;
    for (b, f) in fresnel.iter().enumerate() {
        let theta_d = (b as f64 + 0.5) * FRAC_PI_2 / bins as f64;
        let exact = f64::from(fresnel_conductor(theta_d.cos() as f32, &gold).x);
        let f = f.expect("valid configurations");
        println!("grid from MERL, θd = {:.1}°: F {f:.5}, exact {exact:.5}", theta_d.to_degrees());
        if theta_d < 60f64.to_radians() {
            worst = worst.max((f / exact - 1.0).abs());
        }
    }
    println!(
        "grid from MERL: F0 = {:.5} (exact {f_normal:.5}), α = ({ax:.4}, {ay:.4}), worst F(θd) relative error {worst:.3e}",
        e.f0
    );
    assert!((ax / ay - 1.0).abs() < 1e-3, "anisotropic: ({ax}, {ay})");
    assert!((ax / alpha - 1.0).abs() < 5e-2 && (ay / alpha - 1.0).abs() < 5e-2, "α = ({ax}, {ay})");
    assert!((e.f0 / f_normal - 1.0).abs() < 3e-2, "F0 = {} vs {f_normal}", e.f0);
    assert!(worst < 8e-2, "F(θd) off by {worst:.3e}");
}
