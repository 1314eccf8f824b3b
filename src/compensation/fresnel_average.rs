//! F_avg = 2∫₀¹ F(μ) μ dμ, the cosine-weighted average of a conductor's Fresnel term, per RGB
//! channel, from a table over the complex index built once: what a compensated conductor built
//! per hit needs of its Fresnel term, in a few nanoseconds instead of a quadrature.

use super::shared::boxed;
use crate::albedo::node_cell;
use crate::fresnel::ComplexIor;
use crate::special::GAUSS_LEGENDRE_16;
use glam::Vec3;
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
fn base(f0: Vec3) -> Vec3 {
    f0 + (Vec3::ONE - f0) * (1.0 / 21.0)
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

/// The table of residuals, η slowest (one array per η node).
fn table() -> &'static [[f32; NODES]; NODES] {
    static TABLE: OnceLock<Box<[[f32; NODES]; NODES]>> = OnceLock::new();
    TABLE.get_or_init(|| boxed(|i| core::array::from_fn(|j| node(i, j))))
}

/// F_avg = 2∫₀¹ F(μ) μ dμ per RGB channel of the conductor of complex index `ior`: the
/// Schlick-like base F0 + (1 − F0)/21 plus a residual interpolated bilinearly in
/// (u, v) = (η/(1 + η), k/(2 + k)) on 129 × 129 nodes (each by 128-point Gauss–Legendre), built
/// once (about 2 × 10⁶ Fresnel evaluations in f64, a few tens of milliseconds). Error against
/// 1024-point quadrature (the unit test below): at most 2e-5 for the crate's metal presets,
/// 1e-4 for k ≥ 0.3; dielectric-like indices (k < 0.3) up to 2e-3 for η ≥ 1 and 1e-2 for
/// η < 1, where the Fresnel term has a sharp feature at the critical angle (measured 1.1e-5,
/// 8.6e-5, 1.3e-3 and 8.3e-3). A per-hit lookup
/// (two loads of adjacent nodes per channel): a bicubic stencil would be 30 times as accurate
/// for metals at about four times the instructions, for an input of the compensated lobes whose
/// own albedo error against the walk is 2.5e-3 and above.
#[inline]
pub(crate) fn fresnel_average(ior: &ComplexIor) -> Vec3 {
    let (eta, k) = (ior.eta(), ior.k());
    let u = eta / (Vec3::ONE + eta) * LAST;
    let v = k / (Vec3::splat(K_SCALE) + k) * LAST;
    let t = table();
    let residual = |c: usize| {
        let ((i, fu), (j, fv)) = (node_cell(u[c], NODES), node_cell(v[c], NODES));
        let (a, b) = (&t[i], &t[i + 1]);
        let (low, high) = (a[j] + fv * (a[j + 1] - a[j]), b[j] + fv * (b[j + 1] - b[j]));
        low + fu * (high - low)
    };
    (base(ior.normal_reflectance()) + Vec3::new(residual(0), residual(1), residual(2)))
        .clamp(Vec3::ZERO, Vec3::ONE)
}

#[cfg(test)]
mod tests {
    use super::*;

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
            presets = presets.max((fresnel_average(&ior) - exact(ior.eta(), ior.k())).abs().max_element());
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
