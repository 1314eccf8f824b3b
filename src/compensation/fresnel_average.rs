//! F_avg = 2∫₀¹ F(μ) μ dμ, the cosine-weighted average of a conductor's Fresnel term, per RGB
//! channel, from a table over the complex index built once: what a compensated conductor built
//! per hit needs of its Fresnel term, in a few nanoseconds instead of a quadrature.

use super::shared::boxed;
use crate::albedo::{lane_indices, node_cells};
use crate::fresnel::ComplexIor;
use crate::special::GAUSS_LEGENDRE_16;
use glam::{Vec3A, Vec4};
use std::sync::OnceLock;

/// Nodes per axis of the table.
const NODES: usize = 129;
/// The last node index, as a float.
const LAST: f32 = (NODES - 1) as f32;
/// The scale of the extinction axis: v = k/(K_SCALE + k).
const K_SCALE: f32 = 2.0;

/// Panels of 16-point Gauss–Legendre of the table's nodes.
const PANELS: usize = 8;

/// The unpolarized Fresnel reflectance of one channel (η, k) at cos θ = c ∈ (0, 1], in f64
/// (the expression of [`crate::fresnel::fresnel_conductor`]).
fn reflectance(eta: f64, k: f64, c: f64) -> f64 {
    let c2 = c * c;
    let s2 = 1.0 - c2;
    let t = eta * eta - k * k - s2;
    let a2b2 = (t * t + 4.0 * eta * eta * k * k).sqrt();
    let a = (0.5 * (a2b2 + t)).max(0.0).sqrt();
    let p = a2b2 + c2;
    let q = 2.0 * a * c;
    let r = c2 * a2b2 + s2 * s2;
    ((p - q) * r / ((p + q) * (r + q * s2))).clamp(0.0, 1.0)
}

/// F_avg of one channel by `panels` panels of 16-point Gauss–Legendre, in f64.
pub(crate) fn quadrature(eta: f64, k: f64, panels: usize) -> f64 {
    let h = 1.0 / panels as f64;
    let mut sum = 0.0;
    for panel in 0..panels {
        let mid = (panel as f64 + 0.5) * h;
        for &(x, w) in &GAUSS_LEGENDRE_16 {
            for mu in [mid - 0.5 * h * x, mid + 0.5 * h * x] {
                sum += w * mu * reflectance(eta, k, mu);
            }
        }
    }
    sum * h
}

/// The Schlick-like base the table stores the residual of: F0 + (1 − F0)/21, the average of
/// Schlick's approximation with the exact F0 ([`ComplexIor::normal_reflectance`]).
#[inline(always)]
fn base(f0: Vec3A) -> Vec3A {
    f0 + (Vec3A::ONE - f0) * (1.0 / 21.0)
}

/// The residual F_avg − base at the table's node (i, j): η = u/(1 − u), k = 2v/(1 − v) with
/// (u, v) = (i, j)/64; where η or k is infinite (u or v = 1) or η = 0 the Fresnel term is 1
/// and so is the base: 0.
fn node(i: usize, j: usize) -> f32 {
    let (u, v) = (i as f64 / f64::from(LAST), j as f64 / f64::from(LAST));
    if i == 0 || i == NODES - 1 || j == NODES - 1 {
        return 0.0;
    }
    let eta = u / (1.0 - u);
    let k = f64::from(K_SCALE) * v / (1.0 - v);
    let f0 = ((eta - 1.0).powi(2) + k * k) / ((eta + 1.0).powi(2) + k * k);
    (quadrature(eta, k, PANELS) - (f0 + (1.0 - f0) / 21.0)) as f32
}

/// Cells per axis of the table.
const CELLS: usize = NODES - 1;

/// The residuals of the table, stored for its lookup: for each η cell i and k node j the pair
/// (node(i, j), node(i + 1, j)), j fastest, so that the four corners of a cell (i, j) are four
/// consecutive floats [(i, j), (i + 1, j), (i, j + 1), (i + 1, j + 1)]: one 16-byte load per
/// channel.
#[derive(Debug)]
pub(crate) struct FresnelAverageTable {
    pairs: Box<[f32; CELLS * NODES * 2]>,
}

impl FresnelAverageTable {
    /// The table, built on first use.
    #[inline]
    pub(crate) fn get() -> &'static Self {
        static TABLE: OnceLock<FresnelAverageTable> = OnceLock::new();
        TABLE.get_or_init(|| {
            let nodes: Box<[[f32; NODES]; NODES]> = boxed(|i| core::array::from_fn(|j| node(i, j)));
            Self { pairs: boxed(|n| nodes[n / (2 * NODES) + n % 2][(n / 2) % NODES]) }
        })
    }

    /// F_avg of `ior` per channel: see [`fresnel_average`]. Written for a short dependency chain
    /// (the construction waits on it): the cells' first floats as one product and one sum.
    #[inline(always)]
    pub(crate) fn lookup(&self, ior: &ComplexIor) -> Vec3A {
        let (eta, k) = (ior.eta().extend(0.0), ior.k().extend(0.0));
        let last_cell = Vec4::splat((CELLS - 1) as f32);
        // (u = η/(1 + η) ≤ 1 first: LAST η would overflow for η > f32::MAX/LAST)
        let (iu, fu) = node_cells(eta / (Vec4::ONE + eta) * LAST, last_cell);
        let (iv, fv) = node_cells(k / (Vec4::splat(K_SCALE) + k) * LAST, last_cell);
        // each channel's first float, 2 NODES iu + 2 iv: whole numbers below 2²², exact
        let [s0, s1, s2, _] = lane_indices(iu * (2 * NODES) as f32 + iv * 2.0);
        let [q0, q1, q2] = [s0, s1, s2].map(|n| Vec4::from_slice(&self.pairs[n..n + 4]));
        // the corners of the three channels, lane by lane
        let (a0, b0) = (Vec3A::new(q0.x, q1.x, q2.x), Vec3A::new(q0.y, q1.y, q2.y));
        let (a1, b1) = (Vec3A::new(q0.z, q1.z, q2.z), Vec3A::new(q0.w, q1.w, q2.w));
        let (fu, fv) = (Vec3A::from_vec4(fu), Vec3A::from_vec4(fv));
        let (low, high) = (a0 + fv * (a1 - a0), b0 + fv * (b1 - b0));
        (base(ior.normal_reflectance()) + (low + fu * (high - low))).clamp(Vec3A::ZERO, Vec3A::ONE)
    }
}

/// F_avg = 2∫₀¹ F(μ) μ dμ per RGB channel of the conductor of complex index `ior`: the
/// Schlick-like base F0 + (1 − F0)/21 plus a residual interpolated bilinearly in
/// (u, v) = (η/(1 + η), k/(2 + k)) on 129 × 129 nodes (each by 128-point Gauss–Legendre), built
/// once (about 2 × 10⁶ Fresnel evaluations in f64, a few tens of milliseconds). Error against
/// 1024-point quadrature (the unit test below): at most 2e-5 for the crate's metal presets,
/// 1e-4 for k ≥ 0.3; dielectric-like indices (k < 0.3) up to 2e-3 for η ≥ 1 and 1e-2 for
/// η < 1, where the Fresnel term has a sharp feature at the critical angle (measured 1.1e-5,
/// 8.6e-5, 1.3e-3 and 8.3e-3). A per-hit lookup (one load of a cell's four corners per
/// channel; the coordinates, cells and blends of the three channels in SIMD lanes): a bicubic
/// stencil would be 30 times as accurate for metals at about four times the instructions, for
/// an input of the compensated lobes whose own albedo error against the walk is 2.5e-3 and
/// above.
#[inline]
pub(crate) fn fresnel_average(ior: &ComplexIor) -> Vec3A {
    FresnelAverageTable::get().lookup(ior)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    /// The stated accuracy: the lookup against 64 panels of 16-point Gauss–Legendre, at the
    /// presets and at 4000 pseudo-random indices (η ∈ [0.02, 20], k ∈ [1e-3, 30] log-uniform,
    /// a tenth with k = 0), by region.
    #[test]
    fn lookup_is_within_its_stated_error() {
        let exact = |eta: Vec3, k: Vec3| {
            Vec3::from_array(core::array::from_fn(|c| {
                quadrature(f64::from(eta[c]), f64::from(k[c]), 64) as f32
            }))
        };
        let mut presets: f32 = 0.0;
        for ior in [ComplexIor::GOLD, ComplexIor::COPPER, ComplexIor::ALUMINIUM, ComplexIor::SILVER] {
            presets = presets
                .max((Vec3::from(fresnel_average(&ior)) - exact(ior.eta(), ior.k())).abs().max_element());
        }
        let mut state = 0x853c_49e6_748f_ea9b_u64;
        let mut next = || {
            state = state.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
            (state >> 40) as f32 / (1u64 << 24) as f32
        };
        let (mut metal, mut dielectric, mut internal): (f32, f32, f32) = (0.0, 0.0, 0.0);
        for _ in 0..4000 {
            let eta = (0.02f32.ln() + next() * (20.0f32 / 0.02).ln()).exp();
            let k = if next() < 0.1 { 0.0 } else { (1e-3f32.ln() + next() * (30.0f32 / 1e-3).ln()).exp() };
            let ior = ComplexIor::new(Vec3::splat(eta), Vec3::splat(k)).unwrap();
            let e = (fresnel_average(&ior).x - exact(ior.eta(), ior.k()).x).abs();
            if k >= 0.3 {
                metal = metal.max(e);
            } else if eta >= 1.0 {
                dielectric = dielectric.max(e);
            } else {
                internal = internal.max(e);
            }
        }
        println!(
            "F_avg lookup error: presets {presets:.2e}, k ≥ 0.3 {metal:.2e}, k < 0.3 and η ≥ 1 {dielectric:.2e}, \
             η < 1 {internal:.2e}"
        );
        assert!(presets <= 2e-5 && metal <= 1e-4 && dielectric <= 2e-3 && internal <= 1e-2);
    }
}
