//! A tabulated anisotropic slope distribution on a 2D grid of slopes, with exact visible-normal
//! sampling on the whole sphere (Dupuy 2015, thesis §4.2: the anisotropic data-driven
//! microsurface).

use super::radial::{check_ring_count, grid_angle};
use crate::error::Error;
use crate::rng::cut_tails64;
use crate::slope::MicrosurfaceSlope;
use crate::vector::{ensure_visible, normal_from_slopes};
use glam::{DVec3, Vec2, Vec3};

/// Intervals of the back-face area table over v = √(1 − |cos θ|) ∈ [0, 1] (≈ θ/√2 near the
/// poles, where B is small and varies on the scale of the angle).
const AREA_U: usize = 512;
/// Intervals of the back-face area table over φ ∈ [0, 2π).
const AREA_PHI: usize = 128;
/// The most rows a grid has (2 × the largest `half_cells`, 512).
const MAX_ROWS: usize = 1024;
/// The relative margin a sample keeps from a side of its cell beyond which P²² = 0.
const GUARD: f64 = 1.0 / 1_048_576.0;
/// Newton–bisection tolerance (relative to the interval) and iteration cap of the sampler.
const SOLVE_TOLERANCE: f64 = 1e-13;
const SOLVE_ITERATIONS: usize = 100;

/// An anisotropic slope distribution given by a 2D table: P²²(x̃, ỹ) = P_ij on the cell
/// [xᵢ, xᵢ₊₁) × [yⱼ, yⱼ₊₁) of a grid of 2N × 2N cells, and 0 outside.
///
/// # The table
/// Along each axis the boundaries are ±s·tan θ′ₖ, k = 0 … N, with θ′ₖ = (π/2)(1 − (1 − k/(N+1))²)
/// (the ring grid of [`super::TabulatedSlope`] mirrored), scales sx along x̃ and sy along ỹ. The
/// interpolation is piecewise constant (nearest cell); the table is normalized to
/// Σ P_ij Δxᵢ Δyⱼ = 1 (∫D cos θm dωm = 1 exactly). The mean slope need not be zero: a table
/// whose mean slope is not 0 describes a tilted microsurface, for which Λ(−ω) = −1 − Λ(ω) no
/// longer holds; the constructors do not require a centred table, but the identities of the
/// crate's walks assume one (the tests use centred tables).
///
/// # Λ and the projected area
/// The projected area ∫(ω.z − x̃ω.x − ỹω.y)₊ P²² dx̃ dỹ is, for fixed ỹ, a·S0(t) − ω.x·S1(t)
/// with a = ω.z − ỹω.y, t = a/ω.x and S0, S1 the prefix integrals of P and xP along the row: a
/// quadratic in ỹ between the points where t crosses a column boundary, integrated exactly by
/// Simpson's rule ([`GridSlope::projected_area_exact`], O(N) per direction). `lambda` and
/// `projected_area` interpolate bilinearly a precomputed table of the back-face area
/// B(u, φ) = A(−ω) over v = √(1 − u), u = |cos θ| (513 nodes), and φ (128 intervals); Λ = B/cos θ
/// above, −1 − B/|cos θ| below (for a centred table).
///
/// # Sampling
/// Exact, with the two uniforms and no reuse: the first inverts the marginal of ỹ (a
/// piecewise cubic CDF: strip masses by Simpson, then a safeguarded Newton iteration in the
/// strip), the second the conditional of x̃ at that ỹ (a piecewise quadratic CDF along the row:
/// binary search of the prefix sums, then Newton in the cell). Cost O(N) per sample.
///
/// `MicrosurfaceSlope` is implemented for `&GridSlope` (the trait requires `Copy`).
#[derive(Clone)]
pub struct GridSlope {
    /// Column boundaries x₀ < … < x_{2N} and row boundaries y₀ < … < y_{2N}.
    xs: Vec<f64>,
    ys: Vec<f64>,
    /// Normalized cell values, row-major (row j = ỹ cell).
    p: Vec<f64>,
    /// Per row, the prefix integrals of P and xP at the column boundaries (2N + 1 each).
    s0: Vec<f64>,
    s1: Vec<f64>,
    /// The back-face area B at (u = 1 − (i/AREA_U)², φ = k·2π/AREA_PHI), (AREA_U + 1) ×
    /// (AREA_PHI + 1).
    backface: Vec<f64>,
    /// The GGX-equivalent roughnesses 2·projected_area at the horizon along x and y.
    alpha: (f32, f32),
}

impl core::fmt::Debug for GridSlope {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("GridSlope")
            .field("cells", &(self.xs.len() - 1))
            .field("alpha", &self.alpha)
            .finish_non_exhaustive()
    }
}

/// The symmetric boundaries ±s·tan θ′ₖ of a grid with N cells per half axis.
pub(super) fn boundaries(scale: f64, n: usize) -> Vec<f64> {
    let half: Vec<f64> =
        (0..=n).map(|k| if k == 0 { 0.0 } else { scale * grid_angle(k as f64, n).tan() }).collect();
    half.iter().rev().map(|v| -v).chain(half[1..].iter().copied()).collect()
}

/// The index i with v[i] ≤ x < v[i+1] (clamped to the range of cells).
#[inline]
fn cell_of(v: &[f64], x: f64) -> usize {
    v[1..v.len() - 1].partition_point(|&b| b <= x)
}

/// Solves g(x) = target for an increasing g on [lo, hi] by Newton's method safeguarded by
/// bisection (`g` returns the value and the derivative).
fn solve(mut lo: f64, mut hi: f64, target: f64, g: impl Fn(f64) -> (f64, f64)) -> f64 {
    let tol = SOLVE_TOLERANCE * (hi - lo).abs().max(f64::MIN_POSITIVE);
    let mut x = 0.5 * (lo + hi);
    for _ in 0..SOLVE_ITERATIONS {
        let (v, d) = g(x);
        let f = v - target;
        if f > 0.0 {
            hi = x;
        } else {
            lo = x;
        }
        let mut next = if d > 0.0 { x - f / d } else { f64::NAN };
        if !(next > lo && next < hi) {
            next = 0.5 * (lo + hi);
        }
        let done = (next - x).abs() <= tol;
        x = next;
        if done || hi - lo <= tol {
            break;
        }
    }
    x
}

impl GridSlope {
    /// A table from cell values of P²²: `values[j·2N + i]` on the cell (column i, row j) of the
    /// 2N × 2N grid with N = `half_cells` per half axis, scales `scale_x`, `scale_y` (see the
    /// type's documentation). Normalized to unit mass.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] if a scale is not finite and > 0, if `half_cells` is 0 or
    /// above 512 or `values.len()` ≠ (2N)² (`name = "values.len()"`), if a value is NaN,
    /// infinite or negative (`name = "values[k]"`), or if the total mass is zero.
    pub fn from_p22(scale_x: f32, scale_y: f32, half_cells: usize, values: &[f64]) -> Result<Self, Error> {
        let sx = f64::from(Error::check_positive("scale_x", scale_x)?);
        let sy = f64::from(Error::check_positive("scale_y", scale_y)?);
        check_ring_count(half_cells)?;
        if half_cells > 512 || values.len() != 4 * half_cells * half_cells {
            return Err(Error::InvalidParameter {
                name: "values.len()",
                value: values.len() as f32,
                expected: "(2·half_cells)², half_cells ≤ 512",
            });
        }
        if let Some(&bad) = values.iter().find(|v| !(v.is_finite() && **v >= 0.0)) {
            return Err(Error::InvalidParameter {
                name: "values[k]",
                value: bad as f32,
                expected: "finite and >= 0",
            });
        }
        let (xs, ys) = (boundaries(sx, half_cells), boundaries(sy, half_cells));
        let m = 2 * half_cells;
        let mut total = 0.0;
        for j in 0..m {
            for i in 0..m {
                total += values[j * m + i] * (xs[i + 1] - xs[i]) * (ys[j + 1] - ys[j]);
            }
        }
        if !(total.is_finite() && total > 0.0) {
            return Err(Error::InvalidParameter {
                name: "total mass",
                value: total as f32,
                expected: "finite and > 0 (a table with some mass)",
            });
        }
        let p: Vec<f64> = values.iter().map(|v| v / total).collect();
        let mut s0 = Vec::with_capacity(m * (m + 1));
        let mut s1 = Vec::with_capacity(m * (m + 1));
        for j in 0..m {
            let (mut a0, mut a1) = (0.0, 0.0);
            s0.push(0.0);
            s1.push(0.0);
            for i in 0..m {
                let v = p[j * m + i];
                a0 += v * (xs[i + 1] - xs[i]);
                a1 += v * 0.5 * (xs[i + 1] - xs[i]) * (xs[i + 1] + xs[i]);
                s0.push(a0);
                s1.push(a1);
            }
        }
        let mut table = Self { xs, ys, p, s0, s1, backface: Vec::new(), alpha: (0.0, 0.0) };
        let mut backface = Vec::with_capacity((AREA_U + 1) * (AREA_PHI + 1));
        for iu in 0..=AREA_U {
            let v = iu as f64 / AREA_U as f64;
            let u = 1.0 - v * v;
            let s = ((1.0 - u) * (1.0 + u)).sqrt();
            for k in 0..=AREA_PHI {
                let phi = core::f64::consts::TAU * k as f64 / AREA_PHI as f64;
                backface.push(table.area(DVec3::new(s * phi.cos(), s * phi.sin(), -u)));
            }
        }
        table.backface = backface;
        table.alpha = ((2.0 * table.area(DVec3::X)) as f32, (2.0 * table.area(DVec3::Y)) as f32);
        Ok(table)
    }

    /// A table of the slope density `p22(x̃, ỹ)` by its cell averages (4 × 4 Gauss–Legendre
    /// points per cell in the stretched angles), normalized; the mass outside the grid is
    /// dropped.
    ///
    /// # Errors
    /// As [`Self::from_p22`].
    pub fn from_fn(
        scale_x: f32,
        scale_y: f32,
        half_cells: usize,
        p22: impl Fn(f64, f64) -> f64,
    ) -> Result<Self, Error> {
        let sx = f64::from(Error::check_positive("scale_x", scale_x)?);
        let sy = f64::from(Error::check_positive("scale_y", scale_y)?);
        check_ring_count(half_cells)?;
        const GL4: [(f64, f64); 4] = [
            (-0.861_136_311_594_052_6, 0.347_854_845_137_453_9),
            (-0.339_981_043_584_856_3, 0.652_145_154_862_546_1),
            (0.339_981_043_584_856_3, 0.652_145_154_862_546_1),
            (0.861_136_311_594_052_6, 0.347_854_845_137_453_9),
        ];
        let n = half_cells;
        // stretched angles of the boundaries, mirrored
        let angles: Vec<f64> = {
            let half: Vec<f64> = (0..=n).map(|k| grid_angle(k as f64, n)).collect();
            half.iter().rev().map(|v| -v).chain(half[1..].iter().copied()).collect()
        };
        let m = 2 * n;
        let mut values = Vec::with_capacity(m * m);
        for j in 0..m {
            for i in 0..m {
                let (ax, bx) = (angles[i], angles[i + 1]);
                let (ay, by) = (angles[j], angles[j + 1]);
                let mut mass = 0.0;
                for (gx, wx) in GL4 {
                    let tx = 0.5 * (ax + bx) + 0.5 * (bx - ax) * gx;
                    let (x, dx) = (sx * tx.tan(), sx * (1.0 + tx.tan() * tx.tan()));
                    for (gy, wy) in GL4 {
                        let ty = 0.5 * (ay + by) + 0.5 * (by - ay) * gy;
                        let (y, dy) = (sy * ty.tan(), sy * (1.0 + ty.tan() * ty.tan()));
                        let v = p22(x, y);
                        if !(v.is_finite() && v >= 0.0) {
                            return Err(Error::InvalidParameter {
                                name: "values[k]",
                                value: v as f32,
                                expected: "finite and >= 0",
                            });
                        }
                        mass += 0.25 * (bx - ax) * (by - ay) * wx * wy * v * dx * dy;
                    }
                }
                let area = (sx * bx.tan() - sx * ax.tan()) * (sy * by.tan() - sy * ay.tan());
                values.push(mass / area);
            }
        }
        Self::from_p22(scale_x, scale_y, half_cells, &values)
    }

    /// The backscattering direction of the centre of cell (column `i`, row `j`) of the grid of
    /// `half_cells` per half axis: the unit normal whose slopes are the cell centre (in the
    /// stretched angles, as the ring centres of [`super::TabulatedSlope`]), where
    /// [`crate::tabulated::extract_anisotropic`] collocates its samples. Cell k = j·2N + i.
    #[must_use]
    pub fn cell_centre_direction(scale_x: f32, scale_y: f32, half_cells: usize, i: usize, j: usize) -> Vec3 {
        let n = half_cells;
        // the centre of the cell in the stretched angle (wide tail cells are collocated where
        // their angular extent is halved, not at their slope midpoint)
        let centre = |k: usize, s: f64| {
            if k >= n {
                s * grid_angle((k - n) as f64 + 0.5, n).tan()
            } else {
                -s * grid_angle((n - 1 - k) as f64 + 0.5, n).tan()
            }
        };
        let (x, y) = (centre(i, f64::from(scale_x)), centre(j, f64::from(scale_y)));
        DVec3::new(-x, -y, 1.0).normalize().as_vec3()
    }

    /// S0 and S1 of row j at t: ∫_{x<t} P and ∫_{x<t} xP along the row.
    #[inline]
    fn prefix(&self, j: usize, t: f64) -> (f64, f64) {
        let m = self.xs.len() - 1;
        let base = j * (m + 1);
        if t <= self.xs[0] {
            return (0.0, 0.0);
        }
        if t >= self.xs[m] {
            return (self.s0[base + m], self.s1[base + m]);
        }
        let i = cell_of(&self.xs, t);
        let v = self.p[j * m + i];
        let x0 = self.xs[i];
        (self.s0[base + i] + v * (t - x0), self.s1[base + i] + v * 0.5 * (t - x0) * (t + x0))
    }

    /// The marginal density m(ỹ) = ∫(ω.z − x̃ω.x − ỹω.y)₊ P(x̃, ỹ) dx̃ in row j.
    #[inline]
    fn row_density(&self, j: usize, w: DVec3, y: f64) -> f64 {
        let a = w.z - y * w.y;
        let m = self.xs.len() - 1;
        let base = j * (m + 1);
        if w.x == 0.0 {
            return a.max(0.0) * self.s0[base + m];
        }
        let t = a / w.x;
        let (p0, p1) = self.prefix(j, t);
        let v = if w.x > 0.0 {
            a * p0 - w.x * p1
        } else {
            a * (self.s0[base + m] - p0) - w.x * (self.s1[base + m] - p1)
        };
        v.max(0.0)
    }

    /// The mass of row j between y0 and y1 ≤ the row's end, exactly (Simpson on each piece).
    fn row_mass(&self, j: usize, w: DVec3, y0: f64, y1: f64) -> f64 {
        let mut total = 0.0;
        self.for_pieces(j, w, y0, y1, |a, b| {
            total += self.simpson(j, w, a, b);
        });
        total
    }

    /// Simpson's rule for m on [a, b] (exact: m is quadratic there).
    #[inline]
    fn simpson(&self, j: usize, w: DVec3, a: f64, b: f64) -> f64 {
        (b - a) / 6.0
            * (self.row_density(j, w, a)
                + 4.0 * self.row_density(j, w, 0.5 * (a + b))
                + self.row_density(j, w, b))
    }

    /// Calls `f(a, b)` for the consecutive pieces of [y0, y1] between breakpoints of m.
    fn for_pieces(&self, _j: usize, w: DVec3, y0: f64, y1: f64, mut f: impl FnMut(f64, f64)) {
        if y1 <= y0 {
            return;
        }
        // breakpoints: ỹ with ω.z − ỹω.y = xₖ ω.x, i.e. ỹ = (ω.z − xₖω.x)/ω.y (all k; when
        // ω.x = 0 they all coincide with the zero of a)
        if w.y == 0.0 {
            f(y0, y1);
            return;
        }
        // the breakpoints are monotone in k: walk them in order of ỹ
        let m = self.xs.len() - 1;
        let at = |k: usize| (w.z - self.xs[k] * w.x) / w.y;
        let increasing = at(m) >= at(0);
        let mut prev = y0;
        for idx in 0..=m {
            let k = if increasing { idx } else { m - idx };
            let b = at(k);
            if b > prev && b < y1 {
                f(prev, b);
                prev = b;
            }
        }
        f(prev, y1);
    }

    /// The exact projected area ∫(ω.z − x̃ω.x − ỹω.y)₊ P²² dx̃ dỹ for a unit ω (f64, O(N²)
    /// at worst, O(N) typically).
    #[must_use]
    pub fn projected_area_exact(&self, w: Vec3) -> f64 {
        self.area(w.as_dvec3())
    }

    fn area(&self, w: DVec3) -> f64 {
        let m = self.ys.len() - 1;
        (0..m).map(|j| self.row_mass(j, w, self.ys[j], self.ys[j + 1])).sum()
    }

    /// The back-face area B(u, φ) interpolated bilinearly.
    #[inline]
    fn backface_at(&self, u: f64, phi: f64) -> f64 {
        let tu = (1.0 - u.clamp(0.0, 1.0)).sqrt() * AREA_U as f64;
        let iu = (tu as usize).min(AREA_U - 1);
        let fu = tu - iu as f64;
        let tp = phi.rem_euclid(core::f64::consts::TAU) / core::f64::consts::TAU * AREA_PHI as f64;
        let ip = (tp as usize).min(AREA_PHI - 1);
        let fp = tp - ip as f64;
        let row = AREA_PHI + 1;
        let at = |a: usize, b: usize| self.backface[a * row + b];
        let lo = at(iu, ip) + fp * (at(iu, ip + 1) - at(iu, ip));
        let hi = at(iu + 1, ip) + fp * (at(iu + 1, ip + 1) - at(iu + 1, ip));
        lo + fu * (hi - lo)
    }

    /// B for ω: the area seen from (ω.x, ω.y, −|ω.z|).
    #[inline]
    fn backface_of(&self, w: Vec3) -> f64 {
        let phi = f64::from(w.y).atan2(f64::from(w.x));
        self.backface_at(f64::from(w.z).abs(), phi)
    }

    /// Samples visible slopes exactly for a unit ω (uniforms cut at 2⁻²⁴, the crate's tail
    /// policy); `None` if ω sees nothing.
    fn sample_slopes(&self, w: DVec3, u1: f64, u2: f64) -> Option<(f64, f64)> {
        // the crate's tail policy: both quantiles cut at 2⁻²⁴ (u = 0 would put the sample on
        // the visibility line or the grid's edge, where the model has no density)
        let (u1, u2) = (cut_tails64(u1), cut_tails64(u2));
        let m = self.ys.len() - 1;
        // first pass: the row masses (on the stack: at most MAX_ROWS rows) and the total
        let mut masses = [0.0f64; MAX_ROWS];
        let mut total = 0.0;
        for (j, mass) in masses.iter_mut().enumerate().take(m) {
            *mass = self.row_mass(j, w, self.ys[j], self.ys[j + 1]);
            total += *mass;
        }
        if total.is_nan() || total <= 0.0 {
            return None;
        }
        let target = u1 * total;
        // the row
        let mut acc = 0.0;
        let mut chosen = None;
        let mut last = None;
        for (j, &mass) in masses.iter().enumerate().take(m) {
            if mass > 0.0 {
                last = Some(j);
                if target < acc + mass {
                    chosen = Some((j, target - acc));
                    break;
                }
            }
            acc += mass;
        }
        let (j, rest) = chosen.or_else(|| last.map(|j| (j, f64::INFINITY)))?;
        let (y0, y1) = (self.ys[j], self.ys[j + 1]);
        let row_total = masses[j];
        let rest = rest.min(row_total);
        // the piece of the row holding the target, then Newton on the cubic CDF in it
        let mut acc = 0.0;
        let mut piece = (y0, y1, 0.0);
        let mut found = false;
        self.for_pieces(j, w, y0, y1, |a, b| {
            if found {
                return;
            }
            let mass = self.simpson(j, w, a, b);
            if rest < acc + mass || b >= y1 {
                piece = (a, b, rest - acc);
                found = true;
            }
            acc += mass;
        });
        let (a, b, local) = piece;
        let y = solve(a, b, local.max(0.0), |y| (self.simpson(j, w, a, y), self.row_density(j, w, y)));
        // the conditional of x̃ in row j at ỹ: density (c − x̃ω.x)₊ P_j(x̃), c = ω.z − ỹω.y
        let c = w.z - y * w.y;
        let cols = self.xs.len() - 1;
        let row_cdf = |x: f64| -> f64 {
            // ∫_{−∞}^{x} (c − sω.x)₊ P ds
            if w.x == 0.0 {
                return if c > 0.0 { c * self.prefix(j, x).0 } else { 0.0 };
            }
            let t = c / w.x;
            if w.x > 0.0 {
                let e = x.min(t);
                let (p0, p1) = self.prefix(j, e);
                (c * p0 - w.x * p1).max(0.0)
            } else {
                if x <= t {
                    return 0.0;
                }
                let (q0, q1) = self.prefix(j, t);
                let (p0, p1) = self.prefix(j, x);
                (c * (p0 - q0) - w.x * (p1 - q1)).max(0.0)
            }
        };
        let row_end = row_cdf(self.xs[cols]);
        if row_end.is_nan() || row_end <= 0.0 {
            return Some((0.5 * (self.xs[0] + self.xs[cols]), y));
        }
        let tx = u2 * row_end;
        // the column by binary search on the CDF at the boundaries
        let (mut lo, mut hi) = (0usize, cols - 1);
        while lo < hi {
            let mid = (lo + hi) / 2;
            if row_cdf(self.xs[mid + 1]) <= tx {
                lo = mid + 1;
            } else {
                hi = mid;
            }
        }
        let i = lo;
        let x = solve(self.xs[i], self.xs[i + 1], tx, |x| {
            let d = (c - x * w.x).max(0.0) * self.p[j * cols + cell_of(&self.xs, x)];
            (row_cdf(x), d)
        });
        Some(self.clear_of_empty(i, j, x, y))
    }

    /// Keeps a sample (x, y) of cell (i, j) 2⁻²⁰ (relative to the cell or to the slope, the
    /// larger) away from the sides of the cell beyond which P²² = 0 (the grid's edge, an empty
    /// cell), so that the f32 normal of the slopes, within 2⁻²² of them, stays where the model
    /// has density (a shift of the samples within that margin, below the f32 resolution of
    /// the returned normal).
    fn clear_of_empty(&self, i: usize, j: usize, x: f64, y: f64) -> (f64, f64) {
        let m = self.xs.len() - 1;
        let empty = |i: Option<usize>, j: Option<usize>| match (i, j) {
            (Some(i), Some(j)) if i < m && j < m => self.p[j * m + i] <= 0.0,
            _ => true,
        };
        let clear = |lo: f64, hi: f64, v: f64, below: bool, above: bool| {
            let margin = (GUARD * (hi - lo).max(v.abs())).min(0.25 * (hi - lo));
            let v = if below { v.max(lo + margin) } else { v };
            if above { v.min(hi - margin) } else { v }
        };
        let x = clear(
            self.xs[i],
            self.xs[i + 1],
            x,
            empty(i.checked_sub(1), Some(j)),
            empty(Some(i + 1), Some(j)),
        );
        let y = clear(
            self.ys[j],
            self.ys[j + 1],
            y,
            empty(Some(i), j.checked_sub(1)),
            empty(Some(i), Some(j + 1)),
        );
        (x, y)
    }
}

impl GridSlope {
    /// Visible slopes from (sin θ/αx, 0, cos θ) normalized (the stretched direction
    /// unstretched), divided by (αx, αy): consistent with the trait's default `sample_d_wi`
    /// only for directions in the xz plane; [`MicrosurfaceSlope::sample_d_wi`] is overridden
    /// and exact for every direction.
    #[must_use]
    pub fn sample_p22_11(&self, cos_theta: f32, sin_theta: f32, u1: f32, u2: f32) -> Vec2 {
        let (ax, ay) = (f64::from(self.alpha.0), f64::from(self.alpha.1));
        let w = DVec3::new(f64::from(sin_theta) / ax, 0.0, f64::from(cos_theta));
        let Some(w) = w.try_normalize() else { return Vec2::ZERO };
        match self.sample_slopes(w, f64::from(u1), f64::from(u2)) {
            Some((x, y)) => Vec2::new((x / ax) as f32, (y / ay) as f32),
            None => Vec2::ZERO,
        }
    }
}

impl crate::sealed::Sealed for &GridSlope {}

impl MicrosurfaceSlope for &GridSlope {
    #[inline]
    fn alpha_x(&self) -> f32 {
        self.alpha.0
    }

    #[inline]
    fn alpha_y(&self) -> f32 {
        self.alpha.1
    }

    #[inline]
    fn p22(&self, slope_x: f32, slope_y: f32) -> f32 {
        let (x, y) = (f64::from(slope_x), f64::from(slope_y));
        let m = self.xs.len() - 1;
        if !(x >= self.xs[0] && x < self.xs[m] && y >= self.ys[0] && y < self.ys[m]) {
            return 0.0;
        }
        self.p[cell_of(&self.ys, y) * m + cell_of(&self.xs, x)] as f32
    }

    #[inline]
    fn d(&self, wm: Vec3) -> f32 {
        self.d64_unchecked(wm.as_dvec3()) as f32
    }

    /// P_ij/cos⁴θm (0 for ωm.z ≤ 0, outside the grid and for a non-finite normal).
    #[inline]
    fn d64_unchecked(&self, wm: DVec3) -> f64 {
        debug_assert!(wm.is_finite(), "d64: non-finite normal {wm}");
        if !wm.is_finite() || wm.z <= 0.0 {
            return 0.0;
        }
        let (x, y) = (-wm.x / wm.z, -wm.y / wm.z);
        let m = self.xs.len() - 1;
        if !(x >= self.xs[0] && x < self.xs[m] && y >= self.ys[0] && y < self.ys[m]) {
            return 0.0;
        }
        let c2 = wm.z * wm.z / wm.length_squared();
        self.p[cell_of(&self.ys, y) * m + cell_of(&self.xs, x)] / (c2 * c2)
    }

    /// B/cos θ above the horizon, −1 − B/|cos θ| below (B interpolated); ±`f32::MAX` at ±0;
    /// invalid input ([policy](crate#invalid-input)): NaN.
    #[inline]
    fn lambda_unchecked(&self, w: Vec3) -> f32 {
        let b = self.backface_of(w);
        let l = (b / f64::from(w.z).abs()).min(f64::from(f32::MAX)) as f32;
        if w.z >= 0.0 { l } else { -1.0 - l }
    }

    /// cos θ + B above the horizon, B below (B interpolated); invalid input
    /// ([policy](crate#invalid-input)): NaN.
    #[inline]
    fn projected_area_unchecked(&self, w: Vec3) -> f32 {
        let b = self.backface_of(w);
        (if w.z >= 0.0 { f64::from(w.z) + b } else { b }) as f32
    }

    /// Exact for every ωi; +z for ωi = −z. Invalid input ([policy](crate#invalid-input)): a
    /// non-unit ωi or a uniform outside [0, 1] gives NaN.
    fn sample_d_wi_unchecked(&self, wi: Vec3, u1: f32, u2: f32) -> Vec3 {
        let Some(w) = wi.as_dvec3().try_normalize() else { return Vec3::Z };
        match self.sample_slopes(w, f64::from(u1), f64::from(u2)) {
            Some((x, y)) => ensure_visible(wi, normal_from_slopes(x as f32, y as f32)),
            None => Vec3::Z,
        }
    }
}
