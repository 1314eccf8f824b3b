//! A renderer's first use of `microsurface`: a minimal path tracer of one sphere under a sun
//! and a sky, with three materials built at each hit from "textured" parameters.
//!
//! It shows, in order: the per-hit BSDF (roughness from a texture, `MicrofacetBsdf::new` is a
//! few copies), the shading frame of the normal and a tangent (the roughness along the
//! tangent), light sampling with MIS through `eval_with_pdf`, BSDF sampling with the tracer's
//! own uniforms, and Russian roulette on throughput × η² (`BsdfSample::eta`).
//!
//! Run with `cargo run --release --example renderer`.

use microsurface::glam::{Vec2, Vec3};
use microsurface::rand::{RngExt, SeedableRng};
use microsurface::{Bsdf, ComplexIor, Conductor, Dielectric, Diffuse, Ggx, MicrofacetBsdf, ShadingFrame};

type Rng = rand_pcg::Pcg64Mcg;

const SUN_DIR: Vec3 = Vec3::new(0.48, 0.6, 0.64);
/// cos of the sun's angular radius (about 2.6°).
const SUN_COS: f32 = 0.999;
const SUN_RADIANCE: f32 = 2000.0;
const SKY_RADIANCE: f32 = 0.5;

/// What the sky and the sun send along `d`.
fn environment(d: Vec3) -> Vec3 {
    let sun = if d.dot(SUN_DIR) >= SUN_COS { SUN_RADIANCE } else { 0.0 };
    Vec3::splat(SKY_RADIANCE + sun)
}

/// The density of the sun's uniform cone sampling, for MIS.
fn sun_pdf(d: Vec3) -> f32 {
    if d.dot(SUN_DIR) >= SUN_COS { 1.0 / (std::f32::consts::TAU * (1.0 - SUN_COS)) } else { 0.0 }
}

/// A direction in the sun's cone, uniform in solid angle.
fn sample_sun(u: Vec2) -> Vec3 {
    let cos = 1.0 - u.x * (1.0 - SUN_COS);
    let sin = (1.0 - cos * cos).max(0.0).sqrt();
    let (s, c) = (std::f32::consts::TAU * u.y).sin_cos();
    ShadingFrame::from_normal(SUN_DIR).expect("a unit axis").to_world(Vec3::new(sin * c, sin * s, cos))
}

/// The power heuristic.
fn mis(a: f32, b: f32) -> f32 {
    a * a / (a * a + b * b)
}

/// The material at point `p` of the unit sphere: its roughness is a texture lookup.
fn material_at(kind: usize, p: Vec3) -> Result<Box<dyn Bsdf>, microsurface::Error> {
    let stripes = 0.5 + 0.5 * (12.0 * p.y).sin();
    Ok(match kind {
        // brushed gold: rougher across the tangent (αy) than along it (αx)
        0 => Box::new(MicrofacetBsdf::new(
            Ggx::new(0.05 + 0.1 * stripes, 0.4)?,
            Conductor::new(ComplexIor::GOLD),
        )?),
        1 => Box::new(MicrofacetBsdf::new(Ggx::isotropic(0.05 + 0.3 * stripes)?, Dielectric::new(1.5)?)?),
        _ => Box::new(MicrofacetBsdf::new(Ggx::isotropic(0.5)?, Diffuse::new(Vec3::new(0.8, 0.3, 0.2))?)?),
    })
}

/// The distance along the ray (o, d) to the unit sphere at the origin, if it is hit.
fn hit_sphere(o: Vec3, d: Vec3) -> Option<f32> {
    let (b, c) = (o.dot(d), o.length_squared() - 1.0);
    let disc = b * b - c;
    let s = disc.max(0.0).sqrt();
    [-b - s, -b + s].into_iter().find(|&t| disc >= 0.0 && t > 1e-4)
}

/// One path's radiance from the camera ray (o, d); `key` decorrelates the stochastic BSDFs.
fn radiance(kind: usize, mut o: Vec3, mut d: Vec3, key: u64, rng: &mut Rng) -> Vec3 {
    let (mut sum, mut throughput, mut eta_scale) = (Vec3::ZERO, Vec3::ONE, 1.0f32);
    let mut prev_pdf: Option<f32> = None; // None: camera ray or specular bounce
    for depth in 0..32u64 {
        let Some(t) = hit_sphere(o, d) else {
            // the environment, MIS-weighted against the light sampling of the previous hit
            let w = prev_pdf.map_or(1.0, |p| mis(p, sun_pdf(d)));
            return sum + throughput * environment(d) * w;
        };
        let p = o + t * d;
        // the shading frame: the normal and a tangent along the sphere's parallels
        let frame = ShadingFrame::from_normal_tangent(p, Vec3::Y.cross(p)).expect("a non-zero normal");
        let bsdf = material_at(kind, p).expect("valid texture values");
        let wo = frame.to_local(-d);
        let key = key.wrapping_mul(64).wrapping_add(depth);

        // light sampling: f and the BSDF's own density for the MIS weight (skip Dirac lobes)
        if bsdf.flags().has_non_specular() {
            let l = sample_sun(Vec2::new(rng.random(), rng.random()));
            let wi = frame.to_local(l);
            let (f, pdf_bsdf) = bsdf.eval_with_pdf_keyed(wo, wi, key);
            let outside = p.dot(l) > 0.0; // a convex sphere: no other occluder
            if f.f != Vec3::ZERO && outside {
                let p_sun = sun_pdf(l);
                sum += throughput * f.f * wi.z.abs() * environment(l) * (mis(p_sun, pdf_bsdf) / p_sun);
            }
        }

        // BSDF sampling with the tracer's own uniforms
        let Some(s) = bsdf.sample_keyed(wo, rng.random(), Vec2::new(rng.random(), rng.random()), key) else {
            break;
        };
        throughput *= s.weight;
        prev_pdf = (!s.flags.specular).then_some(s.pdf);
        if s.flags.transmission {
            eta_scale *= s.eta * s.eta; // the energy behind the radiance (pbrt's etaScale)
        }
        o = p;
        d = frame.to_world(s.wi);

        // Russian roulette on the energy: throughput × the product of η²
        if depth >= 3 {
            let q = (throughput.max_element() * eta_scale).min(0.95);
            if rng.random::<f32>() >= q {
                break;
            }
            throughput /= q;
        }
    }
    sum
}

fn main() {
    let camera = Vec3::new(0.0, 0.0, 4.0);
    let (width, spp) = (24u32, 16u32);
    let mut rng = Rng::seed_from_u64(1);
    for (kind, name) in ["brushed gold", "rough glass", "diffuse facets"].iter().enumerate() {
        let mut total = Vec3::ZERO;
        for y in 0..width {
            for x in 0..width {
                for i in 0..spp {
                    let jitter = Vec2::new(rng.random(), rng.random());
                    let film = (Vec2::new(x as f32, y as f32) + jitter) / width as f32 * 2.0 - 1.0;
                    let d = Vec3::new(0.35 * film.x, -0.35 * film.y, -1.0).normalize();
                    let key = (u64::from(y * width + x) << 16) | u64::from(i);
                    total += radiance(kind, camera, d, key, &mut rng);
                }
            }
        }
        let mean = total / (width * width * spp) as f32;
        println!("{name:>15}: mean pixel radiance ({:.3}, {:.3}, {:.3})", mean.x, mean.y, mean.z);
    }
}
