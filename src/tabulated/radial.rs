//! A tabulated isotropic slope distribution (Dupuy 2015, thesis §4.2: data-driven
//! microsurfaces), with exact visible-normal sampling on the whole sphere.

use crate::error::Error;
use crate::slope::{Azimuth, MicrosurfaceSlope};
use crate::vector::ensure_visible;
use core::f64::consts::{FRAC_PI_2, PI};
use glam::{DVec3, Vec2, Vec3};

/// Largest number of rings a table may have (the sampler's cost grows linearly with it).
pub const MAX_RINGS: usize = 4096;

/// Intervals of the table of the back-face area B over u = |cos θ| ∈ [0, 1] (linear
/// interpolation; its error is measured in `tests/tabulated/tabulated.rs`).
const BACKFACE_INTERVALS: usize = 2048;

/// B is summed exactly (instead of interpolated) when the visibility line cuts at most this
/// many rings: near the poles, where B is small and has a kink at every ring the line
/// crosses (at angles atan(1/Rₖ), ever closer for the outer rings), which no table in u
/// resolves.
const EXACT_RINGS: usize = 24;

/// Gauss–Legendre nodes and weights on [−1, 1], 8 points (exact for polynomials of degree 15),
/// used for the ring masses of [`TabulatedSlope::from_radial_fn`].
const GL8: [(f64, f64); 8] = [
    (-0.960_289_856_497_536_3, 0.101_228_536_290_376_3),
    (-0.796_666_477_413_626_7, 0.222_381_034_453_374_5),
    (-0.525_532_409_916_329, 0.313_706_645_877_887_3),
    (-0.183_434_642_495_649_8, 0.362_683_783_378_362),
    (0.183_434_642_495_649_8, 0.362_683_783_378_362),
    (0.525_532_409_916_329, 0.313_706_645_877_887_3),
    (0.796_666_477_413_626_7, 0.222_381_034_453_374_5),
    (0.960_289_856_497_536_3, 0.101_228_536_290_376_3),
];

/// The safeguarded Newton iteration of the sampler stops when its step is below this fraction
/// of the ring's outer radius (far below the f32 resolution of the returned slope).
const NEWTON_TOLERANCE: f64 = 1e-13;
/// A hard cap on the sampler's Newton–bisection iterations (bisection alone needs ~45 to reach
/// [`NEWTON_TOLERANCE`]; Newton typically converges in 4–8).
const MAX_ITERATIONS: usize = 100;

/// An isotropic slope distribution given by a radial table: P²²(x̃, ỹ) = pₖ for slope radii
/// r = √(x̃² + ỹ²) in the ring [Rₖ, Rₖ₊₁), k = 0 … N−1, and 0 beyond R_N.
///
/// # The table
/// The ring boundaries are Rₖ = s·tan θ′ₖ for a slope scale s > 0, at the "stretched" normal
/// angles θ′ₖ = (π/2)(1 − (1 − k/(N+1))²): steps of the angle atan(r/s) that are π/(N+1) at
/// the centre and shrink towards the horizon, so that a lobe of roughness ≈ s is resolved and
/// the table reaches the slope R_N = s·cot(π/(2(N+1)²)) ≈ 0.64 (N+1)² s (the mass beyond it is
/// dropped: for GGX with s = α, the tail mass ≈ 2.5/(N+1)⁴ and the back-face area it would add,
/// 2α²/(πR_N), are negligible at N = 256). The interpolation is **piecewise constant in slope
/// space** (nearest ring), so D(ωm) = pₖ/cos⁴θm is piecewise smooth with jumps at the ring
/// boundaries; the table is normalized so that ∫P²² = Σₖ pₖ π(Rₖ₊₁² − Rₖ²) = 1, i.e.
/// ∫D cos θm dωm = 1 exactly for the stated interpolation. Tabulating a smooth radial P²² by
/// ring averages gives a relative error of D of at most about ½ δθ′·|d ln P²²/dθ′| at the ring
/// edges (δθ′ the ring's angular width); for GGX with s = α that is 2δθ′·r/α, e.g. 2.4 % at
/// r = α with N = 256, and O(δθ′²) at the ring centres.
///
/// # Λ and the projected area
/// The projected area of one ring seen from ω = (sin θ, 0, cos θ) has a closed form,
/// ∫_{r<R} (cos θ − x̃ sin θ)₊ dx̃ dỹ = cos θ·(c w + R² acos(−c/R)) + ⅔ sin θ·w³ with
/// c = cot θ, w = √(R² − c²) (for |c| < R; πR² cos θ or 0 otherwise), so the projected area of
/// the table is an exact finite sum ([`TabulatedSlope::projected_area_exact`], cost O(N)). For
/// speed, the trait's `lambda` and `projected_area` interpolate linearly a precomputed table
/// of the back-face area B(u) = ∫⟨ω′, ωm⟩₊ D dωm, ω′.z = −u, over u ∈ [0, 1] (2049 nodes),
/// except near the poles, where the visibility line cuts at most 24 rings and B is summed
/// exactly (B is small there and has a kink at each ring boundary the line crosses):
/// projected_area(ω) = cos θ + B(cos θ) above the horizon and B(|cos θ|) below, Λ = B/cos θ
/// above and −1 − B/|cos θ| below. This keeps Λ(−ω) = −1 − Λ(ω) exact and Λ's relative
/// error small near the zenith (where Λ = B/cos θ is small, B is small too).
///
/// # Sampling
/// Visible normals are sampled **exactly** (for the stated interpolation) by inversion, with
/// the two uniforms only: in the slope frame aligned with ωi's azimuth, D_ωi dωm ∝
/// (cos θi − x̃ sin θi)₊ P²² dx̃ dỹ, a mixture over rings of uniform annuli weighted by a
/// linear function clipped to a half plane. The first uniform picks the ring by its exact
/// visible mass (prefix sums for the rings entirely on the visible side, the closed form above
/// for the others), then, rescaled, gives x̃ by a safeguarded Newton inversion of the closed-form
/// marginal CDF of x̃ in that annulus; the second gives ỹ uniformly on the annulus' chord at x̃.
/// The sampled density is the exact D_ωi of the table; [`MicrosurfaceSlope::d_wi`] divides by
/// the interpolated projected area, whose relative error is measured in the tests. The cost is
/// O(log N) plus O(number of rings cut by the visibility line x̃ = cot θi): all N for grazing
/// and back-facing ωi.
///
/// The crate's [`MicrosurfaceSlope`] trait requires `Copy`; it is implemented for
/// `&TabulatedSlope`, so that the tables live once and the walks, estimators and BSDFs share
/// them by reference.
///
/// Reference: Dupuy 2015, *Photorealistic Surface Rendering with Microfacet Theory*, §4.2–4.3
/// (the tabulated slope distribution and its Smith Λ by quadrature).
#[derive(Clone)]
pub struct TabulatedSlope {
    /// The slope scale s of the ring grid.
    scale: f64,
    /// N + 1, the grid's divisor.
    divisions: f64,
    /// Ring boundaries R₀ = 0 < R₁ < … < R_N.
    radii: Vec<f64>,
    /// The normalized ring values pₖ (N of them).
    p22: Vec<f64>,
    /// Prefix masses Mₖ = Σ_{j<k} pⱼ π(Rⱼ₊₁² − Rⱼ²), M₀ = 0, M_N = 1.
    mass_prefix: Vec<f64>,
    /// The back-face area B at u = j/BACKFACE_INTERVALS.
    backface: Vec<f64>,
    /// The GGX-equivalent roughness 2 B(0).
    alpha: f32,
    /// The mass of the input before normalization (≠ 1 when the input was truncated at R_N).
    input_mass: f64,
}

impl core::fmt::Debug for TabulatedSlope {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("TabulatedSlope")
            .field("rings", &self.p22.len())
            .field("scale", &self.scale)
            .field("alpha", &self.alpha)
            .field("input_mass", &self.input_mass)
            .finish_non_exhaustive()
    }
}

/// The projected area of the uniform slope disk r < R (of density 1) seen from
/// ω = (sin θ, 0, cos θ): ∫_{r<R} (cos θ − x̃ sin θ)₊ dx̃ dỹ, in closed form.
#[inline]
pub(super) fn disk_area(radius: f64, cos_t: f64, sin_t: f64) -> f64 {
    if radius <= 0.0 {
        return 0.0;
    }
    // visible where x̃ sin θ < cos θ, i.e. x̃ < c = cot θ
    if cos_t >= radius * sin_t {
        return PI * radius * radius * cos_t.max(0.0);
    }
    if cos_t <= -radius * sin_t {
        return 0.0;
    }
    partial_disk_integral(radius, cos_t / sin_t, cos_t, sin_t)
}

/// ∫_{−R}^{x} (cos θ − s sin θ)·2√(R² − s²) ds for x ∈ [−R, R]: the projected area of the part
/// x̃ < x of the disk r < R.
#[inline]
fn partial_disk_integral(radius: f64, x: f64, cos_t: f64, sin_t: f64) -> f64 {
    let x = x.clamp(-radius, radius);
    let w = ((radius - x) * (radius + x)).max(0.0).sqrt();
    // ∫ 2√(R² − s²) ds = s√(R² − s²) + R² asin(s/R); from −R: + R²π/2 = R² acos(−s/R)
    let chord_part = x * w + radius * radius * (-x / radius).clamp(-1.0, 1.0).acos();
    // ∫ −2s√(R² − s²) ds = ⅔ (R² − s²)^{3/2}, zero at −R
    cos_t * chord_part + sin_t * (2.0 / 3.0) * w * w * w
}

/// The chord length 2√(R² − x²)₊ of the disk r < R at x̃ = x.
#[inline]
fn chord(radius: f64, x: f64) -> f64 {
    2.0 * ((radius - x) * (radius + x)).max(0.0).sqrt()
}

impl TabulatedSlope {
    /// A table from ring values of P²²: `values[k]` is P²² on the ring [Rₖ, Rₖ₊₁) of the grid
    /// Rₖ = `scale`·tan(kπ/(2(N+1))), N = `values.len()` (a ring average, or a sample at the
    /// ring's centre). The values are normalized to unit mass with the piecewise-constant
    /// interpolation (see the type's documentation).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] if `scale` is not finite and > 0, if `values` is empty or
    /// longer than [`MAX_RINGS`] (`name = "values.len()"`), if a value is NaN, infinite or
    /// negative (`name = "values[k]"`, the offending value), or if the total mass is zero or not
    /// finite (`name = "total mass"`).
    pub fn from_p22(scale: f32, values: &[f32]) -> Result<Self, Error> {
        let values: Vec<f64> = values.iter().map(|&v| f64::from(v)).collect();
        Self::from_ring_values(scale, values, None)
    }

    /// A table from samples of D: `values[k]` is D at the normal angle of the centre of ring k,
    /// θₖ = atan(`scale`·tan((k + ½)Δ)), converted to P²² = D cos⁴θₖ and then as
    /// [`Self::from_p22`].
    ///
    /// # Errors
    /// As [`Self::from_p22`].
    pub fn from_d(scale: f32, values: &[f32]) -> Result<Self, Error> {
        let s = f64::from(Error::check_positive("scale", scale)?);
        let n = values.len();
        let p: Vec<f64> = values
            .iter()
            .enumerate()
            .map(|(k, &d)| {
                let r = s * grid_angle(k as f64 + 0.5, n).tan();
                let cos2 = 1.0 / (1.0 + r * r);
                f64::from(d) * cos2 * cos2
            })
            .collect();
        // validation of the values (sign, NaN) is done on the converted values, which keep
        // the sign and NaN-ness of the inputs
        Self::from_ring_values(scale, p, None).map_err(|e| match e {
            Error::InvalidParameter { name: "values[k]", .. } => {
                let bad = values.iter().copied().find(|v| !(v.is_finite() && *v >= 0.0)).unwrap_or(f32::NAN);
                Error::InvalidParameter { name: "values[k]", value: bad, expected: "finite and >= 0" }
            }
            other => other,
        })
    }

    /// A table of `rings` rings of the radial slope density `p22(r)` (r ≥ 0 the slope radius),
    /// by the exact ring averages pₖ = ∫_{Rₖ}^{Rₖ₊₁} p22(r) 2πr dr / (π(Rₖ₊₁² − Rₖ²)) (8-point
    /// Gauss–Legendre in the stretched angle per ring), normalized. The mass beyond R_N is
    /// dropped; [`Self::input_mass`] reports the mass that was tabulated.
    ///
    /// # Errors
    /// As [`Self::from_p22`] (`rings` is `values.len()`); a NaN, infinite or negative value
    /// of `p22` at a quadrature node is reported as `values[k]`.
    pub fn from_radial_fn(scale: f32, rings: usize, p22: impl Fn(f64) -> f64) -> Result<Self, Error> {
        let s = f64::from(Error::check_positive("scale", scale)?);
        check_ring_count(rings)?;
        let mut values = Vec::with_capacity(rings);
        let mut input_mass = 0.0;
        for k in 0..rings {
            let (t0, t1) = (grid_angle(k as f64, rings), grid_angle((k + 1) as f64, rings));
            let (mid, half) = (0.5 * (t0 + t1), 0.5 * (t1 - t0));
            let mut mass = 0.0;
            for (x, w) in GL8 {
                let t = mid + half * x;
                let r = s * t.tan();
                let v = p22(r);
                if !(v.is_finite() && v >= 0.0) {
                    return Err(Error::InvalidParameter {
                        name: "values[k]",
                        value: v as f32,
                        expected: "finite and >= 0",
                    });
                }
                // dr = s sec²t dt
                let sec2 = 1.0 + t.tan() * t.tan();
                mass += w * half * v * 2.0 * PI * r * s * sec2;
            }
            let (r0, r1) = (s * t0.tan(), s * t1.tan());
            let area = PI * (r1 - r0) * (r1 + r0);
            input_mass += mass;
            values.push(mass / area);
        }
        Self::from_ring_values(scale, values, Some(input_mass))
    }

    /// A table of an isotropic analytic slope distribution ([`crate::Ggx`], [`crate::Beckmann`],
    /// …) by [`Self::from_radial_fn`] of its `p22(r, 0)`.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] if `slope` is anisotropic (`name = "alpha_y"`: αx ≠ αy, or a
    /// projected roughness on the diagonal that differs from αx, as for a correlated slope), else as
    /// [`Self::from_radial_fn`].
    pub fn from_slope<S: MicrosurfaceSlope>(slope: &S, scale: f32, rings: usize) -> Result<Self, Error> {
        // αx = αy is not enough: a correlated (rotated elliptical) slope has equal marginals
        // and a different αᵢ on the diagonals
        let diagonal = Vec3::new(core::f32::consts::FRAC_1_SQRT_2, core::f32::consts::FRAC_1_SQRT_2, 0.0);
        if slope.alpha_x() != slope.alpha_y()
            || (slope.alpha_i(diagonal) - slope.alpha_x()).abs() > 1e-6 * slope.alpha_x()
        {
            return Err(Error::InvalidParameter {
                name: "alpha_y",
                value: slope.alpha_y(),
                expected: "equal to alpha_x (the table is isotropic)",
            });
        }
        Self::from_radial_fn(scale, rings, |r| f64::from(slope.p22(r as f32, 0.0)))
    }

    pub(super) fn from_ring_values(
        scale: f32,
        mut values: Vec<f64>,
        input_mass: Option<f64>,
    ) -> Result<Self, Error> {
        let s = f64::from(Error::check_positive("scale", scale)?);
        let n = values.len();
        check_ring_count(n)?;
        if let Some(&bad) = values.iter().find(|v| !(v.is_finite() && **v >= 0.0)) {
            return Err(Error::InvalidParameter {
                name: "values[k]",
                value: bad as f32,
                expected: "finite and >= 0",
            });
        }
        let radii: Vec<f64> =
            (0..=n).map(|k| if k == 0 { 0.0 } else { s * grid_angle(k as f64, n).tan() }).collect();
        let ring_area = |k: usize| PI * (radii[k + 1] - radii[k]) * (radii[k + 1] + radii[k]);
        let total: f64 = (0..n).map(|k| values[k] * ring_area(k)).sum();
        if !(total.is_finite() && total > 0.0) {
            return Err(Error::InvalidParameter {
                name: "total mass",
                value: total as f32,
                expected: "finite and > 0 (a table with some mass)",
            });
        }
        for v in &mut values {
            *v /= total;
        }
        let mut mass_prefix = Vec::with_capacity(n + 1);
        let mut acc = 0.0;
        mass_prefix.push(0.0);
        for (k, v) in values.iter().enumerate() {
            acc += v * ring_area(k);
            mass_prefix.push(acc);
        }
        let mut table = Self {
            scale: s,
            divisions: n as f64 + 1.0,
            radii,
            p22: values,
            mass_prefix,
            backface: Vec::new(),
            alpha: 0.0,
            input_mass: input_mass.unwrap_or(total),
        };
        table.backface = (0..=BACKFACE_INTERVALS)
            .map(|j| {
                let u = j as f64 / BACKFACE_INTERVALS as f64;
                table.area_exact(-u, (1.0 - u * u).max(0.0).sqrt())
            })
            .collect();
        table.alpha = (2.0 * table.backface[0]) as f32;
        Ok(table)
    }

    /// The number of rings N.
    #[must_use]
    pub fn rings(&self) -> usize {
        self.p22.len()
    }

    /// The slope scale s of the ring grid.
    #[must_use]
    pub fn scale(&self) -> f32 {
        self.scale as f32
    }

    /// The ring boundaries R₀ = 0 < … < R_N.
    #[must_use]
    pub fn radii(&self) -> &[f64] {
        &self.radii
    }

    /// The normalized ring values pₖ of P²².
    #[must_use]
    pub fn ring_values(&self) -> &[f64] {
        &self.p22
    }

    /// The mass ∫P²² of the input before normalization (for [`Self::from_radial_fn`], the mass
    /// inside R_N: 1 minus the truncated tail for a normalized input).
    #[must_use]
    pub fn input_mass(&self) -> f64 {
        self.input_mass
    }

    /// The GGX-equivalent roughness α = 2·projected_area(horizon) = E|x̃|: the GGX α with the
    /// same projected area at grazing incidence. Reported by `alpha_x`/`alpha_y`.
    #[must_use]
    pub fn alpha(&self) -> f32 {
        self.alpha
    }

    /// The Beckmann roughness with the same second moment, α = √E[x̃² + ỹ²] (E\[r²\] = α² for
    /// Beckmann), computed exactly from the rings: E\[r²\] = Σₖ pₖ π(Rₖ₊₁⁴ − Rₖ⁴)/2 (Dupuy 2015,
    /// Listing 4.4, which converts a radial table to Beckmann roughness by its second moment).
    #[must_use]
    pub fn beckmann_alpha(&self) -> f32 {
        let m2: f64 = self
            .p22
            .iter()
            .zip(self.radii.windows(2))
            .map(|(p, r)| {
                let (a, b) = (r[0] * r[0], r[1] * r[1]);
                p * 0.5 * PI * (b - a) * (b + a)
            })
            .sum();
        m2.sqrt() as f32
    }

    /// The normal angle θₖ = atan(s·tan θ′) of the centre of ring k (θ′ the stretched angle at
    /// k + ½): where [`crate::tabulated::extract_isotropic`] collocates the backscattering samples.
    #[must_use]
    pub fn ring_centre_angle(scale: f32, rings: usize, k: usize) -> f64 {
        (f64::from(scale) * grid_angle(k as f64 + 0.5, rings).tan()).atan()
    }

    /// The ring holding the slope radius r = `horizontal`/`z`, from the stretched angle.
    #[inline]
    fn ring_of(&self, horizontal: f64, z: f64) -> Option<usize> {
        let angle = horizontal.atan2(self.scale * z);
        // invert θ′ = (π/2)(1 − (1 − k/(N+1))²)
        let k = ((1.0 - (1.0 - angle / FRAC_PI_2).max(0.0).sqrt()) * self.divisions) as usize;
        (k < self.p22.len()).then_some(k)
    }

    /// The radial density P²² at slope radius `r` ≥ 0 (f64).
    #[must_use]
    pub fn p22_radial(&self, r: f64) -> f64 {
        if r.is_nan() || r < 0.0 {
            return 0.0;
        }
        self.ring_of(r, 1.0).map_or(0.0, |k| self.p22[k])
    }

    /// The exact projected area ∫⟨ω, ωm⟩₊ D(ωm) dωm of the table for ω = (sin θ, 0, cos θ),
    /// as the closed-form sum over rings (O(N), f64): the reference of the interpolated
    /// [`MicrosurfaceSlope::projected_area`].
    #[must_use]
    pub fn projected_area_exact(&self, w: Vec3) -> f64 {
        let w = w.as_dvec3();
        let h = (w.x * w.x + w.y * w.y).sqrt();
        let len = (h * h + w.z * w.z).sqrt();
        if len.is_nan() || len <= 0.0 {
            return 0.0;
        }
        self.area_exact(w.z / len, h / len)
    }

    fn area_exact(&self, cos_t: f64, sin_t: f64) -> f64 {
        let n = self.p22.len();
        // rings entirely on the visible side contribute cos θ times their mass
        let full = self.fully_visible(cos_t, sin_t);
        let mut area = cos_t.max(0.0) * self.mass_prefix[full];
        let mut prev = disk_area(self.radii[full], cos_t, sin_t);
        for k in full..n {
            let next = disk_area(self.radii[k + 1], cos_t, sin_t);
            area += self.p22[k] * (next - prev);
            prev = next;
        }
        area
    }

    /// The number of rings entirely on the visible side x̃ < cot θ: the k with Rₖ·sin θ ≤ cos θ.
    #[inline]
    fn fully_visible(&self, cos_t: f64, sin_t: f64) -> usize {
        if cos_t <= 0.0 {
            return 0;
        }
        // radii[1..=n] are increasing: count the outer radii inside the visible half plane
        self.radii[1..].partition_point(|&r| r * sin_t <= cos_t)
    }

    /// The back-face area B(u), u ∈ [0, 1]: the exact sum where the visibility line cuts at
    /// most [`EXACT_RINGS`] rings, else interpolated linearly in u.
    #[inline]
    fn backface_at(&self, u: f64) -> f64 {
        let u = u.clamp(0.0, 1.0);
        let (cos_t, sin_t) = (-u, ((1.0 - u) * (1.0 + u)).sqrt());
        // rings with Rₖ₊₁ sin θ ≤ u lie entirely on the invisible side
        let first_cut = self.radii[1..].partition_point(|&r| r * sin_t <= u);
        let n = self.p22.len();
        if n - first_cut <= EXACT_RINGS {
            let mut area = 0.0;
            let mut prev = disk_area(self.radii[first_cut], cos_t, sin_t);
            for k in first_cut..n {
                let next = disk_area(self.radii[k + 1], cos_t, sin_t);
                area += self.p22[k] * (next - prev);
                prev = next;
            }
            return area;
        }
        let t = u * BACKFACE_INTERVALS as f64;
        let j = (t as usize).min(BACKFACE_INTERVALS - 1);
        let frac = t - j as f64;
        self.backface[j] + frac * (self.backface[j + 1] - self.backface[j])
    }

    /// Samples visible slopes (x̃, ỹ) in the frame of ωi = (sin θ, 0, cos θ), exactly, from
    /// two uniforms; `None` if ωi sees no microsurface.
    fn sample_slopes(&self, cos_t: f64, sin_t: f64, u1: f64, u2: f64) -> Option<(f64, f64)> {
        let n = self.p22.len();
        let full = self.fully_visible(cos_t, sin_t);
        let full_mass = cos_t.max(0.0) * self.mass_prefix[full];
        // first pass: the exact total visible mass
        let base = disk_area(self.radii[full], cos_t, sin_t);
        let mut total = full_mass;
        let mut prev = base;
        for k in full..n {
            let next = disk_area(self.radii[k + 1], cos_t, sin_t);
            total += self.p22[k] * (next - prev);
            prev = next;
        }
        if total.is_nan() || total <= 0.0 {
            return None;
        }
        let target = u1 * total;
        // the ring, and the uniform rescaled to it
        let (ring, u) = if target < full_mass {
            let m = target / cos_t;
            let k = (self.mass_prefix[1..=full].partition_point(|&p| p <= m)).min(full - 1);
            let ring_mass = self.mass_prefix[k + 1] - self.mass_prefix[k];
            (k, ((m - self.mass_prefix[k]) / ring_mass).clamp(0.0, 1.0))
        } else {
            let mut acc = full_mass;
            let mut prev = base;
            let mut chosen = None;
            let mut last_positive = None;
            for k in full..n {
                let next = disk_area(self.radii[k + 1], cos_t, sin_t);
                let m = self.p22[k] * (next - prev);
                prev = next;
                if m > 0.0 {
                    last_positive = Some((k, acc, m));
                    if target < acc + m {
                        chosen = Some((k, ((target - acc) / m).clamp(0.0, 1.0)));
                        break;
                    }
                }
                acc += m;
            }
            // rounding can leave target ≥ the recomputed sum: the last ring with mass
            chosen.or_else(|| last_positive.map(|(k, _, _)| (k, 1.0)))?
        };
        let (r1, r2) = (self.radii[ring], self.radii[ring + 1]);
        let x = self.invert_ring_marginal(r1, r2, cos_t, sin_t, u);
        let lo = ((r1 - x.abs()).max(0.0) * (r1 + x.abs())).sqrt();
        let hi = ((r2 - x.abs()).max(0.0) * (r2 + x.abs())).sqrt();
        let s = 2.0 * u2 - 1.0;
        let y = (lo + s.abs() * (hi - lo)).copysign(s);
        Some((x, y))
    }

    /// The x̃ with F(x̃) = u·F(x_max) for the marginal F(x) = ∫_{−R₂}^{x} (cos θ − s sin θ)
    /// (chord(R₂, s) − chord(R₁, s)) ds of the annulus R₁ ≤ r < R₂ on its visible side, by
    /// Newton's method safeguarded by bisection.
    fn invert_ring_marginal(&self, r1: f64, r2: f64, cos_t: f64, sin_t: f64, u: f64) -> f64 {
        let x_max = if cos_t >= r2 * sin_t { r2 } else { cos_t / sin_t };
        let cdf = |x: f64| {
            let outer = partial_disk_integral(r2, x, cos_t, sin_t);
            let inner = if r1 > 0.0 && x > -r1 { partial_disk_integral(r1, x, cos_t, sin_t) } else { 0.0 };
            outer - inner
        };
        let target = u * cdf(x_max);
        let (mut lo, mut hi) = (-r2, x_max);
        let mut x = 0.5 * (lo + hi);
        for _ in 0..MAX_ITERATIONS {
            let f = cdf(x) - target;
            if f > 0.0 {
                hi = x;
            } else {
                lo = x;
            }
            let density = (cos_t - x * sin_t) * (chord(r2, x) - chord(r1, x));
            let mut next = if density > 0.0 { x - f / density } else { f64::NAN };
            if !(next > lo && next < hi) {
                next = 0.5 * (lo + hi);
            }
            let done = (next - x).abs() <= NEWTON_TOLERANCE * r2;
            x = next;
            if done || hi - lo <= NEWTON_TOLERANCE * r2 {
                break;
            }
        }
        x
    }

    /// An exactly sampled visible normal for a unit `wi` (f64 inside).
    fn sample_normal(&self, wi: Vec3, u1: f32, u2: f32) -> Vec3 {
        let w = wi.as_dvec3();
        let azimuth = Azimuth::of(w.x, w.y);
        let h = azimuth.len_xy;
        let len = (h * h + w.z * w.z).sqrt();
        if len.is_nan() || len <= 0.0 {
            return Vec3::Z;
        }
        let Some((x, y)) = self.sample_slopes(w.z / len, h / len, f64::from(u1), f64::from(u2)) else {
            return Vec3::Z;
        };
        // the table is isotropic and unstretched: rotate only
        ensure_visible(wi, azimuth.unstretched_normal(1.0, 1.0, x, y))
    }

    /// D in f64 for a normal with horizontal length `h` and height `z`.
    #[inline]
    fn d_from(&self, h: f64, z: f64) -> f64 {
        if z.is_nan() || z <= 0.0 || !h.is_finite() {
            return 0.0;
        }
        let Some(k) = self.ring_of(h, z) else { return 0.0 };
        // D = P²²/cos⁴θm for a unit normal; for a non-unit one, cos θm = z/‖m‖
        let len2 = h * h + z * z;
        let c2 = z * z / len2;
        self.p22[k] / (c2 * c2)
    }
}

/// The stretched angle θ′ = (π/2)(1 − (1 − k/(N+1))²) of the (fractional) ring boundary `k` of
/// a grid of N = `rings` rings.
pub(super) fn grid_angle(k: f64, rings: usize) -> f64 {
    let v = 1.0 - k / (rings as f64 + 1.0);
    FRAC_PI_2 * (1.0 - v * v)
}

pub(super) fn check_ring_count(rings: usize) -> Result<(), Error> {
    if rings == 0 || rings > MAX_RINGS {
        return Err(Error::InvalidParameter {
            name: "values.len()",
            value: rings as f32,
            expected: "between 1 and MAX_RINGS = 4096 rings",
        });
    }
    Ok(())
}

impl TabulatedSlope {
    /// Visible slopes of the table stretched by 1/α (α = [`TabulatedSlope::alpha`]), seen from
    /// the stretched direction (sin θ, 0, cos θ): the table's exact sampler from the
    /// unstretched direction (sin θ/α, 0, cos θ), its slopes divided by α. The trait's default
    /// `sample_d_wi` composed with this is exact; the override below skips the stretching.
    #[must_use]
    pub fn sample_p22_11(&self, cos_theta: f32, sin_theta: f32, u1: f32, u2: f32) -> Vec2 {
        let a = f64::from(self.alpha);
        let (sx, z) = (f64::from(sin_theta) / a, f64::from(cos_theta));
        let len = (sx * sx + z * z).sqrt();
        if len.is_nan() || len <= 0.0 {
            return Vec2::ZERO;
        }
        match self.sample_slopes(z / len, sx / len, f64::from(u1), f64::from(u2)) {
            Some((x, y)) => Vec2::new((x / a) as f32, (y / a) as f32),
            None => Vec2::ZERO,
        }
    }
}

impl crate::sealed::Sealed for &TabulatedSlope {}

impl MicrosurfaceSlope for &TabulatedSlope {
    #[inline]
    fn alpha_x(&self) -> f32 {
        self.alpha
    }

    #[inline]
    fn alpha_y(&self) -> f32 {
        self.alpha
    }

    /// The ring value pₖ of the slope radius (0 beyond R_N and for NaN slopes).
    #[inline]
    fn p22(&self, slope_x: f32, slope_y: f32) -> f32 {
        let (x, y) = (f64::from(slope_x), f64::from(slope_y));
        self.p22_radial((x * x + y * y).sqrt()) as f32
    }

    /// pₖ/cos⁴θm in f64, rounded (0 for ωm.z ≤ 0 and beyond R_N, which bounds 1/cos θm).
    #[inline]
    fn d(&self, wm: Vec3) -> f32 {
        self.d64_unchecked(wm.as_dvec3()) as f32
    }

    /// As `d`; 0 for a non-finite normal (a debug assertion in debug builds).
    #[inline]
    fn d64_unchecked(&self, wm: DVec3) -> f64 {
        debug_assert!(wm.is_finite(), "d64_unchecked: non-finite normal {wm}");
        if !wm.is_finite() {
            return 0.0;
        }
        self.d_from((wm.x * wm.x + wm.y * wm.y).sqrt(), wm.z)
    }

    /// B(cos θ)/cos θ above the horizon and −1 − B(|cos θ|)/|cos θ| below, B interpolated
    /// from the table (see the type's documentation); saturates to ±`f32::MAX` at ±0. Invalid input
    /// ([policy](crate#invalid-input)): a `w` that is not a unit direction gives NaN.
    #[inline]
    fn lambda_unchecked(&self, w: Vec3) -> f32 {
        let z = f64::from(w.z);
        let b = self.backface_at(z.abs());
        let lambda = (b / z.abs()).min(f64::from(f32::MAX)) as f32;
        if w.z >= 0.0 { lambda } else { -1.0 - lambda }
    }

    /// cos θ + B(cos θ) above the horizon, B(|cos θ|) below (B interpolated). Invalid input
    /// ([policy](crate#invalid-input)): a `w` that is not a unit direction gives NaN.
    #[inline]
    fn projected_area_unchecked(&self, w: Vec3) -> f32 {
        let z = f64::from(w.z);
        let b = self.backface_at(z.abs());
        (if w.z >= 0.0 { z + b } else { b }) as f32
    }

    /// Exact for every ωi (see the type's documentation); +z for ωi = −z. Invalid
    /// input ([policy](crate#invalid-input)): a non-unit ωi or a uniform outside [0, 1] gives NaN.
    #[inline]
    fn sample_d_wi_unchecked(&self, wi: Vec3, u1: f32, u2: f32) -> Vec3 {
        self.sample_normal(wi, u1, u2)
    }
}

/// An anisotropic slope distribution made by stretching a [`TabulatedSlope`] by (sx, sy):
/// P²²(x̃, ỹ) = P²²_table(√((x̃/sx)² + (ỹ/sy)²))/(sx sy), i.e. a tabulated profile with
/// elliptic level sets (the way the analytic GGX and Beckmann become anisotropic; not a general
/// 2D table).
///
/// Everything follows from the table by the stretch (Heitz et al. 2016, supplement §2.1):
/// with ω_s = (sx ω.x, sy ω.y, ω.z), Λ(ω) = Λ_table(ω_s/‖ω_s‖) and the projected area is
/// ‖ω_s‖·area_table(ω_s/‖ω_s‖); visible normals are sampled exactly by sampling the table's
/// visible slopes from ω_s/‖ω_s‖ and scaling them by (sx, sy), since
/// (ω.z − x̃ω.x − ỹω.y)₊ dx̃ dỹ becomes ‖ω_s‖(ŝ.z − uŝ.x − vŝ.y)₊ du dv. `alpha_x` and
/// `alpha_y` report sx·α and sy·α (α = [`TabulatedSlope::alpha`]).
#[derive(Debug, Clone, Copy)]
pub struct StretchedTabulated<'a> {
    table: &'a TabulatedSlope,
    sx: f32,
    sy: f32,
}

impl TabulatedSlope {
    /// The table stretched by (`sx`, `sy`) into an anisotropic distribution.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] if `sx` or `sy` is not finite and > 0.
    pub fn stretched(&self, sx: f32, sy: f32) -> Result<StretchedTabulated<'_>, Error> {
        Ok(StretchedTabulated {
            table: self,
            sx: Error::check_positive("sx", sx)?,
            sy: Error::check_positive("sy", sy)?,
        })
    }
}

impl StretchedTabulated<'_> {
    /// ω_s/‖ω_s‖ and ‖ω_s‖ for ω_s = (sx ω.x, sy ω.y, ω.z), in f64.
    #[inline]
    fn stretch(&self, w: Vec3) -> (Vec3, f64) {
        let s = DVec3::new(
            f64::from(self.sx) * f64::from(w.x),
            f64::from(self.sy) * f64::from(w.y),
            f64::from(w.z),
        );
        let len = s.length();
        if len.is_nan() || len <= 0.0 {
            return (Vec3::Z, 0.0);
        }
        ((s / len).as_vec3(), len)
    }
}

impl crate::sealed::Sealed for StretchedTabulated<'_> {}

impl MicrosurfaceSlope for StretchedTabulated<'_> {
    #[inline]
    fn alpha_x(&self) -> f32 {
        self.sx * self.table.alpha
    }

    #[inline]
    fn alpha_y(&self) -> f32 {
        self.sy * self.table.alpha
    }

    #[inline]
    fn p22(&self, slope_x: f32, slope_y: f32) -> f32 {
        let (x, y) = (f64::from(slope_x) / f64::from(self.sx), f64::from(slope_y) / f64::from(self.sy));
        (self.table.p22_radial((x * x + y * y).sqrt()) / (f64::from(self.sx) * f64::from(self.sy))) as f32
    }

    #[inline]
    fn d(&self, wm: Vec3) -> f32 {
        self.d64_unchecked(wm.as_dvec3()) as f32
    }

    /// P²²(x̃, ỹ)/cos⁴θm in f64; 0 for ωm.z ≤ 0, beyond the table and for a non-finite normal
    /// (a debug assertion).
    #[inline]
    fn d64_unchecked(&self, wm: DVec3) -> f64 {
        debug_assert!(wm.is_finite(), "d64_unchecked: non-finite normal {wm}");
        if !wm.is_finite() || wm.z <= 0.0 {
            return 0.0;
        }
        let (sx, sy) = (f64::from(self.sx), f64::from(self.sy));
        // the stretched normal (m.x/sx, m.y/sy, m.z) has the stretched slopes; D transforms
        // with cos⁴: D(m) = D_table(m′) (cos θm′/cos θm)⁴ /(sx sy) for unit m, m′
        let m = DVec3::new(wm.x / sx, wm.y / sy, wm.z);
        let (lm, lw) = (m.length(), wm.length());
        let d_table = self.table.d_from((m.x * m.x + m.y * m.y).sqrt(), m.z);
        let ratio = (m.z / lm) / (wm.z / lw);
        d_table * ratio.powi(4) / (sx * sy)
    }

    #[inline]
    fn lambda_unchecked(&self, w: Vec3) -> f32 {
        let (s, _) = self.stretch(w);
        (&self.table).lambda(s)
    }

    #[inline]
    fn projected_area_unchecked(&self, w: Vec3) -> f32 {
        let (s, len) = self.stretch(w);
        (len * f64::from((&self.table).projected_area(s))) as f32
    }

    /// Exact for every ωi: the table's visible slopes from ω_s/‖ω_s‖, scaled by (sx, sy); +z
    /// for ωi = −z. Invalid input ([policy](crate#invalid-input)): a non-unit ωi or a uniform
    /// outside [0, 1] gives NaN.
    #[inline]
    fn sample_d_wi_unchecked(&self, wi: Vec3, u1: f32, u2: f32) -> Vec3 {
        let (s, len) = self.stretch(wi);
        if len <= 0.0 {
            return Vec3::Z;
        }
        let m = (&self.table).sample_d_wi(s, u1, u2);
        // the table's normal m ∝ (−u, −v, 1): the slopes scale by (sx, sy)
        let stretched = Vec3::new(m.x * self.sx, m.y * self.sy, m.z);
        ensure_visible(wi, crate::vector::normalize_scaled(stretched, Vec3::Z))
    }
}
