//! A periodic height (displacement) map and its slopes.

use crate::error::Error;
use glam::Vec2;

/// A scalar displacement map ξ over a periodic grid of `width × height` texels of side
/// `texel_size` (heights in the same unit), the input of LEADR mapping (Dupuy 2015, §3.4).
///
/// The map tiles the plane: it wraps around at its edges, so every texel has neighbours.
///
/// # Examples
///
/// ```
/// use microsurface::leadr::HeightMap;
///
/// // a ramp of slope 0.5 along x would not be periodic; a ridge is
/// let heights = vec![0.0, 0.5, 1.0, 0.5];
/// let map = HeightMap::new(4, 1, 1.0, heights)?;
/// assert_eq!(map.slope(1, 0).x, 0.5); // central difference (1.0 − 0.0)/2
/// # Ok::<(), microsurface::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct HeightMap {
    width: usize,
    height: usize,
    texel_size: f32,
    heights: Vec<f32>,
}

impl HeightMap {
    /// A map of `width × height` heights in row-major order (x fastest), texels of side
    /// `texel_size`.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`]: `"width"` / `"height"` if 0, `"heights"` if its length is
    /// not `width · height` (the value reported is the length) or a height is not finite (the
    /// value reported is the height), `"texel_size"` if not finite and > 0.
    pub fn new(width: usize, height: usize, texel_size: f32, heights: Vec<f32>) -> Result<Self, Error> {
        check_size("width", width)?;
        check_size("height", height)?;
        Error::check_positive("texel_size", texel_size)?;
        if heights.len() != width * height {
            return Err(Error::InvalidParameter {
                name: "heights",
                value: heights.len() as f32,
                expected: "width · height values",
            });
        }
        if let Some(&h) = heights.iter().find(|h| !h.is_finite()) {
            return Err(Error::InvalidParameter { name: "heights", value: h, expected: "finite" });
        }
        Ok(Self { width, height, texel_size, heights })
    }

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

    /// The side of a texel.
    #[must_use]
    pub fn texel_size(&self) -> f32 {
        self.texel_size
    }

    /// The height of texel (x, y), the coordinates taken modulo the size (the map tiles).
    #[must_use]
    pub fn height_at(&self, x: isize, y: isize) -> f32 {
        let xi = x.rem_euclid(self.width as isize) as usize;
        let yi = y.rem_euclid(self.height as isize) as usize;
        self.heights[yi * self.width + xi]
    }

    /// The slope (x̃, ỹ) = (∂ξ/∂x, ∂ξ/∂y) of texel (x, y) by central differences,
    /// ((ξ(x+1, y) − ξ(x−1, y)), (ξ(x, y+1) − ξ(x, y−1))) / (2 · texel size), which the thesis
    /// prefers to one-sided differences for smoother shading (§3.4, fig. 3.6). Computed in
    /// f64; coordinates wrap.
    #[must_use]
    pub fn slope(&self, x: usize, y: usize) -> Vec2 {
        let (x, y) = (x as isize, y as isize);
        let h = |dx, dy| f64::from(self.height_at(x + dx, y + dy));
        let scale = 0.5 / f64::from(self.texel_size);
        Vec2::new(((h(1, 0) - h(-1, 0)) * scale) as f32, ((h(0, 1) - h(0, -1)) * scale) as f32)
    }
}

/// Checks a grid dimension: at least 1.
pub(crate) fn check_size(name: &'static str, size: usize) -> Result<usize, Error> {
    if size == 0 {
        Err(Error::InvalidParameter { name, value: 0.0, expected: "at least 1" })
    } else {
        Ok(size)
    }
}
