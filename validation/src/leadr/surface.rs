//! The procedural displacement map of the LEADR validation, and the naive alternative to
//! LEADR (a MIP pyramid of averaged normals). Shared by `lab/src/bin/leadr` and `tests/leadr.rs`.

use glam::{DVec2, DVec3, Vec2, Vec3};
use microsurface::leadr::HeightMap;
use rand::{RngExt, SeedableRng};
use std::f64::consts::TAU;

/// Sines of the displacement.
const SINES: usize = 64;
/// Heights of the sines ∝ |k|^−HEIGHT_SPECTRUM.
const HEIGHT_SPECTRUM: f64 = 1.0;

/// A periodic displacement map of `size × size` texels over the unit square (texel side
/// 1/size): a sum of `SINES` plane waves with integer wave vectors (so that it tiles), of
/// wavelengths from the whole map down to 4 texels (log-uniform), heights ∝ |k|^−1
/// (`HEIGHT_SPECTRUM`: each octave adds about the same slope variance, and coarse texels hold
/// a wide, near-Gaussian spread of slopes) and random phases; scaled so that the RMS of the
/// central-difference slopes is `rms_slope` per axis. Deterministic for a `seed`.
pub fn procedural_height_map(size: usize, rms_slope: f64, seed: u64) -> HeightMap {
    let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(seed);
    let max_k = (size / 4).max(1) as f64;
    let waves: Vec<(DVec2, f64, f64)> = (0..SINES)
        .map(|_| {
            let k_len = max_k.powf(rng.random::<f64>());
            let angle = TAU * rng.random::<f64>();
            let k = (DVec2::new(angle.cos(), angle.sin()) * k_len).round();
            let k = if k == DVec2::ZERO { DVec2::X } else { k };
            (k, k.length().powf(-HEIGHT_SPECTRUM), TAU * rng.random::<f64>())
        })
        .collect();
    let mut heights: Vec<f64> = Vec::with_capacity(size * size);
    for y in 0..size {
        for x in 0..size {
            let p = DVec2::new(x as f64, y as f64) / size as f64;
            heights.push(waves.iter().map(|&(k, a, phase)| a * (TAU * k.dot(p) + phase).sin()).sum());
        }
    }
    let unit = HeightMap::new(size, size, 1.0 / size as f32, heights.iter().map(|&h| h as f32).collect())
        .expect("finite heights");
    let mean_sq: f64 =
        (0..size * size).map(|i| unit.slope(i % size, i / size).as_dvec2().length_squared()).sum::<f64>()
            / (2 * size * size) as f64;
    let scale = rms_slope / mean_sq.sqrt();
    HeightMap::new(size, size, 1.0 / size as f32, heights.iter().map(|&h| (h * scale) as f32).collect())
        .expect("finite heights")
}

/// The naive filter LEADR is compared against: a MIP pyramid of normals (2 × 2 box filter of the
/// unnormalized normals, renormalized at lookup), shaded with the base roughness alone.
pub struct NormalMip {
    /// (width, normals) per level; level 0 is the height map's unit normals.
    levels: Vec<(usize, Vec<DVec3>)>,
}

impl NormalMip {
    /// The pyramid of a square power-of-two height map's normals (−x̃, −ỹ, 1)/‖·‖.
    pub fn new(map: &HeightMap) -> Self {
        let size = map.width();
        let level0: Vec<DVec3> = (0..size * size)
            .map(|i| {
                let s = map.slope(i % size, i / size).as_dvec2();
                DVec3::new(-s.x, -s.y, 1.0).normalize()
            })
            .collect();
        let mut levels = vec![(size, level0)];
        while levels.last().expect("level 0").0 > 1 {
            let (w, fine) = levels.last().expect("level 0");
            let half = w / 2;
            let coarse = (0..half * half)
                .map(|i| {
                    let (x, y) = (2 * (i % half), 2 * (i / half));
                    (fine[y * w + x]
                        + fine[y * w + x + 1]
                        + fine[(y + 1) * w + x]
                        + fine[(y + 1) * w + x + 1])
                        / 4.0
                })
                .collect();
            levels.push((half, coarse));
        }
        Self { levels }
    }

    /// The mean slope −n.xy/n.z of the averaged normal of texel (x, y) at `level` (wrapping).
    pub fn slope(&self, level: usize, x: isize, y: isize) -> DVec2 {
        let (w, normals) = &self.levels[level.min(self.levels.len() - 1)];
        let w = *w as isize;
        let n = normals[(y.rem_euclid(w) * w + x.rem_euclid(w)) as usize];
        DVec2::new(-n.x / n.z, -n.y / n.z)
    }

    /// The averaged normal at texture coordinates `uv` and fractional `lod`, trilinearly
    /// interpolated as a GPU filters a normal map, as a mean slope.
    pub fn trilinear_slope(&self, uv: Vec2, lod: f32) -> DVec2 {
        let top = (self.levels.len() - 1) as f32;
        let lod = lod.clamp(0.0, top);
        let l0 = lod.floor() as usize;
        let t = f64::from(lod - lod.floor());
        let mut n = self.bilinear(l0, uv) * (1.0 - t);
        if t > 0.0 {
            n += self.bilinear(l0 + 1, uv) * t;
        }
        DVec2::new(-n.x / n.z, -n.y / n.z)
    }

    fn bilinear(&self, level: usize, uv: Vec2) -> DVec3 {
        let (w, normals) = &self.levels[level.min(self.levels.len() - 1)];
        let wi = *w as isize;
        // wrapped first, as `MomentLevel::bilinear`: any finite uv is a lookup
        let p = uv.as_dvec2().rem_euclid(DVec2::ONE) * *w as f64 - 0.5;
        let (x0, y0) = (p.x.floor(), p.y.floor());
        let (fx, fy) = (p.x - x0, p.y - y0);
        let at = |x: isize, y: isize| normals[(y.rem_euclid(wi) * wi + x.rem_euclid(wi)) as usize];
        let (x0, y0) = (x0 as isize, y0 as isize);
        at(x0, y0) * (1.0 - fx) * (1.0 - fy)
            + at(x0 + 1, y0) * fx * (1.0 - fy)
            + at(x0, y0 + 1) * (1.0 - fx) * fy
            + at(x0 + 1, y0 + 1) * fx * fy
    }
}

/// A unit direction at polar angle `theta_deg` in the xz plane, tilted towards +x.
pub fn direction(theta_deg: f64, phi_deg: f64) -> Vec3 {
    let (t, p) = (theta_deg.to_radians(), phi_deg.to_radians());
    DVec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos()).as_vec3()
}
