//! A small CPU path tracer over the `microsurface` BSDFs: spheres, one spherical area light,
//! an environment; next-event estimation, Russian roulette and multiple importance sampling
//! (the classic unidirectional path tracer with MIS). Used by
//! `lab/src/bin/path_tracer/` and `lab/tests/path_tracer.rs`.
//!
//! The materials are a `Vec<Box<dyn Bsdf>>`: no enum, no dispatch macro. The BSDF samples
//! are driven by the tracer's own uniforms; the stochastic BSDFs get the path's index as
//! their key, so a render is a pure function of its seed (identical for any thread count).

use glam::{Vec2, Vec3};
use microsurface::research::{Estimator, ScatteringOrder, Shadowing};
use microsurface::{
    Bsdf, ClassicBrdf, ClassicMasking, ClassicNdf, ComplexIor, Conductor, Dielectric, Diffuse, Ggx,
    MicrofacetBsdf, ShadingFrame, Technique,
};
use rand::Rng;
use rand::RngExt;
use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};

/// Offset of secondary ray origins along the normal.
const RAY_EPSILON: f32 = 1e-4;
/// Russian roulette from this path depth on.
const ROULETTE_DEPTH: u32 = 3;
/// Highest survival probability of the roulette.
const ROULETTE_MAX_SURVIVAL: f32 = 0.95;

/// A material of the scene: any BSDF of the crate, behind the object-safe trait.
pub type Material = Box<dyn Bsdf>;

#[derive(Debug, Clone, Copy)]
pub struct Sphere {
    pub center: Vec3,
    pub radius: f32,
    pub material: usize,
}

#[derive(Debug, Clone, Copy)]
pub struct Light {
    pub center: Vec3,
    pub radius: f32,
    pub radiance: Vec3,
}

#[derive(Debug, Clone, Copy)]
pub enum Environment {
    Constant(Vec3),
    /// Linear in the direction's y: horizon at y = 0, zenith at y = 1 (and the ground colour
    /// below).
    Sky {
        zenith: Vec3,
        horizon: Vec3,
        ground: Vec3,
    },
}

impl Environment {
    pub fn radiance(&self, d: Vec3) -> Vec3 {
        match *self {
            Environment::Constant(c) => c,
            Environment::Sky { zenith, horizon, ground } => {
                if d.y >= 0.0 {
                    horizon.lerp(zenith, d.y)
                } else {
                    ground
                }
            }
        }
    }
}

pub struct Scene {
    pub spheres: Vec<Sphere>,
    pub materials: Vec<Material>,
    pub light: Option<Light>,
    pub environment: Environment,
}

#[derive(Debug, Clone, Copy)]
pub struct Camera {
    pub origin: Vec3,
    pub forward: Vec3,
    pub right: Vec3,
    pub up: Vec3,
    pub tan_half_fov: f32,
}

impl Camera {
    pub fn look_at(origin: Vec3, target: Vec3, fov_degrees: f32) -> Self {
        let forward = (target - origin).normalize();
        let right = forward.cross(Vec3::Y).normalize();
        let up = right.cross(forward);
        Self { origin, forward, right, up, tan_half_fov: (0.5 * fov_degrees.to_radians()).tan() }
    }

    /// The ray through image position (x, y) in pixels (y down).
    pub fn ray(&self, x: f32, y: f32, width: u32, height: u32) -> Vec3 {
        let aspect = width as f32 / height as f32;
        let sx = (2.0 * x / width as f32 - 1.0) * self.tan_half_fov * aspect;
        let sy = (1.0 - 2.0 * y / height as f32) * self.tan_half_fov;
        (self.forward + sx * self.right + sy * self.up).normalize()
    }
}

pub enum Hit {
    Surface { t: f32, point: Vec3, normal: Vec3, material: usize },
    Light { t: f32 },
}

fn intersect_sphere(center: Vec3, radius: f32, o: Vec3, d: Vec3) -> Option<f32> {
    let oc = o - center;
    let b = oc.dot(d);
    let c = oc.length_squared() - radius * radius;
    let disc = b * b - c;
    if disc < 0.0 {
        return None;
    }
    let s = disc.sqrt();
    [-b - s, -b + s].into_iter().find(|&t| t > RAY_EPSILON)
}

impl Scene {
    pub fn intersect(&self, o: Vec3, d: Vec3) -> Option<Hit> {
        let mut best: Option<Hit> = None;
        let mut best_t = f32::INFINITY;
        for s in &self.spheres {
            if let Some(t) = intersect_sphere(s.center, s.radius, o, d).filter(|&t| t < best_t) {
                best_t = t;
                let point = o + t * d;
                best = Some(Hit::Surface {
                    t,
                    point,
                    normal: (point - s.center) / s.radius,
                    material: s.material,
                });
            }
        }
        if let Some(t) = self
            .light
            .as_ref()
            .and_then(|l| intersect_sphere(l.center, l.radius, o, d))
            .filter(|&t| t < best_t)
        {
            best = Some(Hit::Light { t });
        }
        best
    }
}

/// Counters shared by the render threads.
#[derive(Default)]
pub struct RenderStats {
    /// Contributions dropped because they were not finite (should stay 0).
    pub rejected: AtomicU64,
    /// Rows finished (for the progress bar).
    pub rows_done: AtomicUsize,
}

/// Uniform direction in the cone towards the light sphere, and its solid-angle density.
fn sample_light_cone(light: &Light, p: Vec3, rng: &mut impl Rng) -> Option<(Vec3, f32)> {
    let to_center = light.center - p;
    let dist2 = to_center.length_squared();
    let sin2_max = light.radius * light.radius / dist2;
    if sin2_max >= 1.0 {
        return None;
    }
    let cos_max = (1.0 - sin2_max).sqrt();
    let u1: f32 = rng.random();
    let u2: f32 = rng.random();
    let cos_t = 1.0 - u1 * (1.0 - cos_max);
    let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
    let frame = ShadingFrame::from_normal(to_center)?;
    let (s, c) = (std::f32::consts::TAU * u2).sin_cos();
    let d = frame.to_world(Vec3::new(sin_t * c, sin_t * s, cos_t));
    Some((d, 1.0 / (std::f32::consts::TAU * (1.0 - cos_max))))
}

/// The density of [`sample_light_cone`] for direction d (0 outside the cone).
fn light_cone_pdf(light: &Light, p: Vec3, d: Vec3) -> f32 {
    let to_center = light.center - p;
    let dist2 = to_center.length_squared();
    let sin2_max = light.radius * light.radius / dist2;
    if sin2_max >= 1.0 {
        return 0.0;
    }
    let cos_max = (1.0 - sin2_max).sqrt();
    if d.dot(to_center) / dist2.sqrt() < cos_max {
        return 0.0;
    }
    1.0 / (std::f32::consts::TAU * (1.0 - cos_max))
}

/// Power heuristic (β = 2) weight of a strategy with density `a` against one with `b`.
fn power_heuristic(a: f32, b: f32) -> f32 {
    let (a2, b2) = (a * a, b * b);
    if a2 + b2 > 0.0 { a2 / (a2 + b2) } else { 0.0 }
}

fn add_finite(acc: &mut Vec3, c: Vec3, stats: &RenderStats) {
    if c.is_finite() {
        *acc += c;
    } else {
        stats.rejected.fetch_add(1, Ordering::Relaxed);
    }
}

/// Radiance along the ray (o, d): path tracing with next-event estimation towards the light,
/// BSDF sampling, MIS (power heuristic) between the two, and Russian roulette on the
/// throughput with the η² of the refractions taken out (pbrt's `etaScale`). `key` identifies
/// the path (pixel and sample); the BSDFs' stochastic estimates mix it with the depth into
/// their seeds.
pub fn radiance(
    scene: &Scene,
    mut o: Vec3,
    mut d: Vec3,
    max_depth: u32,
    key: u64,
    rng: &mut impl Rng,
    stats: &RenderStats,
) -> Vec3 {
    let mut sum = Vec3::ZERO;
    let mut throughput = Vec3::ONE;
    // the product of the η² of the refractions: radiance is scaled by 1/η² entering glass
    let mut eta_scale = 1.0f32;
    let mut bsdf_pdf_prev: Option<f32> = None; // None: camera or specular vertex, no MIS
    for depth in 0..max_depth {
        let Some(hit) = scene.intersect(o, d) else {
            add_finite(&mut sum, throughput * scene.environment.radiance(d), stats);
            break;
        };
        let (point, normal, material) = match hit {
            Hit::Light { .. } => {
                let light = scene.light.as_ref().expect("a light hit needs a light");
                let w = match bsdf_pdf_prev {
                    None => 1.0,
                    Some(p_bsdf) => power_heuristic(p_bsdf, light_cone_pdf(light, o, d)),
                };
                add_finite(&mut sum, throughput * light.radiance * w, stats);
                break;
            }
            Hit::Surface { point, normal, material, .. } => (point, normal, material),
        };
        let Some(frame) = ShadingFrame::from_normal(normal) else { break };
        let bsdf: &dyn Bsdf = scene.materials[material].as_ref();
        let wo = frame.to_local(-d).normalize();
        let vertex_key = key.wrapping_mul(64).wrapping_add(u64::from(depth));

        // next-event estimation (useless on a Dirac lobe)
        if let Some(light) = scene.light.as_ref().filter(|_| bsdf.flags().has_non_specular()) {
            let origin = point + normal * RAY_EPSILON * normal.dot(-d).signum();
            if let Some((wi_world, p_light)) = sample_light_cone(light, origin, rng) {
                let wi = frame.to_local(wi_world).normalize();
                let (f, p_bsdf) = bsdf.eval_with_pdf_keyed(wo, wi, vertex_key);
                if f.f != Vec3::ZERO {
                    let shadow_origin = point + normal * RAY_EPSILON * wi.z.signum();
                    if matches!(scene.intersect(shadow_origin, wi_world), Some(Hit::Light { .. })) {
                        let w = power_heuristic(p_light, p_bsdf);
                        add_finite(
                            &mut sum,
                            throughput * f.f * wi.z.abs() * light.radiance * (w / p_light),
                            stats,
                        );
                    }
                }
            }
        }

        // BSDF sampling, driven by the tracer's uniforms
        let (uc, u) = (rng.random::<f32>(), Vec2::new(rng.random(), rng.random()));
        let Some(s) = bsdf.sample_keyed(wo, uc, u, vertex_key) else { break };
        throughput *= s.weight;
        if !throughput.is_finite() {
            stats.rejected.fetch_add(1, Ordering::Relaxed);
            break;
        }
        if s.flags.transmission {
            eta_scale *= s.eta * s.eta;
        }
        bsdf_pdf_prev = (!s.flags.specular).then_some(s.pdf);
        d = frame.to_world(s.wi).normalize();
        o = point + normal * RAY_EPSILON * s.wi.z.signum();
        if depth >= ROULETTE_DEPTH {
            let q = (throughput.max_element() * eta_scale).min(ROULETTE_MAX_SURVIVAL);
            if rng.random::<f32>() >= q {
                break;
            }
            throughput /= q;
        }
    }
    sum
}

/// Renders `spp` samples per pixel on `threads` threads (rows interleaved, one seeded
/// generator per row); returns linear RGB and, per pixel, the standard error of its mean
/// (luminance-free: the mean over channels).
pub fn render(
    scene: &Scene,
    camera: &Camera,
    (width, height): (u32, u32),
    spp: u32,
    seed: u64,
    threads: usize,
    stats: &RenderStats,
) -> (Vec<[f32; 3]>, Vec<f32>) {
    let mut image = vec![[0.0f32; 3]; (width * height) as usize];
    let mut errors = vec![0.0f32; (width * height) as usize];
    let rows: Vec<(usize, Vec<[f32; 3]>, Vec<f32>)> = std::thread::scope(|scope| {
        let handles: Vec<_> = (0..threads.max(1))
            .map(|t| {
                scope.spawn(move || {
                    let mut out = Vec::new();
                    for y in (t..height as usize).step_by(threads.max(1)) {
                        let mut rng = <rand_pcg::Pcg64Mcg as rand::SeedableRng>::seed_from_u64(
                            seed ^ (y as u64 * 0x9E37_79B9),
                        );
                        let mut row = Vec::with_capacity(width as usize);
                        let mut row_err = Vec::with_capacity(width as usize);
                        for x in 0..width {
                            let (mut s, mut s2) = (glam::DVec3::ZERO, 0.0f64);
                            for i in 0..spp {
                                let jx: f32 = rng.random();
                                let jy: f32 = rng.random();
                                let d = camera.ray(x as f32 + jx, y as f32 + jy, width, height);
                                let path = (u64::from(y as u32) * u64::from(width) + u64::from(x))
                                    * u64::from(spp)
                                    + u64::from(i);
                                let l =
                                    radiance(scene, camera.origin, d, 64, path, &mut rng, stats).as_dvec3();
                                s += l;
                                let m = l.element_sum() / 3.0;
                                s2 += m * m;
                            }
                            let mean = s / f64::from(spp);
                            let m = mean.element_sum() / 3.0;
                            let var = (s2 / f64::from(spp) - m * m).max(0.0) * f64::from(spp)
                                / f64::from(spp.max(2) - 1);
                            row.push(mean.as_vec3().to_array());
                            row_err.push((var / f64::from(spp)).sqrt() as f32);
                        }
                        stats.rows_done.fetch_add(1, Ordering::Relaxed);
                        out.push((y, row, row_err));
                    }
                    out
                })
            })
            .collect();
        handles.into_iter().flat_map(|h| h.join().expect("render thread panicked")).collect()
    });
    for (y, row, row_err) in rows {
        let start = y * width as usize;
        image[start..start + width as usize].copy_from_slice(&row);
        errors[start..start + width as usize].copy_from_slice(&row_err);
    }
    (image, errors)
}

/// GGX roughness of the showcase spheres.
const SHOWCASE_ALPHA: f32 = 0.5;

fn conductor(technique: Technique, ior: Option<ComplexIor>) -> Material {
    let c = ior.map_or_else(Conductor::perfect, Conductor::new);
    let alpha = Ggx::isotropic(SHOWCASE_ALPHA).expect("valid α");
    Box::new(MicrofacetBsdf::new(alpha, c).expect("α ≤ MAX_WALK_ALPHA").with_technique(technique))
}

fn dielectric(technique: Technique) -> Material {
    let d = Dielectric::new(1.5).expect("valid η");
    let alpha = Ggx::isotropic(SHOWCASE_ALPHA).expect("valid α");
    Box::new(MicrofacetBsdf::new(alpha, d).expect("α ≤ MAX_WALK_ALPHA").with_technique(technique))
}

fn diffuse(technique: Technique, albedo: Vec3) -> Material {
    let d = Diffuse::new(albedo).expect("valid albedo");
    let alpha = Ggx::isotropic(1.0).expect("valid α");
    Box::new(MicrofacetBsdf::new(alpha, d).expect("α ≤ MAX_WALK_ALPHA").with_technique(technique))
}

fn classic(kd: Vec3, ks: Vec3, alpha: f32) -> Material {
    Box::new(
        ClassicBrdf::new(kd, ks, ClassicNdf::Ggx(alpha), ClassicMasking::Exact).expect("valid parameters"),
    )
}

pub const BDPT: Technique =
    Technique::PositionFree { estimator: Estimator::Bdpt, shadowing: Shadowing::Correlated };
pub const PT: Technique =
    Technique::PositionFree { estimator: Estimator::Pt, shadowing: Shadowing::Correlated };

/// The labels of the showcase spheres, left to right.
pub const SHOWCASE_LABELS: [&str; 8] = [
    "gold, single scattering",
    "gold, random walk",
    "gold, position-free PT",
    "gold, position-free BDPT",
    "glass, random walk",
    "glass, position-free BDPT",
    "diffuse, random walk",
    "classic GGX + Lambert",
];

/// The x coordinate of showcase sphere i.
pub fn sphere_x(i: usize) -> f32 {
    (i as f32 - 3.5) * 1.15
}

/// The lighting of a scene.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Lighting {
    /// A sky, a ground colour below the horizon and a spherical area light.
    Studio,
    /// The white furnace: radiance 1 from every direction; conductors get F = 1.
    Furnace,
}

/// Spheres in a row on a diffuse floor, lit by a spherical light and a sky. In the
/// [`Lighting::Furnace`], the floor, the light and the classic sphere go, the environment is a
/// constant 1 and every material is non-absorptive (and multiple-scattering): every sphere must
/// vanish.
pub fn showcase_scene(lighting: Lighting) -> (Scene, Camera) {
    let furnace = lighting == Lighting::Furnace;
    let gold = (!furnace).then_some(ComplexIor::GOLD);
    let albedo = if furnace { Vec3::ONE } else { Vec3::new(0.8, 0.35, 0.2) };
    let mut materials = vec![
        conductor(if furnace { Technique::RandomWalk } else { Technique::SingleScattering }, gold),
        conductor(Technique::RandomWalk, gold),
        conductor(PT, gold),
        conductor(BDPT, gold),
        dielectric(Technique::RandomWalk),
        dielectric(BDPT),
        diffuse(Technique::RandomWalk, albedo),
        classic(Vec3::new(0.1, 0.3, 0.6), Vec3::splat(0.04), 0.2),
    ];
    let count = if furnace { 7 } else { 8 };
    let mut spheres: Vec<Sphere> = (0..count)
        .map(|i| Sphere { center: Vec3::new(sphere_x(i), 0.5, 0.0), radius: 0.5, material: i })
        .collect();
    let (light, environment) = if furnace {
        (None, Environment::Constant(Vec3::ONE))
    } else {
        materials.push(classic(Vec3::splat(0.5), Vec3::ZERO, 1.0));
        spheres.push(Sphere {
            center: Vec3::new(0.0, -1000.0, 0.0),
            radius: 1000.0,
            material: materials.len() - 1,
        });
        (
            Some(Light { center: Vec3::new(-2.0, 6.0, 4.0), radius: 1.0, radiance: Vec3::splat(12.0) }),
            Environment::Sky {
                zenith: Vec3::new(0.25, 0.35, 0.6),
                horizon: Vec3::new(0.7, 0.75, 0.8),
                ground: Vec3::splat(0.2),
            },
        )
    };
    let camera = Camera::look_at(Vec3::new(0.0, 2.2, 8.5), Vec3::new(0.0, 0.45, 0.0), 38.0);
    (Scene { spheres, materials, light, environment }, camera)
}

/// Keeps the unused-order import meaningful for the tests.
pub const ALL_ORDERS: ScatteringOrder = ScatteringOrder::All;
