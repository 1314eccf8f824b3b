//! Adaptive quadrature over rectangles of (cos θ, φ) — the equal-area parameterization of the
//! sphere, dω = d(cos θ) dφ.

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
    let whole = gauss(f, z0, z1, p0, p1);
    refine(f, z0, z1, p0, p1, whole, abs_tol, max_depth)
}

#[allow(clippy::too_many_arguments)]
fn refine(
    f: &mut impl FnMut(f64, f64) -> f64,
    z0: f64,
    z1: f64,
    p0: f64,
    p1: f64,
    whole: f64,
    abs_tol: f64,
    depth: u32,
) -> f64 {
    let (zm, pm) = (0.5 * (z0 + z1), 0.5 * (p0 + p1));
    let parts = [
        gauss(f, z0, zm, p0, pm),
        gauss(f, zm, z1, p0, pm),
        gauss(f, z0, zm, pm, p1),
        gauss(f, zm, z1, pm, p1),
    ];
    let sum: f64 = parts.iter().sum();
    if depth == 0 || (sum - whole).abs() <= abs_tol {
        return sum;
    }
    let t = 0.25 * abs_tol;
    refine(f, z0, zm, p0, pm, parts[0], t, depth - 1)
        + refine(f, zm, z1, p0, pm, parts[1], t, depth - 1)
        + refine(f, z0, zm, pm, p1, parts[2], t, depth - 1)
        + refine(f, zm, z1, pm, p1, parts[3], t, depth - 1)
}

/// ∫∫ f over [u_lo, u_hi] × [−π/2, π/2] as the sum of an `nu` × `nv` grid of cells, each
/// refined adaptively to the larger of its share of `abs_tol` and `rel_tol` times its own
/// rough value (cells that hold much mass would otherwise be driven to `max_depth` by the f32
/// rounding of the integrand, ~1e-7 relative). The grid must be fine enough for the adaptive
/// refinement to see every lobe.
#[allow(dead_code, clippy::too_many_arguments)]
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
    use std::f64::consts::{FRAC_PI_2, PI};
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

/// ∫ f(ω) dω over the whole sphere (or the upper hemisphere if `upper_only`), as a sum of
/// adaptively refined cells of a `nz` × `nphi` grid in (cos θ, φ).
pub fn integrate_sphere(
    f: &mut impl FnMut(glam::Vec3) -> f64,
    nz: usize,
    nphi: usize,
    upper_only: bool,
    abs_tol: f64,
    max_depth: u32,
) -> f64 {
    let z_lo = if upper_only { 0.0 } else { -1.0 };
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
