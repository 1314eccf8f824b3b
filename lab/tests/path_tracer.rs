//! The example path tracer: a white-furnace render in which every (non-absorptive,
//! multiple-scattering) sphere vanishes into the background, and pixels of a single-scattering
//! gold sphere that match an independent numerical integral; renders are the same bits for
//! any number of threads.

use glam::Vec3;
use lab::tracer::{
    self, Camera, Environment, Hit, Lighting, RenderStats, Scene, Sphere, render, showcase_scene,
};
use microsurface::{Bsdf, ComplexIor, Conductor, Ggx, MicrofacetBsdf, ShadingFrame, Technique};
use validation::{Stats, family_z};

/// Every BSDF call is a pure function of its arguments and the tracer's generators are
/// seeded per row: one thread and three threads render the same bits (a stochastic BSDF that
/// drew from a shared or thread-local generator would not).
#[test]
fn renders_are_identical_for_any_thread_count() {
    let (scene, camera) = showcase_scene(Lighting::Studio);
    let (width, height, spp) = (48u32, 12u32, 2u32);
    let stats = RenderStats::default();
    let one = render(&scene, &camera, (width, height), spp, 11, 1, &stats);
    let three = render(&scene, &camera, (width, height), spp, 11, 3, &stats);
    assert!(one.0.iter().flatten().any(|&c| c > 0.0), "a black image proves nothing");
    let bits = |img: &[[f32; 3]]| img.iter().flatten().map(|c| c.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&one.0), bits(&three.0), "1 and 3 threads render different images");
    assert_eq!(one.1, three.1);
}

#[test]
fn white_furnace_spheres_vanish() {
    let (scene, camera) = showcase_scene(Lighting::Furnace);
    let (width, height, spp) = (96u32, 40u32, 32u32);
    let stats = RenderStats::default();
    let (image, errors) = render(&scene, &camera, (width, height), spp, 7, 2, &stats);
    assert_eq!(stats.rejected.load(std::sync::atomic::Ordering::Relaxed), 0, "non-finite contributions");
    assert!(image.iter().flatten().all(|c| c.is_finite()));
    let z = family_z(0.01, scene.spheres.len());
    for (i, sphere) in scene.spheres.iter().enumerate() {
        let (mut sum, mut var, mut n) = (0.0f64, 0.0f64, 0usize);
        for y in 0..height {
            for x in 0..width {
                let d = camera.ray(x as f32 + 0.5, y as f32 + 0.5, width, height);
                let hits_this = match scene.intersect(camera.origin, d) {
                    Some(Hit::Surface { material, .. }) => material == sphere.material,
                    _ => false,
                };
                if hits_this {
                    let k = (y * width + x) as usize;
                    sum += image[k].iter().map(|&c| f64::from(c)).sum::<f64>() / 3.0;
                    var += f64::from(errors[k]).powi(2);
                    n += 1;
                }
            }
        }
        assert!(n >= 20, "sphere {i} covers only {n} pixels");
        let (mean, se) = (sum / n as f64, var.sqrt() / n as f64);
        assert!(
            se < 0.02,
            "sphere {i} ({}): SE {se:.4} too large to mean something",
            tracer::SHOWCASE_LABELS[i]
        );
        assert!(
            (mean - 1.0).abs() <= z * se,
            "sphere {i} ({}) does not vanish in the furnace: mean {mean:.4} over {n} pixels, SE {se:.4}, z {z:.2}",
            tracer::SHOWCASE_LABELS[i]
        );
    }
}

/// A gold single-scattering sphere alone under a sky: a pixel's radiance is
/// ∫ f(ωo, ωi) |cos θi| L_sky(ωi) dωi over the hemisphere of the normal at the hit point.
#[test]
fn single_scattering_pixels_match_a_numerical_integral() {
    let bsdf = MicrofacetBsdf::new(Ggx::isotropic(0.35).unwrap(), Conductor::new(ComplexIor::GOLD))
        .unwrap()
        .with_technique(Technique::SingleScattering);
    let sky = Environment::Sky {
        zenith: Vec3::new(0.2, 0.4, 1.0),
        horizon: Vec3::new(1.0, 0.8, 0.5),
        ground: Vec3::ZERO,
    };
    let scene = Scene {
        spheres: vec![Sphere { center: Vec3::ZERO, radius: 1.0, material: 0 }],
        materials: vec![Box::new(bsdf)],
        light: None,
        environment: sky,
    };
    let camera = Camera::look_at(Vec3::new(0.0, 0.5, 4.0), Vec3::ZERO, 40.0);
    let (width, height) = (64u32, 64u32);
    let pixels = [(32u32, 32u32), (20, 30), (44, 40), (32, 16), (25, 47)];
    let z = family_z(0.01, pixels.len() * 3);
    let mut rng = validation::rng(2024);
    let stats = RenderStats::default();
    for (px, py) in pixels {
        let d = camera.ray(px as f32 + 0.5, py as f32 + 0.5, width, height);
        let Some(Hit::Surface { normal, .. }) = scene.intersect(camera.origin, d) else {
            panic!("pixel ({px}, {py}) misses the sphere");
        };
        let frame = ShadingFrame::from_normal(normal).unwrap();
        let wo = frame.to_local(-d).normalize();
        // reference: adaptive quadrature over the hemisphere of the normal
        let mut reference = [0.0f64; 3];
        for (c, r) in reference.iter_mut().enumerate() {
            let mut integrand = |wi: Vec3| {
                let f = bsdf.eval(wo, wi).f;
                f64::from(f[c]) * f64::from(wi.z) * f64::from(sky.radiance(frame.to_world(wi))[c])
            };
            *r = validation::quadrature::integrate_sphere(
                &mut integrand,
                16,
                32,
                validation::quadrature::Domain::UpperHemisphere,
                1e-6,
                8,
            );
        }
        // the path tracer at the pixel centre
        let mut channels = [Stats::default(); 3];
        for path in 0..200_000 {
            let l = tracer::radiance(&scene, camera.origin, d, 8, path, &mut rng, &stats);
            for (c, s) in channels.iter_mut().enumerate() {
                s.push(f64::from(l[c]));
            }
        }
        for c in 0..3 {
            validation::assert_mean(
                &format!("pixel ({px}, {py}) channel {c}"),
                &channels[c],
                reference[c],
                z,
                0.01 * reference[c].max(0.05),
                1e-4,
            );
        }
    }
}
