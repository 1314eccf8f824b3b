//! Extraction of a tabulated slope distribution and of a Fresnel term from a BRDF (Dupuy 2015,
//! thesis §4.2: the backscattering eigenproblem solved by power iteration, Algorithms 1–3).

use super::grid::{GridSlope, boundaries};
use super::radial::{TabulatedSlope, check_ring_count, grid_angle, is_isotropic};
use super::rings::RingGrid;
use crate::error::Error;
use crate::slope::MicrosurfaceSlope;
use core::f64::consts::PI;
use glam::{DVec3, Vec3};

/// The masking-shadowing assumed in backscattering (ωi = ωo = o) by the inversion.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BackscatterShadowing {
    /// G(o, o) = G1(o), the monostatic form of the thesis (eq. 4.2), for data that follows
    /// eq. 4.3.
    Monostatic,
    /// G(o, o) = 1/(1 + 2Λ(o)), the height-correlated G2 the crate's single scattering uses
    /// (supplement §3.2). The kernel stays nonnegative: its entries are ∫_ring |cos θo −
    /// x̃ sin θo| dx̃ dỹ.
    HeightCorrelated,
}

/// The result of [`extract_isotropic`].
#[derive(Debug, Clone)]
pub struct Extraction {
    /// The extracted slope distribution (normalized).
    pub slope: TabulatedSlope,
    /// The Perron eigenvalue λ = F0 (the Fresnel reflectance at normal incidence, or the
    /// overall scale of the data), the Rayleigh quotient of the last iterate.
    pub f0: f64,
    /// The relative residual ‖Kp − λp‖₂/‖Kp‖₂ of the iterate after each power iteration
    /// (`residuals[m]` after m + 1 multiplications).
    pub residuals: Vec<f64>,
}

/// Extracts an isotropic slope distribution from backscattering samples by power iteration
/// (Dupuy 2015, §4.2, eqs. 4.5–4.9 and Algorithm 3 with the isotropic kernel of eq. 4.14).
///
/// `backscatter[i]` is f_r(oᵢ, oᵢ) (the BRDF, not times a cosine) at the polar angle
/// θᵢ = [`TabulatedSlope::ring_centre_angle`]`(scale, N, i)`, N = `backscatter.len()`. The slope
/// distribution is the ring table of [`TabulatedSlope`] on the grid of `scale` with N rings
/// (P²² = fⱼ·P_GGX(s) on ring j), collocated at the ring centres: with
/// D(oᵢ) = fᵢ P_GGX(s)(tan θᵢ)/cos⁴θᵢ and G1 = cos θ/A, eq. 4.3 reads F0 fᵢ = Σⱼ Kᵢⱼ fⱼ with
/// Kᵢⱼ = 4 f_r(oᵢ, oᵢ) cos⁵θᵢ aⱼ(θᵢ)/P_GGX(s)(tan θᵢ), where aⱼ(θ) = ∫_ring j (cos θ −
/// x̃ sin θ)₊ P_GGX(s) dx̃ dỹ = cos θ·mⱼ + s sin θ·ΔSⱼ/π (the projected area of ring j in
/// closed form: the φh integral of eq. 4.14 done exactly for the table, mⱼ the ring's GGX(s)
/// mass and ΔSⱼ its back-face area; [`BackscatterShadowing::Monostatic`]) or the integral of
/// |cos θ − x̃ sin θ|, cos θ·mⱼ + 2 s sin θ·ΔSⱼ/π ([`BackscatterShadowing::HeightCorrelated`]).
/// Starting from f = (1, …, 1), `iterations` multiplications by K (each normalized) give the
/// Perron vector; the thesis uses four. Measured on the crate's single-scattering conductor
/// (`tests/tabulated/extraction.rs`, N = 128, s = α, eight iterations): F0 within 1e-4 and the
/// ring values within 3e-4 for GGX and Beckmann at α = 0.2–1 (GGX at s = α is the start f = 1
/// itself; Beckmann's residual falls ×10 per iteration at α = 1, four leave 3e-4).
///
/// Cost: N² closed-form kernel entries and `iterations`·N² multiply-adds (N = 256: see the
/// test `extraction_cost` in `tests/tabulated/extraction.rs`).
///
/// # Errors
/// [`Error::InvalidParameter`] if `scale` is not finite and > 0, if N is 0 or above
/// [`crate::tabulated::MAX_RINGS`], if `iterations` is 0 (`name = "iterations"`), if a sample is NaN,
/// infinite or negative (`name = "backscatter[i]"`), or if the iterate vanishes (all-zero
/// data, `name = "total mass"`).
pub fn extract_isotropic(
    scale: f32,
    backscatter: &[f64],
    iterations: usize,
    shadowing: BackscatterShadowing,
) -> Result<Extraction, Error> {
    let s = f64::from(Error::check_positive("scale", scale)?);
    let n = backscatter.len();
    check_ring_count(n)?;
    check_extraction(backscatter, iterations)?;
    let grid = RingGrid::new(s, n);
    let absolute = shadowing == BackscatterShadowing::HeightCorrelated;
    // the kernel, row-major
    let mut kernel = vec![0.0f64; n * n];
    for (i, row) in kernel.chunks_exact_mut(n).enumerate() {
        let theta = TabulatedSlope::ring_centre_angle(scale, n, i);
        let (sin_t, cos_t) = theta.sin_cos();
        // P_GGX(s)(tan θᵢ) = cos⁴θ′/(π s²), θ′ the ring centre's stretched angle
        let cos_prime = grid_angle(i as f64 + 0.5, n).cos();
        let row_scale = 4.0 * backscatter[i] * cos_t.powi(5) * PI * s * s / cos_prime.powi(4);
        let back_scale = if absolute { 2.0 } else { 1.0 } * s * sin_t / PI;
        grid.for_zones(cos_t / (s * sin_t), 0, |j, ds| {
            if j < n {
                row[j] = row_scale * (cos_t * grid.ggx_mass[j] + back_scale * ds);
            }
        });
    }
    let (f, lambda, residuals) = power_iteration(&kernel, n, iterations)?;
    let slope = TabulatedSlope::from_factors(scale, f)?;
    Ok(Extraction { slope, f0: lambda, residuals })
}

/// Checks the common input of the extractions: at least one iteration, and backscattering
/// samples finite and ≥ 0.
fn check_extraction(backscatter: &[f64], iterations: usize) -> Result<(), Error> {
    if iterations == 0 {
        return Err(Error::InvalidParameter { name: "iterations", value: 0.0, expected: "at least 1" });
    }
    if let Some(&bad) = backscatter.iter().find(|v| !(v.is_finite() && **v >= 0.0)) {
        return Err(Error::InvalidParameter {
            name: "backscatter[i]",
            value: bad as f32,
            expected: "finite and >= 0",
        });
    }
    Ok(())
}

/// [`extract_isotropic`] from a backscattering function `f_r(θo)` (the BRDF at ωi = ωo with
/// polar angle θo), sampled at the ring centres.
///
/// # Errors
/// As [`extract_isotropic`] (a NaN, infinite or negative value of the function is
/// `backscatter[i]`).
pub fn extract_isotropic_fn(
    scale: f32,
    rings: usize,
    iterations: usize,
    shadowing: BackscatterShadowing,
    backscatter: impl Fn(f64) -> f64,
) -> Result<Extraction, Error> {
    Error::check_positive("scale", scale)?;
    check_ring_count(rings)?;
    let values: Vec<f64> =
        (0..rings).map(|i| backscatter(TabulatedSlope::ring_centre_angle(scale, rings, i))).collect();
    extract_isotropic(scale, &values, iterations, shadowing)
}

/// Extracts the Fresnel term F(θd) as the average ratio of the BRDF to the "ideal mirror"
/// microfacet BRDF f_id = D(h) G(i, o)/(4 cos θi cos θo) over the configurations with
/// i·h = cos θd (Dupuy 2015, eq. 4.11 and Algorithm 2), for `bins` values of θd at the bin
/// centres (k + ½)(π/2)/`bins`, for any slope distribution: a [`TabulatedSlope`] from
/// [`extract_isotropic`], a [`GridSlope`] from [`extract_anisotropic`], or an analytic one.
///
/// For each θd the average runs over a midpoint grid of `n_theta_h` × `n_phi` (θh, φd), and,
/// for an anisotropic slope, over `n_phi` azimuths φh of the half vector (an isotropic slope,
/// αx = αy with the same projected roughness on the diagonal, has the same ratio at every φh
/// for an isotropic BRDF: φh = 0 only); the configurations with i or o at or below the horizon,
/// or with f_id = 0, are skipped. G is the height-correlated 1/(1 + Λ(i) + Λ(o)) or, for
/// [`BackscatterShadowing::Monostatic`], the separable G1(i)G1(o). `brdf(i, o)` is the BRDF
/// (not times a cosine) in one channel; a non-finite value skips the configuration (a MERL
/// file's missing data). Returns `None` for a bin where no configuration is valid.
pub fn extract_fresnel<S: MicrosurfaceSlope>(
    slope: S,
    shadowing: BackscatterShadowing,
    bins: usize,
    n_theta_h: usize,
    n_phi: usize,
    brdf: impl Fn(Vec3, Vec3) -> f64,
) -> Vec<Option<f64>> {
    let s = slope;
    let n_phi_h = if is_isotropic(&s) { 1 } else { n_phi };
    (0..bins)
        .map(|b| {
            let theta_d = (b as f64 + 0.5) * 0.5 * PI / bins as f64;
            let (sd, cd) = theta_d.sin_cos();
            let (mut sum, mut count) = (0.0, 0usize);
            for ih in 0..n_theta_h {
                let theta_h = (ih as f64 + 0.5) * 0.5 * PI / n_theta_h as f64;
                let (sh, ch) = theta_h.sin_cos();
                for ia in 0..n_phi_h {
                    // the half-vector frame: h, t = ∂h/∂θh, b = z × h/|…|
                    let phi_h =
                        if n_phi_h == 1 { 0.0 } else { (ia as f64 + 0.5) * 2.0 * PI / n_phi_h as f64 };
                    let (sa, ca) = phi_h.sin_cos();
                    let h = DVec3::new(sh * ca, sh * sa, ch);
                    let t = DVec3::new(ch * ca, ch * sa, -sh);
                    let bt = DVec3::new(-sa, ca, 0.0);
                    for ip in 0..n_phi {
                        let phi = (ip as f64 + 0.5) * 2.0 * PI / n_phi as f64;
                        let i = h * cd + (t * phi.cos() + bt * phi.sin()) * sd;
                        let o = 2.0 * i.dot(h) * h - i;
                        if i.z <= 0.0 || o.z <= 0.0 {
                            continue;
                        }
                        let (i32, o32) = (i.as_vec3(), o.as_vec3());
                        let (li, lo) = (s.lambda64(i32), s.lambda64(o32));
                        let g = match shadowing {
                            BackscatterShadowing::HeightCorrelated => 1.0 / (1.0 + li + lo),
                            BackscatterShadowing::Monostatic => 1.0 / ((1.0 + li) * (1.0 + lo)),
                        };
                        let f_id = s.d64(h) * g / (4.0 * i.z * o.z);
                        if f_id > 0.0 {
                            let v = brdf(i32, o32);
                            if v.is_finite() {
                                sum += v / f_id;
                                count += 1;
                            }
                        }
                    }
                }
            }
            (count > 0).then(|| sum / count as f64)
        })
        .collect()
}

/// ∫∫ over [x0, x1] × [y0, y1] of (ω.z − x̃ω.x − ỹω.y)₊ (`absolute` = false) or of its absolute
/// value: for fixed ỹ the x̃ integral is a closed form, a quadratic in ỹ between the ỹ where the
/// zero line crosses x = x0 or x = x1, integrated exactly by Simpson's rule on each piece.
fn cell_weight(w: DVec3, x0: f64, x1: f64, y0: f64, y1: f64, absolute: bool) -> f64 {
    let row = |y: f64| -> f64 {
        let c = w.z - y * w.y;
        // ∫_{x0}^{x1} (c − x ω.x)₊ dx (and the same of the negative part)
        let lin = |x: f64| c * x - 0.5 * w.x * x * x;
        let full = lin(x1) - lin(x0);
        if w.x == 0.0 {
            return if absolute { full.abs() } else { full.max(0.0) };
        }
        let t = (c / w.x).clamp(x0, x1);
        let (left, right) = (lin(t) - lin(x0), lin(x1) - lin(t));
        // the positive part lies left of t when ω.x > 0, right of it otherwise
        let (pos, neg) = if w.x > 0.0 { (left, -right) } else { (right, -left) };
        if absolute { pos.max(0.0) + neg.max(0.0) } else { pos.max(0.0) }
    };
    let mut cuts = [y0, y1, y1, y1];
    if w.y != 0.0 {
        for (k, x) in [x0, x1].into_iter().enumerate() {
            let y = (w.z - x * w.x) / w.y;
            cuts[k + 1] = if y > y0 && y < y1 { y } else { y1 };
        }
    }
    cuts[1..3].sort_by(f64::total_cmp);
    let mut total = 0.0;
    for k in 0..3 {
        let (a, b) = (cuts[k], cuts[k + 1]);
        if b > a {
            total += (b - a) / 6.0 * (row(a) + 4.0 * row(0.5 * (a + b)) + row(b));
        }
    }
    total
}

/// The result of [`extract_anisotropic`].
#[derive(Debug, Clone)]
pub struct GridExtraction {
    /// The extracted slope distribution (normalized).
    pub slope: GridSlope,
    /// The Perron eigenvalue λ = F0.
    pub f0: f64,
    /// The relative residual after each power iteration (as [`Extraction::residuals`]).
    pub residuals: Vec<f64>,
}

/// Extracts an anisotropic slope distribution on the 2D grid of [`GridSlope`] from
/// backscattering samples by power iteration (Dupuy 2015, §4.2, eqs. 4.5–4.9 and Algorithm 1).
///
/// `backscatter[k]` is f_r(oₖ, oₖ) at the direction oₖ =
/// [`GridSlope::cell_centre_direction`]`(scale_x, scale_y, half_cells, i, j)`, k = j·2N + i.
/// The kernel is collocated at the cell centres with the cell integrals done exactly:
/// Kₖₗ = 4 f_r(oₖ, oₖ) cos⁵θₖ ∫_cell l (oₖ.z − x̃oₖ.x − ỹoₖ.y)₊ dx̃ dỹ (monostatic G1) or with
/// |·| (height-correlated G2), as [`extract_isotropic`]. Cost: (2N)⁴ kernel entries.
///
/// # Errors
/// As [`extract_isotropic`], with `values.len()` ≠ (2N)² also an error, and N above 64.
pub fn extract_anisotropic(
    scale_x: f32,
    scale_y: f32,
    half_cells: usize,
    backscatter: &[f64],
    iterations: usize,
    shadowing: BackscatterShadowing,
) -> Result<GridExtraction, Error> {
    let sx = f64::from(Error::check_positive("scale_x", scale_x)?);
    let sy = f64::from(Error::check_positive("scale_y", scale_y)?);
    check_ring_count(half_cells)?;
    let m = 2 * half_cells;
    if half_cells > 64 || backscatter.len() != m * m {
        return Err(Error::InvalidParameter {
            name: "values.len()",
            value: backscatter.len() as f32,
            expected: "(2·half_cells)², half_cells ≤ 64",
        });
    }
    check_extraction(backscatter, iterations)?;
    let (xs, ys) = (boundaries(sx, half_cells), boundaries(sy, half_cells));
    let n = m * m;
    let absolute = shadowing == BackscatterShadowing::HeightCorrelated;
    let mut kernel = vec![0.0f64; n * n];
    for k in 0..n {
        let (i, j) = (k % m, k / m);
        let o = GridSlope::cell_centre_direction(scale_x, scale_y, half_cells, i, j).as_dvec3().normalize();
        let row_scale = 4.0 * backscatter[k] * o.z.powi(5);
        if row_scale == 0.0 {
            continue;
        }
        for l in 0..n {
            let (a, b) = (l % m, l / m);
            kernel[k * n + l] = row_scale * cell_weight(o, xs[a], xs[a + 1], ys[b], ys[b + 1], absolute);
        }
    }
    let (p, lambda, residuals) = power_iteration(&kernel, n, iterations)?;
    let slope = GridSlope::from_p22(scale_x, scale_y, half_cells, &p)?;
    Ok(GridExtraction { slope, f0: lambda, residuals })
}

/// [`extract_anisotropic`] from a backscattering function `f_r(o)` (the BRDF at ωi = ωo = o).
///
/// # Errors
/// As [`extract_anisotropic`].
pub fn extract_anisotropic_fn(
    scale_x: f32,
    scale_y: f32,
    half_cells: usize,
    iterations: usize,
    shadowing: BackscatterShadowing,
    backscatter: impl Fn(Vec3) -> f64,
) -> Result<GridExtraction, Error> {
    Error::check_positive("scale_x", scale_x)?;
    Error::check_positive("scale_y", scale_y)?;
    check_ring_count(half_cells)?;
    let m = 2 * half_cells;
    let values: Vec<f64> = (0..m * m)
        .map(|k| backscatter(GridSlope::cell_centre_direction(scale_x, scale_y, half_cells, k % m, k / m)))
        .collect();
    extract_anisotropic(scale_x, scale_y, half_cells, &values, iterations, shadowing)
}

/// Power iteration from (1, …, 1): the normalized iterate, its Rayleigh quotient and the
/// relative residual after each multiplication.
fn power_iteration(kernel: &[f64], n: usize, iterations: usize) -> Result<(Vec<f64>, f64, Vec<f64>), Error> {
    let multiply = |p: &[f64], out: &mut [f64]| {
        for (i, o) in out.iter_mut().enumerate() {
            *o = kernel[i * n..(i + 1) * n].iter().zip(p).map(|(k, p)| k * p).sum();
        }
    };
    let mut p = vec![1.0f64; n];
    let mut kp = vec![0.0f64; n];
    let mut residuals = Vec::with_capacity(iterations);
    let mut lambda = 0.0;
    for _ in 0..iterations {
        multiply(&p, &mut kp);
        let norm = kp.iter().map(|v| v * v).sum::<f64>().sqrt();
        if norm.is_nan() || norm <= 0.0 || norm.is_infinite() {
            return Err(Error::InvalidParameter {
                name: "total mass",
                value: norm as f32,
                expected: "finite and > 0 (backscattering data with some energy)",
            });
        }
        for (pi, k) in p.iter_mut().zip(&kp) {
            *pi = k / norm;
        }
        multiply(&p, &mut kp);
        lambda = p.iter().zip(&kp).map(|(a, b)| a * b).sum::<f64>();
        let kp_norm = kp.iter().map(|v| v * v).sum::<f64>().sqrt();
        let res = p.iter().zip(&kp).map(|(a, b)| (b - lambda * a).powi(2)).sum::<f64>().sqrt();
        residuals.push(if kp_norm > 0.0 { res / kp_norm } else { 0.0 });
    }
    Ok((p, lambda, residuals))
}
