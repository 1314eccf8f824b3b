//! A displacement-mapped plane receding to the horizon, shaded three ways: supersampled fine
//! texels (the ground truth LEADR approximates), LEADR (trilinear moments), and the naive
//! normal-map MIP with the base roughness; with mirror, glass or diffuse facets.

use glam::{DVec2, DVec3, Vec2};
use microsurface::leadr::{LeadrLobe, LeadrMap};
use microsurface::{Bsdf, Dielectric, Diffuse};
use validation::leadr::surface::NormalMip;
use validation::leadr::validate::{f_cos, texel_lobe};

/// The material of the facets.
#[derive(Debug, Clone, Copy)]
pub enum Facets {
    /// A perfect mirror (F = 1).
    Mirror,
    /// Glass (its reflection of the light; the transmitted light leaves below the plane).
    Glass(Dielectric),
    /// Lambertian facets (the stochastic single scattering, averaged over `DIFFUSE_KEYS`
    /// estimates per shading point).
    Diffuse(Diffuse),
}

/// Estimates averaged per shading point of diffuse facets.
const DIFFUSE_KEYS: u64 = 8;

/// The scene.
pub struct Scene<'a> {
    /// The LEADR pyramid of the map.
    pub leadr: &'a LeadrMap,
    /// The naive pyramid of normals.
    pub normals: &'a NormalMip,
    /// Base roughness.
    pub alpha: f64,
    /// Texels along a side of the map.
    pub size: usize,
    /// World size of one tile of the map.
    pub tile: f64,
    /// Unit direction towards the (directional) light.
    pub light: DVec3,
    /// Panel size in pixels.
    pub width: usize,
    /// Panel height in pixels.
    pub height: usize,
    /// Largest supersampling grid per axis.
    pub max_samples: usize,
    /// The facets' material.
    pub facets: Facets,
}

/// One shaded panel set.
pub struct Panels {
    /// Supersampled reference, LEADR, naive (linear radiance per pixel, row-major).
    pub images: [Vec<f64>; 3],
    /// The MIP level of each pixel (NaN for sky).
    pub lod: Vec<f64>,
}

/// Camera: at height 1 above the origin, looking along +y, the horizon at 15 % from the top.
const CAMERA_HEIGHT: f64 = 1.0;
/// Vertical field of view (radians).
const FOV: f64 = 0.6;
/// The horizon's row as a fraction of the panel height.
const HORIZON_ROW: f64 = 0.15;

impl Scene<'_> {
    /// The ray through the panel point (px, py) (pixel units, y down).
    fn ray(&self, px: f64, py: f64) -> DVec3 {
        let (w, h) = (self.width as f64, self.height as f64);
        let focal = 0.5 * h / (0.5 * FOV).tan();
        // pitch so that the horizon (direction +y) projects to HORIZON_ROW
        let pitch = ((0.5 - HORIZON_ROW) * h / focal).atan();
        let (x, y) = (px - 0.5 * w, 0.5 * h - py);
        let forward = DVec3::new(0.0, pitch.cos(), -pitch.sin());
        let up = DVec3::new(0.0, pitch.sin(), pitch.cos());
        (forward * focal + DVec3::X * x + up * y).normalize()
    }

    /// The plane point hit along `d` (None above the horizon).
    fn hit(&self, d: DVec3) -> Option<DVec2> {
        (d.z < -1e-9).then(|| DVec2::new(d.x, d.y) * (CAMERA_HEIGHT / -d.z))
    }

    /// Radiance from the BRDF of `lobe` (light from `light`, seen from −d): f cos θl.
    fn shade(&self, lobe: &LeadrLobe, d: DVec3) -> f64 {
        let view = -d;
        if view.z <= 0.0 {
            return 0.0;
        }
        match self.facets {
            Facets::Mirror => f_cos(lobe, self.light, view) / view.z * self.light.z,
            Facets::Glass(glass) => self.shade_bsdf(&lobe.bsdf(glass).expect("a finite lobe"), view, 1),
            Facets::Diffuse(diffuse) => {
                self.shade_bsdf(&lobe.bsdf(diffuse).expect("a finite lobe"), view, DIFFUSE_KEYS)
            }
        }
    }

    /// f(view, light) cos θl of a renderer BSDF, averaged over `keys` keyed estimates (exact
    /// BSDFs ignore the key).
    fn shade_bsdf(&self, bsdf: &impl Bsdf, view: DVec3, keys: u64) -> f64 {
        let (wo, wi) = (view.as_vec3().normalize(), self.light.as_vec3().normalize());
        let sum: f64 = (0..keys).map(|k| f64::from(bsdf.eval_keyed(wo, wi, k).f.x)).sum();
        sum / keys as f64 * self.light.z
    }

    /// Texture coordinates of a plane point.
    fn uv(&self, p: DVec2) -> Vec2 {
        (p / self.tile).fract_gl().as_vec2()
    }

    /// Renders the three panels.
    pub fn render(&self) -> Panels {
        let n = self.width * self.height;
        let mut images = [vec![0.0; n], vec![0.0; n], vec![0.0; n]];
        let mut lod_image = vec![f64::NAN; n];
        let texel = self.tile / self.size as f64;
        let top = (self.leadr.level_count() - 1) as f64;
        for py in 0..self.height {
            for px in 0..self.width {
                let (cx, cy) = (px as f64 + 0.5, py as f64 + 0.5);
                let d = self.ray(cx, cy);
                let (Some(p), Some(px1), Some(py1)) =
                    (self.hit(d), self.hit(self.ray(cx + 1.0, cy)), self.hit(self.ray(cx, cy + 1.0)))
                else {
                    continue;
                };
                // isotropic footprint: the longer pixel axis, in texels (as a GPU's MIP choice)
                let footprint = (px1 - p).length().max((py1 - p).length()) / texel;
                // trilinear MIP level log₂(footprint); a footprint below one texel is magnified
                let lod = footprint.max(1.0).log2().min(top);
                let i = py * self.width + px;
                lod_image[i] = lod;
                let uv = self.uv(p);
                let (leadr, naive) = if footprint < 1.0 {
                    // magnified: the pixel sees one fine texel, which both filters return as is
                    let t = (p / texel).floor();
                    let fine = self.leadr.lobe(0, t.x as isize, t.y as isize);
                    (fine, fine)
                } else {
                    let moments = self.leadr.trilinear(uv, lod as f32);
                    let naive = texel_lobe(self.normals.trilinear_slope(uv, lod as f32), self.alpha as f32);
                    (LeadrLobe::from_moments(&moments), naive)
                };
                images[1][i] = self.shade(&leadr, d);
                images[2][i] = self.shade(&naive, d);
                // supersampled: a stratified grid over the pixel, ≥ 2 samples per texel per axis
                // up to `max_samples`, each shading the fine texel it lands on
                let k = ((2.0 * footprint).ceil() as usize).clamp(2, self.max_samples);
                let mut sum = 0.0;
                for sy in 0..k {
                    for sx in 0..k {
                        let (ox, oy) =
                            ((sx as f64 + 0.5) / k as f64 - 0.5, (sy as f64 + 0.5) / k as f64 - 0.5);
                        let ds = self.ray(cx + ox, cy + oy);
                        let Some(q) = self.hit(ds) else { continue };
                        let t = (q / texel).floor();
                        let fine = self.leadr.lobe(0, t.x as isize, t.y as isize);
                        sum += self.shade(&fine, ds);
                    }
                }
                images[0][i] = sum / (k * k) as f64;
            }
        }
        Panels { images, lod: lod_image }
    }
}
