//! Adaptive quadrature over rectangles of (cos θ, φ) — the equal-area parameterization of the
//! sphere, dω = d(cos θ) dφ — and the slope-space integrals over the normals visible from a
//! direction (Heitz et al. 2016, supplement §4.2), where sharp lobes are as wide as broad ones.

use glam::Vec3;
use std::f64::consts::{FRAC_PI_2, PI};

/// Nodes and weights of 5-point Gauss–Legendre on [−1, 1].
const GL5: [(f64, f64); 5] = [
    (0.0, 0.568_888_888_888_888_9),
    (-0.538_469_310_105_683_1, 0.478_628_670_499_366_47),
    (0.538_469_310_105_683_1, 0.478_628_670_499_366_47),
    (-0.906_179_845_938_664, 0.236_926_885_056_189_08),
    (0.906_179_845_938_664, 0.236_926_885_056_189_08),
];

/// 5×5 Gauss–Legendre on [z0, z1] × [p0, p1].
fn gauss(f: &mut impl FnMut(f64, f64) -> f64, z0: f64, z1: f64, p0: f64, p1: f64) -> f64 {
    let (zc, zh, pc, ph) = (0.5 * (z0 + z1), 0.5 * (z1 - z0), 0.5 * (p0 + p1), 0.5 * (p1 - p0));
    let mut sum = 0.0;
    for (xi, wi) in GL5 {
        for (xj, wj) in GL5 {
            sum += wi * wj * f(zc + zh * xi, pc + ph * xj);
        }
    }
    sum * zh * ph
}

/// ∫∫ f(cos θ, φ) over the rectangle, refined adaptively: a cell is split in four until the
/// four children agree with their parent within `abs_tol` (scaled to the cell's share) or the
/// depth reaches `max_depth`. Returns the integral.
pub fn integrate(
    f: &mut impl FnMut(f64, f64) -> f64,
    z0: f64,
    z1: f64,
    p0: f64,
    p1: f64,
    abs_tol: f64,
    max_depth: u32,
) -> f64 {
    integrate_refined(f, z0, z1, p0, p1, abs_tol, 0, max_depth)
}

/// [`integrate`] with every cell split `min_depth` times before the adaptive test: for
/// integrands with a jump along a curve (the horizon of a density's support, a cut by a
/// plane), where a thin sliver of a cell can hold the nonzero side while every Gauss node of the
/// cell and its four children falls on the zero side, so that parent and children agree on a
/// wrong value. Forced splits shrink the widest sliver that can be missed by 2^`min_depth`.
#[allow(clippy::too_many_arguments)]
pub fn integrate_refined(
    f: &mut impl FnMut(f64, f64) -> f64,
    z0: f64,
    z1: f64,
    p0: f64,
    p1: f64,
    abs_tol: f64,
    min_depth: u32,
    max_depth: u32,
) -> f64 {
    let whole = gauss(f, z0, z1, p0, p1);
    refine(f, [z0, z1, p0, p1], whole, abs_tol, min_depth, max_depth.max(min_depth))
}

fn refine(
    f: &mut impl FnMut(f64, f64) -> f64,
    [z0, z1, p0, p1]: [f64; 4],
    whole: f64,
    abs_tol: f64,
    min_depth: u32,
    depth: u32,
) -> f64 {
    let (zm, pm) = (0.5 * (z0 + z1), 0.5 * (p0 + p1));
    let cells = [[z0, zm, p0, pm], [zm, z1, p0, pm], [z0, zm, pm, p1], [zm, z1, pm, p1]];
    let parts = cells.map(|[a, b, c, d]| gauss(f, a, b, c, d));
    let sum: f64 = parts.iter().sum();
    if depth == 0 || (min_depth == 0 && (sum - whole).abs() <= abs_tol) {
        return sum;
    }
    let t = 0.25 * abs_tol;
    let min_depth = min_depth.saturating_sub(1);
    cells.iter().zip(parts).map(|(cell, part)| refine(f, *cell, part, t, min_depth, depth - 1)).sum()
}

/// ∫∫ f over [u_lo, u_hi] × [−π/2, π/2] as the sum of an `nu` × `nv` grid of cells, each
/// refined adaptively to the larger of its share of `abs_tol` and `rel_tol` times its own
/// rough value (cells that hold much mass would otherwise be driven to `max_depth` by the f32
/// rounding of the integrand, ~1e-7 relative). The grid must be fine enough for the adaptive
/// refinement to see every lobe.
#[allow(clippy::too_many_arguments)]
pub fn integrate_grid(
    f: &mut impl FnMut(f64, f64) -> f64,
    u_lo: f64,
    u_hi: f64,
    nu: usize,
    nv: usize,
    abs_tol: f64,
    rel_tol: f64,
    max_depth: u32,
) -> f64 {
    let mut total = 0.0;
    for i in 0..nu {
        let u0 = u_lo + (u_hi - u_lo) * i as f64 / nu as f64;
        let u1 = u_lo + (u_hi - u_lo) * (i + 1) as f64 / nu as f64;
        for j in 0..nv {
            let v0 = -FRAC_PI_2 + PI * j as f64 / nv as f64;
            let v1 = -FRAC_PI_2 + PI * (j + 1) as f64 / nv as f64;
            let rough = integrate(f, u0, u1, v0, v1, 0.0, 0).abs();
            let tol = (abs_tol / (nu * nv) as f64).max(rel_tol * rough);
            total += integrate(f, u0, u1, v0, v1, tol, max_depth);
        }
    }
    total
}

/// The part of the sphere [`integrate_sphere`] covers.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Domain {
    /// The whole sphere, cos θ ∈ [−1, 1].
    Sphere,
    /// The upper hemisphere, cos θ ∈ [0, 1].
    UpperHemisphere,
}

/// ∫ f(ω) dω over `domain`, as a sum of adaptively refined cells of a `nz` × `nphi` grid in
/// (cos θ, φ), with the absolute tolerance `abs_tol` shared among the cells.
pub fn integrate_sphere(
    f: &mut impl FnMut(glam::Vec3) -> f64,
    nz: usize,
    nphi: usize,
    domain: Domain,
    abs_tol: f64,
    max_depth: u32,
) -> f64 {
    let z_lo = match domain {
        Domain::Sphere => -1.0,
        Domain::UpperHemisphere => 0.0,
    };
    let mut g = |z: f64, phi: f64| {
        let s = (1.0 - z * z).max(0.0).sqrt();
        f(glam::Vec3::new((s * phi.cos()) as f32, (s * phi.sin()) as f32, z as f32))
    };
    let cells = (nz * nphi) as f64;
    let mut total = 0.0;
    for i in 0..nz {
        let z0 = z_lo + (1.0 - z_lo) * i as f64 / nz as f64;
        let z1 = z_lo + (1.0 - z_lo) * (i + 1) as f64 / nz as f64;
        for j in 0..nphi {
            let p0 = std::f64::consts::TAU * j as f64 / nphi as f64;
            let p1 = std::f64::consts::TAU * (j + 1) as f64 / nphi as f64;
            total += integrate(&mut g, z0, z1, p0, p1, abs_tol / cells, max_depth);
        }
    }
    total
}

// ---------------------------------------------------------------------------------------
// Slope space: the normals visible from a direction
// ---------------------------------------------------------------------------------------

/// The tails of a slope distribution, which choose the coordinates of the slope-space
/// quadratures: where the mass of the conditional cross slope ỹ | x̃ lies.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SlopeTails {
    /// Power-law tails (GGX): ỹ | x̃ spreads as √(1 + x̃²).
    PowerLaw,
    /// Gaussian tails (Beckmann): ỹ ~ N(0, ½) whatever x̃.
    Gaussian,
}

/// A slope distribution whose tails are known to the quadratures (instead of a switch on the
/// type's name).
pub trait SlopeFamily: microsurface::slope::MicrosurfaceSlope {
    /// The tails of the distribution.
    const TAILS: SlopeTails;
}

impl SlopeFamily for microsurface::Ggx {
    const TAILS: SlopeTails = SlopeTails::PowerLaw;
}

impl SlopeFamily for microsurface::Beckmann {
    const TAILS: SlopeTails = SlopeTails::Gaussian;
}

/// The map v ↦ ỹ of the cross coordinate v ∈ (−π/2, π/2) of [`integrate_visible`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CrossMap {
    /// ỹ = √(1 + x̃²) tan v: valid for any distribution, and matched to GGX's conditional.
    Tangent,
    /// ỹ = erf⁻¹(2v/π): matched to a Gaussian cross slope N(0, ½), so that the thin lobes
    /// of Beckmann far from the origin stay resolved.
    Erf,
}

impl SlopeTails {
    /// The cross map matched to these tails.
    pub fn cross_map(self) -> CrossMap {
        match self {
            SlopeTails::PowerLaw => CrossMap::Tangent,
            SlopeTails::Gaussian => CrossMap::Erf,
        }
    }
}

/// The frame of the visible half-plane of `w` in stretched slope space of roughness `a`:
/// (cos φ̃, sin φ̃, u_hi) with u_hi = atan(cot θ̃), or `None` if nothing is visible (w = −z).
pub fn visible_frame(a: (f32, f32), w: Vec3) -> Option<(f64, f64, f64)> {
    let (wx, wy, wz) = (f64::from(w.x) * f64::from(a.0), f64::from(w.y) * f64::from(a.1), f64::from(w.z));
    let h = (wx * wx + wy * wy).sqrt();
    if h > 0.0 {
        Some((wx / h, wy / h, (wz / h).atan()))
    } else if wz > 0.0 {
        Some((1.0, 0.0, FRAC_PI_2))
    } else {
        None
    }
}

/// The cross coordinate v ∈ (−π/2, π/2) of the slopes (x, y): atan(y/√(1 + x²)) for
/// [`CrossMap::Tangent`], (π/2) erf(y) for [`CrossMap::Erf`].
pub fn cross_v(x: f64, y: f64, map: CrossMap) -> f64 {
    match map {
        CrossMap::Erf => FRAC_PI_2 * statrs::function::erf::erf(y),
        CrossMap::Tangent => (y / (1.0 + x * x).sqrt()).atan(),
    }
}

/// The inverse of [`cross_v`] for a given x: (y, dy/dv).
pub fn cross_y(x: f64, v: f64, map: CrossMap) -> (f64, f64) {
    match map {
        CrossMap::Erf => {
            let y = statrs::function::erf::erf_inv(v / FRAC_PI_2);
            (y, (y * y).exp() * std::f64::consts::PI.sqrt() / std::f64::consts::PI)
        }
        CrossMap::Tangent => {
            let sigma = (1.0 + x * x).sqrt();
            (sigma * v.tan(), sigma / (v.cos() * v.cos()))
        }
    }
}

/// The (u, v) coordinates of [`integrate_visible`] of a normal `m` in the visible `frame` of
/// roughness `a` (u may exceed u_hi if m is not visible).
pub fn uv_of(a: (f32, f32), frame: (f64, f64, f64), m: Vec3, map: CrossMap) -> (f64, f64) {
    let (cos_phi, sin_phi, _) = frame;
    let z = f64::from(m.z).max(1e-300);
    let sx = -f64::from(m.x) / z / f64::from(a.0);
    let sy = -f64::from(m.y) / z / f64::from(a.1);
    let x = cos_phi * sx + sin_phi * sy;
    let y = -sin_phi * sx + cos_phi * sy;
    (x.atan(), cross_v(x, y, map))
}

/// Tolerances of [`integrate_visible`].
#[derive(Debug, Clone, Copy)]
pub struct VisibleTolerance {
    /// Absolute adaptive tolerance (for integrals of order 1).
    pub abs_tol: f64,
    /// Relative adaptive tolerance per initial cell (above the f32 rounding of the integrand).
    pub rel_tol: f64,
    /// Maximum refinement depth of each initial cell.
    pub max_depth: u32,
}

/// The tolerances of the visible-normal suites: 1e-7 absolute, 1e-6 relative, depth 8.
pub const VISIBLE_TOLERANCE: VisibleTolerance =
    VisibleTolerance { abs_tol: 1e-7, rel_tol: 1e-6, max_depth: 8 };

/// ∫ g(ωm) dωm over the upper-hemisphere normals visible from `w` (w·ωm > 0, ωm.z > 0), in
/// the slope space of roughness `alpha` stretched to α = 1 and rotated to the azimuth of `w`,
/// where the visible normals are the half-plane x̃ < κ = cot θ̃: mapped by x̃ = tan u and
/// ỹ = `cross_y(x̃, v, map)`, integrated on a 24 × 12 grid of cells refined adaptively
/// ([`integrate_grid`]). `g` gets ωm (f32, unit). Returns 0 if `w` = −z (nothing is visible).
/// Validated against the analytic normalizations in `tests/vndf/normalization.rs`.
pub fn integrate_visible(
    alpha: (f32, f32),
    map: CrossMap,
    w: Vec3,
    tol: VisibleTolerance,
    mut g: impl FnMut(Vec3) -> f64,
) -> f64 {
    let (ax, ay) = (f64::from(alpha.0), f64::from(alpha.1));
    let Some((cos_phi, sin_phi, u_hi)) = visible_frame(alpha, w) else { return 0.0 };
    let lo = -FRAC_PI_2;
    let mut f = |u: f64, v: f64| {
        let (x, dx) = (u.tan(), 1.0 / (u.cos() * u.cos()));
        let (y, dy) = cross_y(x, v, map);
        if !y.is_finite() {
            return 0.0;
        }
        // stretched and rotated slopes → slopes
        let sx = ax * (cos_phi * x - sin_phi * y);
        let sy = ay * (sin_phi * x + cos_phi * y);
        let norm = (1.0 + sx * sx + sy * sy).sqrt();
        let m = Vec3::new((-sx / norm) as f32, (-sy / norm) as f32, (1.0 / norm) as f32);
        let value = g(m);
        if value == 0.0 { 0.0 } else { value * ax * ay * dx * dy / (norm * norm * norm) }
    };
    // an initial grid fine enough that the adaptive refinement sees every lobe
    integrate_grid(&mut f, lo, u_hi, 24, 12, tol.abs_tol, tol.rel_tol, tol.max_depth)
}

/// x(s) and dx/ds of a segment parameterization of the stretched slope x̃.
type SlopeMap = Box<dyn Fn(f64) -> (f64, f64)>;

/// ∫ f(ωm) dωm over the upper hemisphere (ωm.z > 0), in the stretched and rotated slope space
/// of roughness (αx, αy) seen from `wi`, on segments of x̃ with breakpoints at the kinks of
/// the backfacing densities (the peak, the mirror kink at −κ, the V-cavity kinks), for any
/// incident direction including below the horizon. `tails` sets the conditional width of ỹ
/// (Gaussian: 1; power law: √(1 + x̃²)). `f` gets ωm as a unit f32 vector.
///
/// Adaptive, with absolute tolerance `rel_tol` × (a first, coarse estimate of the integral),
/// so that tiny integrals (H near the nadir) are also resolved relatively; at most 3 levels of
/// refinement (deep in backfacing tails the f32 densities carry rounding noise that no
/// refinement removes).
pub fn integrate_upper(
    alpha: (f32, f32),
    tails: SlopeTails,
    wi: Vec3,
    rel_tol: f64,
    mut f: impl FnMut(Vec3) -> f64,
) -> f64 {
    let coarse = integrate_upper_tol(alpha, tails, wi, &mut f, None);
    if coarse == 0.0 {
        return 0.0;
    }
    integrate_upper_tol(alpha, tails, wi, &mut f, Some(rel_tol * coarse.abs()))
}

fn integrate_upper_tol(
    (ax, ay): (f32, f32),
    tails: SlopeTails,
    wi: Vec3,
    f: &mut impl FnMut(Vec3) -> f64,
    tol: Option<f64>,
) -> f64 {
    let gaussian = tails == SlopeTails::Gaussian;
    let (ax, ay) = (f64::from(ax), f64::from(ay));
    let (wx, wy, wz) = (f64::from(wi.x) * ax, f64::from(wi.y) * ay, f64::from(wi.z));
    let h = (wx * wx + wy * wy).sqrt();
    let (cos_phi, sin_phi) = if h > 0.0 { (wx / h, wy / h) } else { (1.0, 0.0) };
    // κ = cot θ̃ (+∞ straight above; everything is invisible straight below)
    let kappa = if h > 0.0 {
        wz / h
    } else if wz > 0.0 {
        f64::INFINITY
    } else {
        f64::NEG_INFINITY
    };
    // x(s) and dx/ds on segments of s, with breakpoints at the kinks
    let (x_of, segments): (SlopeMap, Vec<f64>) = if kappa >= 0.0 {
        // x = tan s on (−π/2, atan κ): the peak at x = 0, the mirror kink at x = −κ
        let hi = kappa.atan();
        let mut b = vec![-FRAC_PI_2, hi];
        for x in [0.0, -kappa, -2.0 * kappa] {
            let s = f64::atan(x);
            if s > -FRAC_PI_2 && s < hi {
                b.push(s);
            }
        }
        b.sort_by(f64::total_cmp);
        (Box::new(|s: f64| (s.tan(), 1.0 / (s.cos() * s.cos()))), b)
    } else if kappa > f64::NEG_INFINITY {
        // x = κ − c tan s, s ∈ (0, π/2): the lobe hugs x = κ (Beckmann) or spreads over |κ|
        // (GGX); kinks at x = 3κ (V-cavity) and edges at x = 2κ, 0
        let k = -kappa;
        let c = if gaussian { 1.0 / (1.0 + 2.0 * k) } else { k.max(1.0) };
        let mut b = vec![0.0, FRAC_PI_2];
        for t in [k, 2.0 * k, 0.5 * k, 4.0 * k] {
            b.push((t / c).atan());
        }
        b.sort_by(f64::total_cmp);
        b.dedup();
        (Box::new(move |s: f64| (kappa - c * s.tan(), c / (s.cos() * s.cos()))), b)
    } else {
        return 0.0;
    };
    let mut g = |s: f64, v: f64| {
        let (x, dx) = x_of(s);
        let sigma = if gaussian { 1.0 } else { (1.0 + x * x).sqrt() };
        let (y, dy) = (sigma * v.tan(), sigma / (v.cos() * v.cos()));
        let sx = ax * (cos_phi * x - sin_phi * y);
        let sy = ay * (sin_phi * x + cos_phi * y);
        let norm = (1.0 + sx * sx + sy * sy).sqrt();
        if !norm.is_finite() {
            return 0.0;
        }
        let m = Vec3::new((-sx / norm) as f32, (-sy / norm) as f32, (1.0 / norm) as f32);
        let value = f(m);
        if value == 0.0 { 0.0 } else { value * ax * ay * dx * dy / (norm * norm * norm) }
    };
    let (per_segment, nv) = (8usize, 12usize);
    let cells = (segments.len() - 1) * per_segment * nv;
    let (cell_tol, depth) = match tol {
        Some(t) => (t / cells as f64, 3),
        None => (f64::INFINITY, 1),
    };
    let mut total = 0.0;
    for w in segments.windows(2) {
        for i in 0..per_segment {
            let s0 = w[0] + (w[1] - w[0]) * i as f64 / per_segment as f64;
            let s1 = w[0] + (w[1] - w[0]) * (i + 1) as f64 / per_segment as f64;
            for j in 0..nv {
                let v0 = -FRAC_PI_2 + PI * j as f64 / nv as f64;
                let v1 = -FRAC_PI_2 + PI * (j + 1) as f64 / nv as f64;
                total += integrate(&mut g, s0, s1, v0, v1, cell_tol, depth);
            }
        }
    }
    total
}
