//! Data-driven microsurfaces (Dupuy 2015, thesis ch. 4): slope distributions tabulated on
//! rings (isotropic) or on a grid (anisotropic), NDF extraction from measured BRDFs by power
//! iteration, and the MERL BRDF reader.
//!
//! # Design
//!
//! * **A GGX lobe modulated ring by ring.** [`TabulatedSlope`] stores a factor fₖ ≥ 0 per ring
//!   of slope radius on the lobe of GGX(s), s the table's scale: P²²(r) = fₖ·P_GGX(s)(r) on
//!   [Rₖ, Rₖ₊₁). Stretched by 1/s this is a piecewise-constant density of normals on zones of the
//!   hemisphere, which makes Λ's back-face area a closed form per ring and the visible normals
//!   samplable by rejection against tabulated majorants. A GGX of roughness s is every fₖ = 1:
//!   tabulated on 256 rings at s = α, its D is within 2.1e-7 of the analytic one at the ring
//!   centres and Beckmann's within 4.0e-5 (single-scattering albedo within 2e-5 and 1.2e-3).
//! * **The tail beyond the last ring** is a [`Tail`]: `Truncated` (no slopes beyond R_N, the
//!   constructors' default) or `Continued` (the last ring's factor carried on as an r⁻⁴ tail,
//!   exact for GGX). With the continued tail the tabulated GGX's Λ is within 2.3e-8 (relative)
//!   of the analytic one on the whole sphere at N = 256, s = α, and within 1.2e-5 at s = 0.7 α.
//! * **Tables in the hot paths.** `d` is a constant-time ring lookup (the float bits of r²
//!   index a table of ring starts, then one or two boundary comparisons) and a few
//!   multiplications; `lambda` and `projected_area` are GGX(s)'s closed form times a factor
//!   interpolated from 2048 nodes (summed exactly near the poles); `sample_d_wi` is exact: a
//!   proposal from majorants tabulated at about 60 incident directions, corrected by
//!   rejection with the exact ratio (0.78–0.98 of the proposals accepted for a tabulated GGX),
//!   and GGX(s)'s spherical cap for the directions that see only the tail. Construction takes
//!   45 ms and 148 KB at N = 256 (0.7 s and 1.9 MB at [`MAX_RINGS`] = 4096).
//! * **Speed** (criterion medians against GGX α = 0.5, 256 rings, θi = 0.3, 1.4, 2.2, one run
//!   on a shared machine, thread CPU time, load average about 3; the ratios move from run to
//!   run): `d` 10–14 ns, 2.1–2.2× GGX's; `sample_d_wi` 122–145 ns, 2.8–3.0× GGX's spherical cap
//!   (3.6–4.3× in instructions: 760–950 per call against 211–219). [`StretchedTabulated`] adds
//!   the stretch (`d` 14–16 ns, `sample_d_wi` 162–178 ns); the grid's inversion sampler takes
//!   14–15 µs at 2 × 32 cells.
//! * **The grid.** [`GridSlope`] tabulates an anisotropic P²² on 2N × 2N cells; Λ is
//!   interpolated over the incident direction and visible normals are sampled exactly by
//!   inverting the marginal and conditional CDFs, O(N) per sample. [`StretchedTabulated`] is
//!   the anisotropic stretch of a ring table, at the ring table's speed.
//! * **Extraction.** [`extract_isotropic`] and [`extract_anisotropic`] solve the
//!   backscattering eigenproblem by power iteration on the ring (or cell) model itself, and
//!   [`extract_fresnel`] divides the data by the extracted microsurface's ideal-mirror BRDF.
//!   On the crate's single-scattering gold conductor: rings (N = 128, eight iterations) give
//!   F0 within 1e-4 and ring values within 3e-4; F(θd) from the exact slope is within 2e-8,
//!   from a 2 × 24 grid within 2.2 % (F0 1.0 %); a 2 × 20 grid from a MERL file written from
//!   GGX α = 0.5 gets α within 3.3 %, F0 within 1.2 % and F(θd) within 5.0 %.

mod extract;
mod grid;
mod merl;
mod radial;
mod rings;
mod vndf;

pub use extract::{
    BackscatterShadowing, Extraction, GridExtraction, extract_anisotropic, extract_anisotropic_fn,
    extract_fresnel, extract_isotropic, extract_isotropic_fn,
};
pub use grid::GridSlope;
pub use merl::{MERL_PHI_D, MERL_THETA_D, MERL_THETA_H, MerlBrdf, MerlError, half_diff_angles};
pub use radial::{MAX_RINGS, StretchedTabulated, TabulatedSlope, Tail};
