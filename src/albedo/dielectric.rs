//! The reflected and transmitted single-scattering albedo tables of dielectric microsurfaces
//! and their interpolation.

use super::axis::{DielectricDirection, log_sqrt_blend};
use super::generated::dielectric as data;
use super::grid::{DIELECTRIC_TABLE_SIZE, EtaRange, MAX_TABULATED_ETA, SideGrids};
use super::table::MAX_TABULATED_ALPHA;

/// The last node index, as a float.
const LAST: f32 = (DIELECTRIC_TABLE_SIZE - 1) as f32;

/// The η-axis coordinate u = ∛((η − 1)/2) ∈ [0, 1] of a relative index η ∈ [1, 3] (η = 1 + 2u³).
#[inline(always)]
fn eta_coordinate(eta_at_least_one: f32) -> f32 {
    ((eta_at_least_one - 1.0) * 0.5).max(0.0).cbrt().min(1.0)
}

/// The roughness-axis coordinate r = B(α) ∈ [0, 1] of α ∈ (0, 1] (the log/√ blend of the
/// direction axis: rows log-spaced at small α, so that the masking feature at μ ≈ α moves by
/// about one direction cell per row).
#[inline(always)]
fn roughness_coordinate(alpha: f32) -> f32 {
    log_sqrt_blend(alpha).min(1.0)
}

/// The fractional node coordinates of a lookup: (x, r, u)·15 on the table of the side of η.
#[inline(always)]
fn node_coordinates(mu: f32, alpha: f32, eta: f32, eta_at_least_one: f32) -> [f32; 3] {
    [
        DielectricDirection::of(eta).coordinate(mu) * LAST,
        roughness_coordinate(alpha) * LAST,
        eta_coordinate(eta_at_least_one) * LAST,
    ]
}

/// The single-scattering albedo of a dielectric interface, split by where the light goes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DielectricAlbedo {
    /// R(μ) = ∫ f_r cos θo dωo over the incident side's hemisphere.
    pub reflected: f32,
    /// T(μ) = ∫ f_t |cos θo| dωo over the other hemisphere, the transmitted flux fraction
    /// (the BTDF of `Transport::Importance`; radiance transport scales it by 1/η²).
    pub transmitted: f32,
}

/// The reflected and transmitted single-scattering albedo of an isotropic dielectric
/// microsurface with height-correlated Smith masking-shadowing and the exact dielectric
/// Fresnel term (the model of [`crate::Dielectric`] with single scattering), tabulated for one
/// slope family and both sides of the interface:
///
/// R(μ) = ∫ D_ωi(ωm) F(ωi·ωm) G2(ωi, ωr)/G1(ωi) dωm,
/// T(μ) = ∫ D_ωi(ωm) (1 − F(ωi·ωm)) G2ᵗ(ωi, ωt)/G1(ωi) dωm,
///
/// with G2 = 1/(1 + Λ(ωi) + Λ(ωr)) for reflection and G2ᵗ = B(1 + Λ(ωi), 1 + Λ(−ωt)) for
/// transmission (Heitz et al. 2016, supplement §3.4; Walter et al. 2007, eqs. 20–21 for the
/// Jacobians), each over the directions that leave on the intended side. 1 − R − T is the
/// energy single scattering loses to the higher orders. At μ = 0 the transmission vanishes
/// (a grazing ray enters only at the top of the surface, and the height-correlated model masks
/// every refraction from there) and R(0) is the Fresnel reflectance averaged over the visible
/// normals.
///
/// **Axes** (16 nodes each, trilinear in (x, r, u); `DESIGN.md`, "Dielectric albedo tables",
/// has the measurements behind them). With the log/√ blend
/// B(v) = ½ ln(v/vf)/ln(1/vf) + ½ (√v − √vf)/(1 − √vf), vf = 1e-6 (B = 0 below vf):
/// - index: the relative index seen by the light is η ∈ [1, 3] from outside and 1/η from
///   inside (so η ∈ [1/3, 3] is covered), on u = ∛((η − 1)/2) (η = 1 + 2u³: the first node
///   at η − 1 = 5.9e-4, where R and the critical cosine change fastest);
/// - roughness: r = B(α) (rows log-spaced at small α, from α = 1e-6 at r = 0; lookups below
///   1e-6 read that row);
/// - direction, from outside: x = B(μ) (the logarithmic half resolves the masking at μ ≈ α
///   and the slow decay of T as μ → 0, the square-root half the Fresnel term in μ; lookups
///   below μ = 1e-6 read the first node);
/// - direction, from inside: the critical cosine μc = √(1 − η²) sits on node 7 in every η
///   row, x = (7/15)(½ B(t) + ½ (1 − √(1 − t))) with t = μ/μc below it and
///   x = 7/15 + (8/15) √((μ − μc)/(1 − μc)) above it, so the onset of total internal
///   reflection is not blended across η rows and 1 − F ∝ √(μ − μc) is linear in x; the row
///   η = 1 of this table holds the limit μc → 0 of the axis (its nodes 0–7 at μ = 0).
///
/// **Accuracy** (measured by the generator, see `DESIGN.md`): nodes within 1e-5 of the exact
/// integral (2 and 3 quadrature panels agree to 7.4e-6 at every 7th node). Between the
/// nodes, measured at 256 pseudo-random points per table and side against quadrature
/// (α ≥ 1e-4, μ concentrated near μ ≈ α as on the conductor's scale-invariant axis):
///
/// | table | R max / RMS | T max / RMS | R + T max / RMS |
/// |---|---|---|---|
/// | GGX, outside | 2.3e-2 / 4.3e-3 | 5.8e-2 / 8.8e-3 | 4.8e-2 / 7.9e-3 |
/// | GGX, inside | 6.2e-2 / 1.4e-2 | 5.6e-2 / 7.9e-3 | 6.2e-2 / 1.5e-2 |
/// | Beckmann, outside | 2.8e-2 / 4.5e-3 | 9.0e-2 / 1.0e-2 | 7.5e-2 / 9.0e-3 |
/// | Beckmann, inside | 1.3e-1 / 1.6e-2 | 7.6e-2 / 1.1e-2 | 1.3e-1 / 1.8e-2 |
///
/// The largest errors sit near η = 1 (where T at large α depends on μ/α alone) and at small
/// μ with α ≈ μ; treat a lookup as uncertain by these maxima, the nodes by 1e-5.
/// # Examples
/// ```
/// use microsurface::compensation::DielectricAlbedoTable;
///
/// // glass (η = 1.5) seen from air at normal incidence, α = 0.25
/// let v = DielectricAlbedoTable::GGX.albedo(1.0, 0.25, 1.5).expect("in range");
/// assert!(v.reflected > 0.03 && v.reflected < 0.06);
/// assert!(v.reflected + v.transmitted < 1.0); // single scattering loses energy
/// // from inside the glass, 1/η
/// assert!(DielectricAlbedoTable::GGX.albedo(0.2, 0.25, 1.0 / 1.5).is_some());
/// assert_eq!(DielectricAlbedoTable::GGX.albedo(1.0, 0.25, 4.0), None); // beyond the table
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DielectricAlbedoTable {
    name: &'static str,
    grids: SideGrids,
}

impl DielectricAlbedoTable {
    /// The GGX (Trowbridge–Reitz) tables.
    pub const GGX: DielectricAlbedoTable = DielectricAlbedoTable {
        name: "ggx",
        grids: SideGrids {
            outside: [&data::GGX_OUTSIDE_REFLECTED, &data::GGX_OUTSIDE_TRANSMITTED],
            inside: [&data::GGX_INSIDE_REFLECTED, &data::GGX_INSIDE_TRANSMITTED],
        },
    };

    /// The Beckmann tables.
    pub const BECKMANN: DielectricAlbedoTable = DielectricAlbedoTable {
        name: "beckmann",
        grids: SideGrids {
            outside: [&data::BECKMANN_OUTSIDE_REFLECTED, &data::BECKMANN_OUTSIDE_TRANSMITTED],
            inside: [&data::BECKMANN_INSIDE_REFLECTED, &data::BECKMANN_INSIDE_TRANSMITTED],
        },
    };

    /// The slope family's name (`"ggx"`, `"beckmann"`).
    #[must_use]
    pub fn name(&self) -> &'static str {
        self.name
    }

    /// R and T at μ = cos θi ∈ [0, 1], α ∈ (0, 1] and the relative index η ∈ [1/3, 3] seen by
    /// the light (η_transmitted side / η_incident side), interpolated.
    ///
    /// Returns `None` outside those ranges (NaN included).
    #[must_use]
    #[inline]
    pub fn albedo(&self, mu: f32, alpha: f32, eta: f32) -> Option<DielectricAlbedo> {
        if !((0.0..=1.0).contains(&mu)
            && alpha > 0.0
            && alpha <= MAX_TABULATED_ALPHA
            && (1.0 / MAX_TABULATED_ETA..=MAX_TABULATED_ETA).contains(&eta))
        {
            return None;
        }
        let (_, eta_ge_1) = self.grids.of(eta);
        let (reflected, transmitted) = self.grids.at(eta, node_coordinates(mu, alpha, eta, eta_ge_1));
        Some(DielectricAlbedo { reflected, transmitted })
    }

    /// The raw node values (R, T) of one side, `values[(l * 16 + j) * 16 + i]` at x = i/15,
    /// r = j/15, u = l/15 on the axes of the type's documentation (η = 1 + 2u³ from outside,
    /// its inverse from inside; the direction axis of the side), for export to shaders.
    #[must_use]
    pub fn nodes(&self, range: EtaRange) -> (&'static [f32], &'static [f32]) {
        self.grids.nodes(range)
    }
}

impl DielectricAlbedoTable {
    /// The fractional roughness node r·15 of α ∈ (0, 1].
    #[inline(always)]
    pub(crate) fn roughness_node(alpha: f32) -> f32 {
        roughness_coordinate(alpha) * LAST
    }

    /// The fractional index node u·15 of η ≥ 1.
    #[inline(always)]
    pub(crate) fn eta_node(eta_at_least_one: f32) -> f32 {
        eta_coordinate(eta_at_least_one) * LAST
    }

    /// The (reflected, transmitted) grids of one side.
    pub(crate) fn grids(&self, range: EtaRange) -> [&'static super::grid::Grid; 2] {
        self.grids.side(range)
    }
}
