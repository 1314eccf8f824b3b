//! The MERL isotropic BRDF binary format (Matusik, Pfister, Brand and McMillan 2003, "A
//! Data-Driven Reflectance Model"), in which most measured BRDFs ship: a reader, a writer and a
//! nearest-bin lookup, so that the extractions run on a measurement: the backscattering
//! ([`MerlBrdf::backscatter`] by polar angle for [`crate::tabulated::extract_isotropic_fn`],
//! [`MerlBrdf::backscatter_toward`] by direction for [`crate::tabulated::extract_anisotropic_fn`]) gives
//! the slope distribution, and [`MerlBrdf::eval`] the Fresnel term through
//! [`crate::tabulated::extract_fresnel`], for a [`crate::tabulated::TabulatedSlope`] or a [`crate::tabulated::GridSlope`] alike.
//!
//! Layout (little-endian): three `i32` dimensions (90 θh bins, 90 θd bins, 180 φd bins), then
//! 3 × 90·90·180 `f64` values, the red, green and blue blocks, each indexed by
//! φd + 180·(θd + 90·θh) and scaled by 1/1500, 1.15/1500 and 1.66/1500 respectively. The bins
//! are in the half/difference parameterization of Rusinkiewicz: θh is binned by
//! ⌊90·√(θh/(π/2))⌋ (finer near the specular peak), θd by ⌊90·θd/(π/2)⌋, φd ∈ [0, π) by
//! ⌊180·φd/π⌋ (φd < 0 is folded by +π: reciprocity). Negative values mark missing data.

use glam::{DVec3, Vec3};
use std::f64::consts::{FRAC_PI_2, PI};

/// Bins of θh.
pub const MERL_THETA_H: usize = 90;
/// Bins of θd.
pub const MERL_THETA_D: usize = 90;
/// Bins of φd over [0, π).
pub const MERL_PHI_D: usize = 180;
/// Values per channel.
const CELLS: usize = MERL_THETA_H * MERL_THETA_D * MERL_PHI_D;
/// Bytes of the header and of a complete file.
const HEADER_BYTES: usize = 12;
const FILE_BYTES: usize = HEADER_BYTES + 3 * CELLS * 8;
/// The per-channel scales of the stored values.
const SCALES: [f64; 3] = [1.0 / 1500.0, 1.15 / 1500.0, 1.66 / 1500.0];

/// Why a MERL file was rejected.
#[derive(Debug)]
#[non_exhaustive]
pub enum MerlError {
    /// The file is shorter than its header or than the data its header announces.
    Truncated {
        /// Bytes a complete file has.
        expected: usize,
        /// Bytes found.
        found: usize,
    },
    /// The header's dimensions are not 90 × 90 × 180.
    Dimensions([i32; 3]),
    /// The file is longer than header plus data.
    TrailingBytes(usize),
    /// A stored value is NaN or infinite (at this index of the whole value array).
    NonFinite(usize),
    /// Reading or writing the file failed.
    Io(std::io::Error),
}

impl core::fmt::Display for MerlError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            MerlError::Truncated { expected, found } => {
                write!(f, "truncated MERL file: {found} bytes, expected {expected}")
            }
            MerlError::Dimensions(d) => write!(f, "MERL dimensions {d:?}, expected [90, 90, 180]"),
            MerlError::TrailingBytes(n) => write!(f, "{n} bytes after the MERL data"),
            MerlError::NonFinite(i) => write!(f, "non-finite MERL value at index {i}"),
            MerlError::Io(e) => write!(f, "MERL file I/O: {e}"),
        }
    }
}

impl std::error::Error for MerlError {}

impl From<std::io::Error> for MerlError {
    fn from(e: std::io::Error) -> Self {
        MerlError::Io(e)
    }
}

/// An isotropic BRDF tabulated in the MERL format (values already multiplied by the channel
/// scales; negative = missing).
#[derive(Clone)]
pub struct MerlBrdf {
    /// 3 × CELLS values, channel-major.
    values: Vec<f64>,
}

impl core::fmt::Debug for MerlBrdf {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("MerlBrdf").field("cells", &CELLS).finish_non_exhaustive()
    }
}

/// The flat index of the bins of (θh, θd, φd) (MERL's lookup).
fn cell_index(theta_h: f64, theta_d: f64, phi_d: f64) -> usize {
    let ih = if theta_h <= 0.0 { 0 } else { ((theta_h / FRAC_PI_2).sqrt() * MERL_THETA_H as f64) as usize }
        .min(MERL_THETA_H - 1);
    let id = ((theta_d.max(0.0) / FRAC_PI_2 * MERL_THETA_D as f64) as usize).min(MERL_THETA_D - 1);
    let phi = if phi_d < 0.0 { phi_d + PI } else { phi_d };
    let ip = ((phi.max(0.0) / PI * MERL_PHI_D as f64) as usize).min(MERL_PHI_D - 1);
    ip + MERL_PHI_D * (id + MERL_THETA_D * ih)
}

/// Rotation of `v` about the unit `axis` by `angle` (Rodrigues).
fn rotate(v: DVec3, axis: DVec3, angle: f64) -> DVec3 {
    let (s, c) = angle.sin_cos();
    v * c + axis * axis.dot(v) * (1.0 - c) + axis.cross(v) * s
}

/// (θh, θd, φd) of the directions `wi`, `wo` (unit, upper hemisphere), as MERL computes them;
/// `None` if wi + wo vanishes.
#[must_use]
pub fn half_diff_angles(wi: Vec3, wo: Vec3) -> Option<(f64, f64, f64)> {
    let (i, o) = (wi.as_dvec3(), wo.as_dvec3());
    let h = (i + o).try_normalize()?;
    let theta_h = h.z.clamp(-1.0, 1.0).acos();
    let phi_h = h.y.atan2(h.x);
    let d = rotate(rotate(i, DVec3::Z, -phi_h), DVec3::Y, -theta_h);
    Some((theta_h, d.z.clamp(-1.0, 1.0).acos(), d.y.atan2(d.x)))
}

impl MerlBrdf {
    /// Parses a MERL file's bytes.
    ///
    /// # Errors
    /// [`MerlError::Truncated`] for an empty or short file, [`MerlError::Dimensions`] for a
    /// header other than 90 × 90 × 180, [`MerlError::TrailingBytes`] for extra bytes and
    /// [`MerlError::NonFinite`] for a NaN or infinite value.
    pub fn from_bytes(bytes: &[u8]) -> Result<Self, MerlError> {
        if bytes.len() < HEADER_BYTES {
            return Err(MerlError::Truncated { expected: FILE_BYTES, found: bytes.len() });
        }
        let dim = |k: usize| {
            i32::from_le_bytes([bytes[4 * k], bytes[4 * k + 1], bytes[4 * k + 2], bytes[4 * k + 3]])
        };
        let dims = [dim(0), dim(1), dim(2)];
        if dims != [MERL_THETA_H as i32, MERL_THETA_D as i32, MERL_PHI_D as i32] {
            return Err(MerlError::Dimensions(dims));
        }
        if bytes.len() < FILE_BYTES {
            return Err(MerlError::Truncated { expected: FILE_BYTES, found: bytes.len() });
        }
        if bytes.len() > FILE_BYTES {
            return Err(MerlError::TrailingBytes(bytes.len() - FILE_BYTES));
        }
        let mut values = Vec::with_capacity(3 * CELLS);
        for (k, chunk) in bytes[HEADER_BYTES..].chunks_exact(8).enumerate() {
            let raw = f64::from_le_bytes(chunk.try_into().expect("8-byte chunk"));
            if !raw.is_finite() {
                return Err(MerlError::NonFinite(k));
            }
            values.push(raw * SCALES[k / CELLS]);
        }
        Ok(Self { values })
    }

    /// Reads a MERL file.
    ///
    /// # Errors
    /// [`MerlError::Io`] if the file cannot be read, else as [`Self::from_bytes`].
    pub fn read(path: impl AsRef<std::path::Path>) -> Result<Self, MerlError> {
        Self::from_bytes(&std::fs::read(path)?)
    }

    /// The file's bytes (values divided by the channel scales).
    #[must_use]
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut out = Vec::with_capacity(FILE_BYTES);
        for d in [MERL_THETA_H, MERL_THETA_D, MERL_PHI_D] {
            out.extend_from_slice(&(d as i32).to_le_bytes());
        }
        for (k, v) in self.values.iter().enumerate() {
            out.extend_from_slice(&(v / SCALES[k / CELLS]).to_le_bytes());
        }
        out
    }

    /// Writes a MERL file.
    ///
    /// # Errors
    /// [`MerlError::Io`] if the file cannot be written.
    pub fn write(&self, path: impl AsRef<std::path::Path>) -> Result<(), MerlError> {
        Ok(std::fs::write(path, self.to_bytes())?)
    }

    /// Tabulates an isotropic BRDF `brdf(wi, wo)` (RGB, not times a cosine) at the bin centres:
    /// θh = ((k + ½)/90)²·π/2, θd = (k + ½)/90·π/2, φd = (k + ½)/180·π, with φh = 0.
    /// Configurations with wi or wo at or below the horizon, and non-finite or negative
    /// values, are stored as missing (−1).
    pub fn from_fn(brdf: impl Fn(Vec3, Vec3) -> Vec3) -> Self {
        let mut values = vec![-1.0; 3 * CELLS];
        for ih in 0..MERL_THETA_H {
            let u = (ih as f64 + 0.5) / MERL_THETA_H as f64;
            let theta_h = u * u * FRAC_PI_2;
            let h = DVec3::new(theta_h.sin(), 0.0, theta_h.cos());
            for id in 0..MERL_THETA_D {
                let theta_d = (id as f64 + 0.5) / MERL_THETA_D as f64 * FRAC_PI_2;
                for ip in 0..MERL_PHI_D {
                    let phi_d = (ip as f64 + 0.5) / MERL_PHI_D as f64 * PI;
                    let d =
                        DVec3::new(theta_d.sin() * phi_d.cos(), theta_d.sin() * phi_d.sin(), theta_d.cos());
                    let i = rotate(d, DVec3::Y, theta_h);
                    let o = 2.0 * i.dot(h) * h - i;
                    if i.z <= 0.0 || o.z <= 0.0 {
                        continue;
                    }
                    let f = brdf(i.as_vec3(), o.as_vec3());
                    let cell = ip + MERL_PHI_D * (id + MERL_THETA_D * ih);
                    for (c, v) in [f.x, f.y, f.z].into_iter().enumerate() {
                        if v.is_finite() && v >= 0.0 {
                            values[c * CELLS + cell] = f64::from(v);
                        }
                    }
                }
            }
        }
        Self { values }
    }

    /// The BRDF (RGB, not times a cosine) of the bin holding (wi, wo), as MERL looks it up
    /// (nearest bin, no interpolation); `None` if a channel is missing, if either direction is
    /// at or below the horizon, or if wi = −wo.
    #[must_use]
    pub fn eval(&self, wi: Vec3, wo: Vec3) -> Option<Vec3> {
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return None;
        }
        let (th, td, pd) = half_diff_angles(wi, wo)?;
        let cell = cell_index(th, td, pd);
        let rgb = [self.values[cell], self.values[CELLS + cell], self.values[2 * CELLS + cell]];
        if rgb.iter().any(|v| *v < 0.0) {
            return None;
        }
        Some(Vec3::new(rgb[0] as f32, rgb[1] as f32, rgb[2] as f32))
    }

    /// The backscattering f_r(o, o) toward the direction `o` (any length), the function
    /// [`crate::tabulated::extract_anisotropic_fn`] samples: the file is isotropic, so that of the polar
    /// angle of `o` ([`Self::backscatter`]). `None` for `o` at or below the horizon or not
    /// finite, and as [`Self::backscatter`].
    #[must_use]
    pub fn backscatter_toward(&self, o: Vec3) -> Option<Vec3> {
        if o.z <= 0.0 || !o.is_finite() {
            return None;
        }
        let o = o.as_dvec3();
        self.backscatter(o.x.hypot(o.y).atan2(o.z))
    }

    /// The backscattering f_r(o, o) at polar angle `theta` (θd = 0, θh = θ; φ irrelevant).
    #[must_use]
    pub fn backscatter(&self, theta: f64) -> Option<Vec3> {
        let cell = cell_index(theta, 0.0, 0.0);
        let rgb = [self.values[cell], self.values[CELLS + cell], self.values[2 * CELLS + cell]];
        if rgb.iter().any(|v| *v < 0.0) {
            return None;
        }
        Some(Vec3::new(rgb[0] as f32, rgb[1] as f32, rgb[2] as f32))
    }
}
