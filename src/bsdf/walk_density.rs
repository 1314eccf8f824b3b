//! The MIS density of the stochastic techniques (random walk, invariance principle,
//! position-free PT and BDPT) on conductors of a tabulated slope family: the exit density of
//! the F = 1 walk, read per call from the shared albedo tables.
//!
//! For mirror facets the directions a walk leaves along do not depend on the Fresnel term (it
//! only weights them): they have the density f₁(ωin, ωout) cos θout of the F = 1 microsurface,
//! which conserves energy. Its single-scattering part is exact,
//! D_ωin(ωh)/(4⟨ωout, ωh⟩) · G2/G1(ωin) (Heitz et al. 2016, eq. 4 and §4); the higher orders,
//! of albedo 1 − E(μin), take the shape of Kulla and Conty 2017,
//! (1 − E(μin))(1 − E(μout)) μout/(π (1 − E_avg)), with E and E_avg the F = 1
//! single-scattering albedos of [`AlbedoTable`](crate::compensation::AlbedoTable). The sum
//! integrates to E(μin) + 1 − E(μin) = 1 over the upper hemisphere, up to the tables'
//! interpolation. Cui et al. 2023 build a multiple-bounce density for MIS in the same spirit;
//! this one is the tables' closed form.
//!
//! Dielectrics, diffuse facets, untabulated slopes (α beyond the tables, tabulated and
//! noncentral slopes) and views or lights below the horizon keep the research layer's
//! density (0.8 × the phase density + 0.2 × a cosine lobe).

use crate::slope::MicrosurfaceSlope;
use core::f32::consts::PI;
use glam::Vec3;

/// The F = 1 walk's exit density of ωout for a walk entering along ωin, both unit and strictly
/// above the horizon, for a slope family with albedo tables; `None` where the tables do not
/// cover the roughness, where single scattering loses no energy, or for other families.
#[inline]
pub(crate) fn walk_exit_density<S: MicrosurfaceSlope>(
    slope: &S,
    walk_in: Vec3,
    walk_out: Vec3,
) -> Option<f32> {
    let (table, alpha) = slope.conductor_albedo()?;
    // √α and the direction axis once for the three lookups
    let row = table.row(alpha)?;
    let lost = 1.0 - row.average();
    if lost.is_nan() || lost <= 0.0 {
        return None;
    }
    let (zi, zo) = (walk_in.z, walk_out.z);
    let (e_in, e_out) = (row.directional(zi), row.directional(zo));
    // G2/G1(ωin) = (1 + Λin)/(1 + Λin + Λout) from the projected areas A = (1 + Λ) cos θ
    let (area_in, area_out) =
        (slope.projected_area_unchecked(walk_in), slope.projected_area_unchecked(walk_out));
    let front = area_in * zo;
    let single =
        slope.reflection_density_unchecked(walk_in, walk_out) * front / (front + zi * (area_out - zo));
    let density = single + (1.0 - e_in) * (1.0 - e_out) * zo / (PI * lost);
    density.is_finite().then_some(density)
}
