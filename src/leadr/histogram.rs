//! A histogram of a displacement's slopes: the tabulated displacement distribution of the
//! downsampling operator.

use super::HeightMap;
use crate::error::Error;
use glam::{DVec2, Vec2};

/// The most bins per axis of a [`SlopeHistogram`].
pub const MAX_HISTOGRAM_BINS: usize = 64;

/// The slope distribution of a patch of displacement (the fine texels under a MIP texel) as a
/// histogram: the slopes binned on `bins × bins` equal bins over their bounding box, each
/// occupied bin kept as its share of the slopes at the centroid of its slopes (Dupuy 2015,
/// §5.1: the distribution P_X of the displacement's slopes).
///
/// Keeping the centroid keeps the mass and the mean slope exact; the covariance of the bins
/// is that of the slopes less the spread within the bins (at most w²/12 per axis for bins of
/// width w). With one bin per distinct slope (enough bins) it is the slopes' empirical
/// distribution itself, the exact distribution of a displacement map's finite differences.
///
/// # Examples
/// ```
/// use microsurface::glam::Vec2;
/// use microsurface::leadr::SlopeHistogram;
///
/// let slopes = [Vec2::new(0.1, 0.0), Vec2::new(0.3, 0.0), Vec2::new(0.3, 0.2), Vec2::new(0.1, 0.2)];
/// let h = SlopeHistogram::from_slopes(&slopes, 4)?;
/// assert_eq!(h.bins().len(), 4);
/// assert!((h.mean() - Vec2::new(0.2, 0.1)).length() < 1e-6);
/// assert!((h.covariance()[0] - 0.01).abs() < 1e-6);
/// # Ok::<(), microsurface::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct SlopeHistogram {
    /// (centroid, mass) per occupied bin, masses summing to 1.
    bins: Vec<(DVec2, f64)>,
    mean: DVec2,
    /// [Σxx, Σyy, Σxy] of the slopes.
    covariance: [f64; 3],
}

impl SlopeHistogram {
    /// The histogram of `slopes` (equally weighted) on `bins × bins` bins over their bounding
    /// box (one bin along an axis where all slopes are equal).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`]: `"slopes"` if there are none (the value reported is 0) or
    /// one is not finite (the value reported is the component), `"bins"` if 0 or above
    /// [`MAX_HISTOGRAM_BINS`].
    pub fn from_slopes(slopes: &[Vec2], bins: usize) -> Result<Self, Error> {
        if bins == 0 || bins > MAX_HISTOGRAM_BINS {
            return Err(Error::InvalidParameter {
                name: "bins",
                value: bins as f32,
                expected: "1 to MAX_HISTOGRAM_BINS (64)",
            });
        }
        if slopes.is_empty() {
            return Err(Error::InvalidParameter {
                name: "slopes",
                value: 0.0,
                expected: "at least one slope",
            });
        }
        if let Some(bad) = slopes.iter().find(|s| !s.is_finite()) {
            let value = if bad.x.is_finite() { bad.y } else { bad.x };
            return Err(Error::InvalidParameter { name: "slopes", value, expected: "finite" });
        }
        let s: Vec<DVec2> = slopes.iter().map(|s| s.as_dvec2()).collect();
        let (lo, hi) =
            s.iter().fold((DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)), |(a, b), p| {
                (a.min(*p), b.max(*p))
            });
        let n = s.len() as f64;
        let mean = s.iter().sum::<DVec2>() / n;
        let mut covariance = [0.0; 3];
        for p in &s {
            let d = *p - mean;
            covariance[0] += d.x * d.x / n;
            covariance[1] += d.y * d.y / n;
            covariance[2] += d.x * d.y / n;
        }
        let width = (hi - lo) / bins as f64;
        let index =
            |v: f64, lo: f64, w: f64| if w > 0.0 { (((v - lo) / w) as usize).min(bins - 1) } else { 0 };
        let mut sums = vec![(DVec2::ZERO, 0usize); bins * bins];
        for p in &s {
            let k = index(p.y, lo.y, width.y) * bins + index(p.x, lo.x, width.x);
            sums[k].0 += *p;
            sums[k].1 += 1;
        }
        let bins = sums
            .into_iter()
            .filter(|(_, count)| *count > 0)
            .map(|(sum, count)| (sum / count as f64, count as f64 / n))
            .collect();
        Ok(Self { bins, mean, covariance })
    }

    /// The histogram of the slopes of the `2^level × 2^level` texels of `map` under texel
    /// (x, y) of MIP level `level` (texels (x·2^level + i, y·2^level + j), coordinates
    /// wrapping; the whole map if 2^level exceeds it; [`HeightMap::slope`]): the displacement
    /// a MIP texel of a [`LeadrMap`](crate::leadr::LeadrMap) filters, as its slope
    /// distribution instead of its moments.
    ///
    /// # Errors
    /// As [`Self::from_slopes`]; `"level"` if 2^level overflows (level ≥ 32).
    pub fn from_height_map(
        map: &HeightMap,
        level: usize,
        x: usize,
        y: usize,
        bins: usize,
    ) -> Result<Self, Error> {
        if level >= 32 {
            return Err(Error::InvalidParameter { name: "level", value: level as f32, expected: "below 32" });
        }
        let n = 1usize << level;
        let (w, h) = (map.width(), map.height());
        let mut slopes = Vec::with_capacity(n.min(w) * n.min(h));
        for j in 0..n.min(h) {
            for i in 0..n.min(w) {
                slopes.push(map.slope((x * n + i) % w, (y * n + j) % h));
            }
        }
        Self::from_slopes(&slopes, bins)
    }

    /// The occupied bins: (centroid, mass) with masses summing to 1.
    #[must_use]
    pub fn bins(&self) -> &[(DVec2, f64)] {
        &self.bins
    }

    /// The mean slope.
    #[must_use]
    pub fn mean(&self) -> Vec2 {
        self.mean.as_vec2()
    }

    /// The mean slope in f64.
    #[cfg(feature = "data-driven")]
    pub(crate) fn mean64(&self) -> DVec2 {
        self.mean
    }

    /// The slopes' covariance [Σxx, Σyy, Σxy] (of the slopes, not of the bins' centroids).
    #[must_use]
    pub fn covariance(&self) -> [f32; 3] {
        self.covariance.map(|c| c as f32)
    }

    /// [`Self::covariance`] in f64.
    #[cfg(feature = "data-driven")]
    pub(crate) fn covariance64(&self) -> [f64; 3] {
        self.covariance
    }
}
