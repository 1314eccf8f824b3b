//! The five slope moments of a LEAN/LEADR texel.

use crate::error::Error;
use crate::slope::{Beckmann, MicrosurfaceSlope};
use glam::{DMat2, DVec2, Mat2, Vec2, Vec3};

/// The first and second slope moments of a texel of a LEAN/LEADR map (Dupuy 2015, §3.3,
/// eqs. 3.5–3.9; Olano and Baker 2010):
///
/// E₁ = E(x̃), E₂ = E(ỹ), E₃ = E(x̃²), E₄ = E(ỹ²), E₅ = E(x̃ỹ),
///
/// with slopes x̃ = ∂ξ/∂x, ỹ = ∂ξ/∂y of the displaced surface (the crate's convention
/// x̃ = −m.x/m.z). The moments are raw (not central), so that they filter linearly: the
/// moments of a union of texels are the averages of theirs (eqs. 3.10–3.14). A texel of slope
/// (x̃, ỹ) on a base microsurface of Beckmann roughness (αx, αy) has E₃ = x̃² + αx²/2,
/// E₄ = ỹ² + αy²/2 and E₅ = x̃ỹ: the Beckmann slope density exp(−x̃²/αx² − ỹ²/αy²)/(π αx αy)
/// has variance α²/2 per axis (eq. 3.17; `nmap2leanmap`, listing 3.7).
///
/// Stored in f32, as a renderer stores them. The central moments are formed in f64 from the
/// stored values, so their absolute error is the rounding of the raw ones, about
/// 2⁻²⁴ (E₁² + E₃) for the variance along x: relative to a variance v that is
/// 6e-8 (E₁² + E₃)/v (1.2e-3 for a texel of mean slope 1 and α = 0.01).
///
/// # Examples
///
/// ```
/// use microsurface::glam::Vec2;
/// use microsurface::Beckmann;
/// use microsurface::leadr::SlopeMoments;
///
/// let base = Beckmann::isotropic(0.2)?;
/// let a = SlopeMoments::from_slope(Vec2::new(0.3, 0.0), base)?;
/// let b = SlopeMoments::from_slope(Vec2::new(-0.3, 0.0), base)?;
/// let both = SlopeMoments::average(&[a, b]).expect("two texels");
/// // the mean slope cancels, the spread of the slopes adds to the base variance
/// assert!(both.mean().length() < 1e-7);
/// assert!((both.covariance()[0] - (0.09 + 0.02)).abs() < 1e-6);
/// # Ok::<(), microsurface::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SlopeMoments {
    e1: f32,
    e2: f32,
    e3: f32,
    e4: f32,
    e5: f32,
}

impl SlopeMoments {
    /// The moments (E₁, …, E₅) as given.
    ///
    /// They need not form a positive-definite covariance (filtering and rounding can break
    /// it); [`LeadrLobe::from_moments`](crate::leadr::LeadrLobe::from_moments) states what it does
    /// then.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] (`"e1"`…`"e5"`) if a moment is not finite.
    pub fn new(e1: f32, e2: f32, e3: f32, e4: f32, e5: f32) -> Result<Self, Error> {
        let finite = |name, value: f32| {
            if value.is_finite() {
                Ok(value)
            } else {
                Err(Error::InvalidParameter { name, value, expected: "finite" })
            }
        };
        Ok(Self {
            e1: finite("e1", e1)?,
            e2: finite("e2", e2)?,
            e3: finite("e3", e3)?,
            e4: finite("e4", e4)?,
            e5: finite("e5", e5)?,
        })
    }

    /// The moments of a texel whose mesosurface has slope (x̃, ỹ), on a base microsurface of
    /// Beckmann roughness (αx, αy): (x̃, ỹ, x̃² + αx²/2, ỹ² + αy²/2, x̃ỹ) (eqs. 3.5–3.9 with
    /// mean slope (x̃, ỹ) and ρ = 0).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] (`"slope"`) if a slope component is not finite, or so large
    /// that its square overflows f32 (|x̃| ≥ 1.8e19).
    pub fn from_slope(slope: Vec2, base: Beckmann) -> Result<Self, Error> {
        let s = slope.as_dvec2();
        let (ax, ay) = (f64::from(base.alpha_x()), f64::from(base.alpha_y()));
        let m = Self::from_f64(s, [s.x * s.x + 0.5 * ax * ax, s.y * s.y + 0.5 * ay * ay, s.x * s.y]);
        let bad = if slope.x.is_finite() { slope.y } else { slope.x };
        m.map_err(|_| Error::InvalidParameter {
            name: "slope",
            value: bad,
            expected: "finite, |slope| < 1.8e19",
        })
    }

    /// The moments of a texel of a tangent-space normal map: the slope of the normal n,
    /// (x̃, ỹ) = (−n.x/n.z, −n.y/n.z), on the base microsurface (see [`Self::from_slope`]).
    /// The normal need not be unit.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] (`"normal"`) if a component is not finite or n.z ≤ 0 (a
    /// normal on or below the tangent plane has no slope), or if the slope overflows.
    pub fn from_normal(normal: Vec3, base: Beckmann) -> Result<Self, Error> {
        if !(normal.is_finite() && normal.z > 0.0) {
            return Err(Error::InvalidParameter {
                name: "normal",
                value: normal.z,
                expected: "finite with z > 0 (above the tangent plane)",
            });
        }
        let n = normal.as_dvec3();
        let slope = DVec2::new(-n.x / n.z, -n.y / n.z).as_vec2();
        Self::from_slope(slope, base).map_err(|_| Error::InvalidParameter {
            name: "normal",
            value: normal.z,
            expected: "a slope −n.xy/n.z below 1.8e19",
        })
    }

    /// The moments of the displacement alone: these moments less the base microsurface's
    /// share, (E₁, E₂, E₃ − αx²/2, E₄ − αy²/2, E₅) (eqs. 3.5–3.9 with the base roughness
    /// removed). For the moments of a [`LeadrMap`](crate::leadr::LeadrMap) built on the base
    /// `base` (at any level: every texel carries the base's share once) they are the moments of
    /// the displacement's slopes, the input of the downsampling operator, which combines the
    /// displacement with any base material (Dupuy 2015, §5.1). The covariance may round to
    /// slightly negative values where the displacement is flat (see
    /// [`LeadrLobe::from_moments`](crate::leadr::LeadrLobe::from_moments)).
    #[must_use]
    pub fn without_base(&self, base: Beckmann) -> Self {
        let (ax, ay) = (f64::from(base.alpha_x()), f64::from(base.alpha_y()));
        let [e1, e2, e3, e4, e5] = self.to_array().map(f64::from);
        Self::from_array64([e1, e2, e3 - 0.5 * ax * ax, e4 - 0.5 * ay * ay, e5])
    }

    /// The moments of the union of equally weighted texels: their average, accumulated in f64
    /// (eqs. 3.10–3.14). `None` for an empty slice.
    #[must_use]
    pub fn average(texels: &[SlopeMoments]) -> Option<Self> {
        if texels.is_empty() {
            return None;
        }
        let mut sum = [0.0f64; 5];
        for t in texels {
            for (s, e) in sum.iter_mut().zip(t.to_array()) {
                *s += f64::from(e);
            }
        }
        let n = texels.len() as f64;
        Some(Self::from_array64(sum.map(|s| s / n)))
    }

    /// The moments of the slopes mapped linearly, s′ = A s: E′₁,₂ = A (E₁, E₂) and
    /// [[E′₃, E′₅], [E′₅, E′₄]] = A [[E₃, E₅], [E₅, E₄]] Aᵀ, computed in f64 (Dupuy 2015, §3.4,
    /// "Surface Stretching and Shearing" and "Height Scaling").
    ///
    /// For moments stored in texture space and a surface parameterized by u(x, y), v(x, y), the
    /// world-space moments take A with rows (∂u/∂x, ∂v/∂x) and (∂u/∂y, ∂v/∂y) (as a `Mat2`,
    /// column-major: `Mat2::from_cols((∂u/∂x, ∂u/∂y), (∂v/∂x, ∂v/∂y))`), assumed constant over the
    /// texel; a height scale β is A = β I. The map is linear, so it commutes with the MIP
    /// filtering and can be applied at lookup time. It maps the base roughness's share of the
    /// moments too (a stretched or height-scaled surface stretches its microgeometry as well).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] (`"slope_map"`) if an entry of A is not finite or a
    /// resulting moment overflows f32.
    pub fn transformed(&self, slope_map: Mat2) -> Result<Self, Error> {
        let bad = |value| Error::InvalidParameter {
            name: "slope_map",
            value,
            expected: "finite, moments within f32",
        };
        if let Some(&v) = slope_map.to_cols_array().iter().find(|v| !v.is_finite()) {
            return Err(bad(v));
        }
        let a = slope_map.as_dmat2();
        let [e1, e2, e3, e4, e5] = self.to_array().map(f64::from);
        let mean = a * DVec2::new(e1, e2);
        let second = a * DMat2::from_cols(DVec2::new(e3, e5), DVec2::new(e5, e4)) * a.transpose();
        Self::from_f64(mean, [second.x_axis.x, second.y_axis.y, second.y_axis.x])
            .map_err(|_| bad(f32::INFINITY))
    }

    /// The mean slope (E₁, E₂), the mesosurface's slope (x̃n, ỹn) (eqs. 3.5–3.6).
    #[must_use]
    pub fn mean(&self) -> Vec2 {
        Vec2::new(self.e1, self.e2)
    }

    /// The slope covariance [Σxx, Σyy, Σxy] = [E₃ − E₁², E₄ − E₂², E₅ − E₁E₂], formed in f64
    /// (and rounded to f32). It may fail to be positive definite; see
    /// [`LeadrLobe::from_moments`](crate::leadr::LeadrLobe::from_moments).
    #[must_use]
    pub fn covariance(&self) -> [f32; 3] {
        self.covariance64().map(|c| c as f32)
    }

    /// [`Self::covariance`] in f64.
    pub(crate) fn covariance64(&self) -> [f64; 3] {
        let [e1, e2, e3, e4, e5] = self.to_array().map(f64::from);
        [e3 - e1 * e1, e4 - e2 * e2, e5 - e1 * e2]
    }

    /// The moments as an array [E₁, …, E₅].
    #[must_use]
    pub fn to_array(&self) -> [f32; 5] {
        [self.e1, self.e2, self.e3, self.e4, self.e5]
    }

    /// Moments from f64 values known to be finite (averages of finite f32 moments): rounded.
    pub(crate) fn from_array64(e: [f64; 5]) -> Self {
        let [e1, e2, e3, e4, e5] = e.map(|v| v as f32);
        Self { e1, e2, e3, e4, e5 }
    }

    /// Moments (mean, [E₃, E₄, E₅]) rounded to f32, or `Err(())` if one is not finite there.
    fn from_f64(mean: DVec2, second: [f64; 3]) -> Result<Self, ()> {
        let m = Self::from_array64([mean.x, mean.y, second[0], second[1], second[2]]);
        if m.to_array().iter().all(|e| e.is_finite()) { Ok(m) } else { Err(()) }
    }
}
