//! The LEAN/LEADR MIP pyramid of slope moments.

use super::height_map::check_size;
use super::{HeightMap, LeadrLobe, SlopeMoments};
use crate::error::Error;
use crate::slope::Beckmann;
use glam::{Vec2, Vec3};

/// One level of a [`LeadrMap`]: `width × height` texels of moments, row-major.
///
/// # Examples
/// ```
/// use microsurface::Beckmann;
/// use microsurface::leadr::{HeightMap, LeadrMap};
///
/// // a flat 4 × 4 map: every level keeps the base roughness, variance α²/2 per axis
/// let map = LeadrMap::from_height_map(&HeightMap::new(4, 4, 0.25, vec![0.0; 16])?, Beckmann::isotropic(0.1)?)?;
/// let top = map.level(map.level_count() - 1);
/// assert_eq!((top.width(), top.height()), (1, 1));
/// assert!((top.texel(0, 0).covariance()[0] - 0.005).abs() < 1e-6);
/// # Ok::<(), microsurface::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct MomentLevel {
    width: usize,
    height: usize,
    texels: Vec<SlopeMoments>,
}

impl MomentLevel {
    /// Width in texels.
    #[must_use]
    pub fn width(&self) -> usize {
        self.width
    }

    /// Height in texels.
    #[must_use]
    pub fn height(&self) -> usize {
        self.height
    }

    /// The moments of texel (x, y), coordinates wrapping (the map tiles).
    #[must_use]
    pub fn texel(&self, x: isize, y: isize) -> SlopeMoments {
        let xi = x.rem_euclid(self.width as isize) as usize;
        let yi = y.rem_euclid(self.height as isize) as usize;
        self.texels[yi * self.width + xi]
    }

    /// The texels, row-major (x fastest).
    #[must_use]
    pub fn texels(&self) -> &[SlopeMoments] {
        &self.texels
    }

    /// The moments at texture coordinates `uv`, interpolated bilinearly between texel centres
    /// (texel (x, y) is centred at ((x + ½)/width, (y + ½)/height)). Moments filter linearly, so
    /// this is exact LEADR filtering of the four texels with the bilinear weights.
    ///
    /// The map tiles: every finite `uv` is valid and is first wrapped to uv mod 1 (`rem_euclid` in
    /// f64, exact for every f32; a tiny negative uv rounds to 1, the same texels), so that far-out coordinates (1e30) index
    /// texels without overflow.
    ///
    /// Invalid input ([policy](crate#invalid-input)): a non-finite `uv` trips a debug
    /// assertion; release builds return texel (0, 0) (moments have no "nothing").
    #[must_use]
    pub fn bilinear(&self, uv: Vec2) -> SlopeMoments {
        require!(uv.is_finite(), self.texels[0]; uv);
        let wrapped = uv.as_dvec2().rem_euclid(glam::DVec2::ONE);
        let p = wrapped * glam::DVec2::new(self.width as f64, self.height as f64) - 0.5;
        let (x0, y0) = (p.x.floor(), p.y.floor());
        let (fx, fy) = (p.x - x0, p.y - y0);
        let (x0, y0) = (x0 as isize, y0 as isize);
        let mut sum = [0.0f64; 5];
        for (dx, dy, w) in [
            (0, 0, (1.0 - fx) * (1.0 - fy)),
            (1, 0, fx * (1.0 - fy)),
            (0, 1, (1.0 - fx) * fy),
            (1, 1, fx * fy),
        ] {
            for (s, e) in sum.iter_mut().zip(self.texel(x0 + dx, y0 + dy).to_array()) {
                *s += w * f64::from(e);
            }
        }
        SlopeMoments::from_array64(sum)
    }
}

/// A LEAN/LEADR map: the slope moments of a displacement or normal map and their MIP pyramid
/// (Dupuy 2015, §3.3–3.4; Olano and Baker 2010), from which each texel at each level gets a
/// noncentral anisotropic Beckmann lobe ([`LeadrLobe`]).
///
/// Level 0 holds the moments of the input texels with the base roughness added (eqs.
/// 3.5–3.9, listing 3.7). Level ℓ + 1 is the 2 × 2 box filter of level ℓ: each texel is the
/// average of the four it covers (of two along a dimension that has reached 1), accumulated
/// in f64 (eqs. 3.10–3.14). The moments filter linearly, so level ℓ holds exactly the moments
/// of the 4^ℓ input texels under it; only the Gaussian shape of the lobe is an approximation.
/// Levels go down to 1 × 1.
///
/// **Beckmann only**: the base roughness is a [`Beckmann`] distribution, because GGX's
/// second slope moments diverge (see [`LeadrLobe`]).
///
/// Where the approximation holds (the thesis' limits): the filtered lobe reproduces the
/// *average* of the fine texels' BRDFs when the slopes under a texel are near Gaussian (many
/// texels of varied slope), and as long as the masking of each fine texel by its neighbours,
/// which the per-texel Smith model of the reference does not see either, matters little. At
/// grazing views the Smith masking of the one wide filtered lobe and the average of the
/// fine texels' maskings part (G1 is not linear in the slope distribution), and a few
/// distinct slopes (a coarse texel over a handful of sharp facets) make a multimodal
/// distribution that a single Gaussian blurs. README, “LEADR mapping”, gives the measured
/// errors.
///
/// # Examples
///
/// ```
/// use microsurface::Beckmann;
/// use microsurface::leadr::{HeightMap, LeadrMap};
///
/// // a 4 × 4 periodic bump map with bumps of slope ±0.5 along x
/// let heights: Vec<f32> = (0..16).map(|i| [0.0, 0.5, 1.0, 0.5][i % 4]).collect();
/// let map = LeadrMap::from_height_map(&HeightMap::new(4, 4, 1.0, heights)?, Beckmann::isotropic(0.1)?)?;
/// assert_eq!(map.level_count(), 3); // 4 × 4, 2 × 2, 1 × 1
/// let top = map.lobe(2, 0, 0);
/// // slopes 0, +0.5, 0, −0.5 under it: variance 0.125 + α²/2 along x, α²/2 along y
/// assert!((top.alpha_x() - (2.0f32 * (0.125 + 0.005)).sqrt()).abs() < 1e-6);
/// assert!((top.alpha_y() - 0.1).abs() < 1e-6);
/// # Ok::<(), microsurface::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct LeadrMap {
    levels: Vec<MomentLevel>,
}

impl LeadrMap {
    /// The map of a height map: slopes by central differences ([`HeightMap::slope`]) on the
    /// base roughness `base`.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`]: `"width"` / `"height"` if a dimension is not a power of
    /// two, `"slope"` if a slope overflows f32.
    pub fn from_height_map(map: &HeightMap, base: Beckmann) -> Result<Self, Error> {
        let (w, h) = (map.width(), map.height());
        check_pyramid(w, h)?;
        let mut texels = Vec::with_capacity(w * h);
        for y in 0..h {
            for x in 0..w {
                texels.push(SlopeMoments::from_slope(map.slope(x, y), base)?);
            }
        }
        Ok(Self::from_level(MomentLevel { width: w, height: h, texels }))
    }

    /// The map of a tangent-space normal map (`width × height` normals, row-major, need not
    /// be unit): slopes (−n.x/n.z, −n.y/n.z) ([`SlopeMoments::from_normal`]) on the base
    /// roughness `base`.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`]: `"width"` / `"height"` if a dimension is not a power of
    /// two, `"normals"` if there are not `width · height` of them, `"normal"` if one is not
    /// finite or has n.z ≤ 0.
    pub fn from_normal_map(
        width: usize,
        height: usize,
        normals: &[Vec3],
        base: Beckmann,
    ) -> Result<Self, Error> {
        check_pyramid(width, height)?;
        if normals.len() != width * height {
            return Err(Error::InvalidParameter {
                name: "normals",
                value: normals.len() as f32,
                expected: "width · height normals",
            });
        }
        let texels =
            normals.iter().map(|&n| SlopeMoments::from_normal(n, base)).collect::<Result<Vec<_>, _>>()?;
        Ok(Self::from_level(MomentLevel { width, height, texels }))
    }

    /// The pyramid above a full-resolution level.
    fn from_level(level0: MomentLevel) -> Self {
        let mut levels = vec![level0];
        loop {
            let fine = levels.last().expect("level 0 is there");
            if fine.width == 1 && fine.height == 1 {
                break;
            }
            let coarse = downsample(fine);
            levels.push(coarse);
        }
        Self { levels }
    }

    /// The number of levels, log₂(max(width, height)) + 1.
    #[must_use]
    pub fn level_count(&self) -> usize {
        self.levels.len()
    }

    /// Level `level` (0 is the input's resolution); the coarsest for a larger index.
    #[must_use]
    pub fn level(&self, level: usize) -> &MomentLevel {
        &self.levels[level.min(self.levels.len() - 1)]
    }

    /// The lobe of texel (x, y) of level `level` (coordinates wrap; the coarsest level for a
    /// larger index).
    #[must_use]
    pub fn lobe(&self, level: usize, x: isize, y: isize) -> LeadrLobe {
        LeadrLobe::from_moments(&self.level(level).texel(x, y))
    }

    /// The moments at texture coordinates `uv` (any finite uv, wrapped as in
    /// [`MomentLevel::bilinear`]) and fractional MIP level `lod`
    /// (clamped to [0, coarsest]): trilinear filtering, bilinear within the two nearest
    /// levels and linear between them, exact for moments.
    ///
    /// Invalid input ([policy](crate#invalid-input)): a non-finite `uv` or a NaN `lod` trips a
    /// debug assertion; release builds return texel (0, 0) of level 0.
    pub fn trilinear(&self, uv: Vec2, lod: f32) -> SlopeMoments {
        require!(uv.is_finite() && !lod.is_nan(), self.levels[0].texels[0]; uv, lod);
        let top = (self.levels.len() - 1) as f32;
        let lod = lod.clamp(0.0, top);
        let l0 = lod.floor();
        let t = f64::from(lod - l0);
        let a = self.level(l0 as usize).bilinear(uv).to_array();
        if t == 0.0 {
            return SlopeMoments::from_array64(a.map(f64::from));
        }
        let b = self.level(l0 as usize + 1).bilinear(uv).to_array();
        let mut e = [0.0f64; 5];
        for i in 0..5 {
            e[i] = (1.0 - t) * f64::from(a[i]) + t * f64::from(b[i]);
        }
        SlopeMoments::from_array64(e)
    }
}

/// The 2 × 2 box filter of a level (1 × 2 or 2 × 1 along a dimension of size 1).
fn downsample(fine: &MomentLevel) -> MomentLevel {
    let (w, h) = ((fine.width / 2).max(1), (fine.height / 2).max(1));
    let (sx, sy) = (fine.width / w, fine.height / h);
    let mut texels = Vec::with_capacity(w * h);
    let mut block = Vec::with_capacity(4);
    for y in 0..h {
        for x in 0..w {
            block.clear();
            for dy in 0..sy {
                for dx in 0..sx {
                    block.push(fine.texels[(y * sy + dy) * fine.width + x * sx + dx]);
                }
            }
            texels.push(SlopeMoments::average(&block).expect("a block has 1 to 4 texels"));
        }
    }
    MomentLevel { width: w, height: h, texels }
}

/// Checks the dimensions of a pyramid's level 0: powers of two.
fn check_pyramid(width: usize, height: usize) -> Result<(), Error> {
    for (name, size) in [("width", width), ("height", height)] {
        check_size(name, size)?;
        if !size.is_power_of_two() {
            return Err(Error::InvalidParameter { name, value: size as f32, expected: "a power of two" });
        }
    }
    Ok(())
}
