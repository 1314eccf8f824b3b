//! Energy-compensated conductors: the single-scattering microfacet BRDF plus the energy of the
//! higher orders restored from the single-scattering albedo tables ([`AlbedoTable`]), with a
//! deterministic eval, an exact pdf and a sampler (Kulla and Conty 2017; Turquin 2019).

pub(crate) use super::shared::{ONE_MINUS_ULP, Tables, check_tabulated, mixture_sample};

use super::lobe_profile::{
    DirectionAxis, MixtureTable, MuProfile, mu_cell_centre, mu_cell_masses, profile_average, row_at,
};
use crate::albedo::{
    ALBEDO_TABLE_SIZE, AlbedoTable, DielectricAlbedoTable, LAST_TABULATED_ORDER, ORDER_TABLES,
    ScatteringOrderTable, node_cell,
};
use crate::bsdf::{Bsdf, BsdfFlags, BsdfSample, BsdfValue, valid_direction, valid_uniforms};
use crate::bsdf::{MicrofacetBsdf, Technique};
use crate::error::Error;
use crate::material::Conductor;
use crate::single_scattering::SingleScattering;
use crate::slope::{AxisAlignedSlope, Beckmann, Elliptical, Ggx, MicrosurfaceSlope};
use glam::{DVec3, Vec2, Vec3};

/// The conductor tables' direction axis (32 nodes).
type Axis = DirectionAxis<ALBEDO_TABLE_SIZE>;

/// The last node index of the tables, as a float.
const LAST: f32 = (ALBEDO_TABLE_SIZE - 1) as f32;

/// 16-point Gauss–Legendre nodes and weights on [−1, 1] (positive half; symmetric).
const GL16: [(f64, f64); 8] = [
    (0.095_012_509_837_637_44, 0.189_450_610_455_068_5),
    (0.281_603_550_779_258_9, 0.182_603_415_044_923_6),
    (0.458_016_777_657_227_4, 0.169_156_519_395_002_5),
    (0.617_876_244_402_643_7, 0.149_595_988_816_576_7),
    (0.755_404_408_355_003, 0.124_628_971_255_533_9),
    (0.865_631_202_387_831_7, 0.095_158_511_682_492_78),
    (0.944_575_023_073_232_6, 0.062_253_523_938_647_89),
    (0.989_400_934_991_649_9, 0.027_152_459_411_754_1),
];

/// Panels of 16-point Gauss–Legendre for F_avg = 2∫F(μ)μ dμ: the conductor Fresnel term is
/// smooth on [0, 1] (its grazing dip has a width of ≈ 0.1 in μ for aluminium), and 4 panels
/// agree with 64 to 1e-7 for the crate's presets (`tests/compensated.rs`).
const FRESNEL_PANELS: usize = 4;

/// A slope family with single-scattering albedo tables: the families a
/// [`CompensatedConductor`] and a [`super::CompensatedDielectric`] can be built on.
pub trait AlbedoTabulated: MicrosurfaceSlope {
    /// The family's conductor tables (F = 1).
    const ALBEDO: AlbedoTable;
    /// The family's dielectric tables (reflected and transmitted, both sides).
    const DIELECTRIC_ALBEDO: DielectricAlbedoTable;
    /// The family's per-order energies of the F = 1 walk.
    const ORDERS: ScatteringOrderTable;

    /// The isotropic roughness the tables are read at: √(αx αy), the geometric mean of the
    /// principal radii (for an [`Elliptical`](crate::Elliptical) slope √(α₁ α₂), which is
    /// invariant under its rotation).
    #[inline]
    fn albedo_alpha(&self) -> f32 {
        (self.alpha_x() * self.alpha_y()).sqrt()
    }
}

impl AlbedoTabulated for Ggx {
    const ALBEDO: AlbedoTable = AlbedoTable::GGX;
    const DIELECTRIC_ALBEDO: DielectricAlbedoTable = DielectricAlbedoTable::GGX;
    const ORDERS: ScatteringOrderTable = ScatteringOrderTable::GGX;
}

impl AlbedoTabulated for Beckmann {
    const ALBEDO: AlbedoTable = AlbedoTable::BECKMANN;
    const DIELECTRIC_ALBEDO: DielectricAlbedoTable = DielectricAlbedoTable::BECKMANN;
    const ORDERS: ScatteringOrderTable = ScatteringOrderTable::BECKMANN;
}

impl<S: AxisAlignedSlope + AlbedoTabulated> AlbedoTabulated for Elliptical<S> {
    const ALBEDO: AlbedoTable = S::ALBEDO;
    const DIELECTRIC_ALBEDO: DielectricAlbedoTable = S::DIELECTRIC_ALBEDO;
    const ORDERS: ScatteringOrderTable = S::ORDERS;

    /// √(α₁ α₂): the compensated lobe of the rotated ellipse is that of the axis-aligned one.
    #[inline]
    fn albedo_alpha(&self) -> f32 {
        self.axis_aligned().albedo_alpha()
    }
}

/// How a [`CompensatedConductor`] restores the energy single scattering loses.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Compensation {
    /// Kulla and Conty 2017 (*Revisiting Physically Based Shading at Imageworks*): an additive,
    /// reciprocal lobe
    ///
    /// f_ms(ωo, ωi) = F_ms (1 − E(μo)) (1 − E(μi)) / (π (1 − E_avg)),
    /// F_ms = F_avg² E_avg / (1 − F_avg (1 − E_avg)),
    ///
    /// with F_avg = 2∫₀¹ F(μ) μ dμ per RGB channel (the geometric series of the paper's
    /// "coloured" multiple scattering: each further bounce is weighted by F_avg and escapes with
    /// E_avg). For F = 1 its albedo is exactly 1 − E(μo), so f_ss + f_ms conserves energy.
    #[default]
    KullaConty,
    /// Turquin 2019 (*Practical multiple scattering compensation for microfacet models*, ILM
    /// technical report, eq. for conductors): the single-scattering lobe scaled by
    ///
    /// 1 + F0 (1 − E(μo)) / E(μo),
    ///
    /// with F0 = F(1) the conductor's reflectance at normal incidence per RGB channel and E of
    /// the **view direction** ωo (as the report prescribes): for F = 1 the albedo is exactly 1,
    /// the lobe keeps the single-scattering shape, and it is not reciprocal.
    Turquin,
    /// A reciprocal additive lobe whose energy per RGB channel is the walk's per-order model
    /// of the energy single scattering leaves out ([`ScatteringOrderTable`]):
    ///
    /// f_ms(ωo, ωi) = g(μo) g(μi) / (π ḡ),   ḡ = 2∫₀¹ g(μ) μ dμ,
    /// g(μ) = (1 − E(μ)) Σ_k e_k(μ) F̄^k / Σ_k e_k(μ),   F̄ = F_avg,
    ///
    /// per channel, with e_k the F = 1 walk's energy of order k = 2 … 6 and the tail (weighted
    /// as the geometric continuation of orders 6 and above: e_6 F̄⁶ ρF̄/(1 − ρF̄),
    /// ρ = e_tail/(e_6 + e_tail), which is e_tail at F̄ = 1; where the walk recorded e_6 = 0
    /// and a tail, the tail is placed at order 7, e_tail F̄⁷). Its albedo is exactly g(μo): the
    /// energy of each order k weighted by F̄ᵏ (each bounce reflects F_avg), the split of
    /// 1 − E(μ) between the orders taken from the walk instead of Kulla and Conty's
    /// geometric series in E_avg. For F = 1 it is [`Compensation::KullaConty`].
    PerOrder,
}

/// A conductor microfacet BRDF with energy compensation: the exact single-scattering lobe of
/// [`MicrofacetBsdf`] (height-correlated Smith, [`Technique::SingleScattering`]) plus the
/// energy of the higher orders restored by a [`Compensation`] scheme from this crate's albedo
/// tables. Deterministic: `eval` is exact (of this model), `pdf` is the exact density of
/// `sample`, and a sample's weight is f·cos θi/pdf at its direction.
///
/// **Tables.** E(μ) is the slope family's [`AlbedoTable`] at α = √(αx αy) (anisotropic
/// surfaces are compensated as the isotropic surface of the same slope area: an
/// approximation that restores only about half of the missing energy, measured by
/// `lab --bin compensation`: GGX F = 1, αx = 0.2, αy = 0.8 still lacks up to 0.20 of albedo,
/// against 0.40 for single scattering), interpolated as the table does: the two
/// roughness rows are blended once at construction and the direction axis is interpolated
/// linearly at run time. The lobe interpolates the complements 1 − E of the nodes (exact in
/// f32), so that 1 − E keeps its relative precision where E → 1. E_avg is **not** the shipped
/// E_avg table but the exact cosine-weighted average of the interpolated E at this α (a closed
/// form per cell, in f64), so that the Kulla–Conty lobe integrates to exactly F_ms (1 − E(μo))
/// over the hemisphere: the white furnace then errs only by the table's interpolation error
/// E_exact(μo) − E_table(μo) (at most 1.2e-3 for GGX and 3.7e-3 for Beckmann; Turquin's scaled
/// lobe by that error divided by E(μo)).
///
/// **Sampling** (Kulla–Conty and per-order): with probability p = E(μo) (the energies of the
/// two lobes for F = 1; E here taken at the centre of μo's cell on a uniform μ axis of 32
/// cells, so that the lookup is one multiply and one truncation, any p ∈ (0, 1] giving an exact
/// mixture) the caller's u drives the exact visible-normal sample of the single-scattering
/// lobe, otherwise u samples the added lobe's profile (1 − E(μi)) μi by cells of the uniform μ
/// axis: a density ρ(μi²) μi/π continuous and linear in μi² on each cell, a cell chosen by its
/// mass with the alias method (no search), μi² within it by inverting the line, φ uniform. The
/// density is the mixture pdf = p pdf_ss + (1 − p) ρ(μi²) μi/π, exact, the same bits in `pdf`,
/// `eval_with_pdf` and the sample. In the added lobe's branch single scattering's f·cos θi is
/// taken in its sampler's form F G2/G1 · pdf_ss (within 1e-5 of eval's, as its sampler's
/// weight is). Turquin samples and has the density of the single-scattering lobe.
///
/// **Special cases.** Effectively smooth surfaces (largest principal roughness [`MicrosurfaceSlope::alpha_max`](crate::slope::MicrosurfaceSlope::alpha_max) < [`crate::SMOOTH_ALPHA`]) are
/// the Dirac mirror of the single-scattering BSDF, uncompensated (the energy the single
/// bounce loses vanishes with α). View directions below the horizon (a backfacing shading
/// normal, which single scattering supports) have no tabulated albedo: the lobe is then the
/// single-scattering lobe alone; so is it for light directions below the horizon.
///
/// **Cost.** Construction integrates F_avg (64 Fresnel evaluations) and the average (31 cells;
/// the per-order scheme three more and the blend of six order tables): a few microseconds;
/// build the BSDF once per material, it is `Copy`. Eval adds to the single-scattering eval one
/// (Turquin) or two (Kulla–Conty, per-order, sharing one division) branch-free lookups of the
/// direction axis; pdf two lookups of the uniform μ axis (no division, no root); sample the
/// direction-axis lookups of eval and the uniform-μ lookups of pdf (measured in `README.md`).
///
/// **Per-order** ([`Compensation::PerOrder`]) restores each channel's energy from the walk's
/// per-order energies ([`ScatteringOrderTable`], standard error ≤ 1.95e-3 per node) instead of
/// Kulla and Conty's series in E_avg: for F = 1 it is the Kulla–Conty lobe; for coloured metals
/// it follows the walk where the series does not (GGX gold, copper, aluminium at α = 1: albedo
/// within 0.5 % of the walk against 3–4 % for Kulla–Conty, `lab --bin compensation`), but its
/// F̄ = F_avg per bounce misses the grazing-facet Fresnel of the higher orders for grazing views
/// at small α (gold at α = 0.1, μo = 0.1: 3 % low, as Kulla–Conty).
///
/// # Examples
/// ```
/// use microsurface::glam::{Vec2, Vec3};
/// use microsurface::{Bsdf, CompensatedConductor, Compensation, ComplexIor, Conductor, Ggx};
///
/// let gold = CompensatedConductor::new(Ggx::isotropic(0.6)?, Conductor::new(ComplexIor::GOLD), Compensation::KullaConty)?;
/// let wo = Vec3::new(0.5, 0.0, 0.866);
/// let s = gold.sample(wo, 0.3, Vec2::new(0.6, 0.1)).expect("gold reflects");
/// let (f, pdf) = gold.eval_with_pdf(wo, s.wi);
/// assert!(f.exact && (pdf - s.pdf).abs() <= 1e-6 * pdf);
/// // reciprocal
/// let back = gold.eval(s.wi, wo).f;
/// assert!((back - f.f).abs().max_element() <= 1e-4 * f.f.max_element());
/// // beyond the tables
/// assert!(CompensatedConductor::new(Ggx::isotropic(1.5)?, Conductor::perfect(), Compensation::Turquin).is_err());
/// # Ok::<(), microsurface::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CompensatedConductor<S> {
    single: MicrofacetBsdf<S, Conductor>,
    scheme: Compensation,
    /// The tables' roughness √(αx αy).
    alpha: f32,
    /// Whether the scheme has an additive lobe with energy (Kulla–Conty or per-order, not
    /// a mirror, 1 − E_avg > 0): its sampler is a mixture.
    mixing: bool,
    /// The tables' direction axis at this α.
    axis: Axis,
    /// The probabilities (p, 1 − p) of the single-scattering lobe and the added lobe in the
    /// sampling mixture, per cell of the view's uniform μ axis (p = E(μ) at the cell's centre).
    mixture: MixtureTable<2>,
    /// 1 − E at the direction nodes x = i/31, for this α.
    complement: [f32; ALBEDO_TABLE_SIZE],
    /// 1 − E_avg of the interpolated E.
    complement_average: f64,
    /// The sampler of the added lobes' μi profile (1 − E(μi)) μi on the uniform μ axis.
    profile: MuProfile,
    /// The additive lobe as a product h(μo) h(μi) per channel: h at the direction nodes
    /// (Kulla–Conty: √(F_ms/(π (1 − E_avg))) (1 − E); per order: g/√(π ḡ)).
    lobe: [Vec3; ALBEDO_TABLE_SIZE],
    /// ∫ h(μi) μi dωi per channel: the additive lobe's albedo at μo is h(μo) times this.
    lobe_norm: Vec3,
    /// F_avg per channel.
    fresnel_average: Vec3,
    /// F0 per channel.
    fresnel_normal: Vec3,
    /// F_ms per channel.
    fresnel_ms: Vec3,
    /// Kulla–Conty: F_ms/(π (1 − E_avg)); Turquin: F0.
    scale: Vec3,
}

impl<S: AlbedoTabulated> CompensatedConductor<S> {
    /// The compensated BRDF of a conductor on the given slopes.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] (`"alpha"`) if √(αx αy) > [`MAX_TABULATED_ALPHA`](crate::compensation::MAX_TABULATED_ALPHA) (= 1), the
    /// tables' range: there is no albedo to compensate with beyond it.
    pub fn new(slope: S, conductor: Conductor, scheme: Compensation) -> Result<Self, Error> {
        let alpha = slope.albedo_alpha();
        // the slope's roughnesses are finite and > 0; their product may overflow to ∞ (rejected)
        check_tabulated(alpha, None, Tables::Albedo)?;
        let single = MicrofacetBsdf::new(slope, conductor)?.with_technique(Technique::SingleScattering);
        // a Dirac mirror is not compensated (and √(αx αy) may underflow to 0 there)
        let (complement, complement_average, profile) = if single.is_specular() {
            ([0.0; ALBEDO_TABLE_SIZE], 0.0, MuProfile::EMPTY)
        } else {
            let c = blended_complement(&S::ALBEDO, alpha);
            (c, profile_average(&c, alpha), MuProfile::new(&mu_cell_masses(&c, alpha)))
        };
        let fresnel_average = fresnel_average(&conductor);
        let fresnel_normal = conductor.fresnel(1.0);
        let e_avg = 1.0 - complement_average;
        let f_avg = fresnel_average.as_dvec3();
        // F_avg² E_avg / (1 − F_avg (1 − E_avg)); the denominator is ≥ E_avg > 0
        let fresnel_ms = (f_avg * f_avg * e_avg / (DVec3::ONE - f_avg * complement_average)).as_vec3();
        let scale = match scheme {
            // no energy lost (every node of the row is 1): nothing to restore
            Compensation::KullaConty | Compensation::PerOrder if complement_average <= 0.0 => Vec3::ZERO,
            Compensation::KullaConty | Compensation::PerOrder => {
                (fresnel_ms.as_dvec3() / (core::f64::consts::PI * complement_average)).as_vec3()
            }
            Compensation::Turquin => fresnel_normal,
        };
        let lobe = match scheme {
            Compensation::Turquin => [Vec3::ZERO; ALBEDO_TABLE_SIZE],
            Compensation::KullaConty => {
                let root = scale.as_dvec3().map(f64::sqrt);
                core::array::from_fn(|i| (root * f64::from(complement[i])).as_vec3())
            }
            Compensation::PerOrder if single.is_specular() || complement_average <= 0.0 => {
                [Vec3::ZERO; ALBEDO_TABLE_SIZE]
            }
            Compensation::PerOrder => per_order_lobe(&S::ORDERS, alpha, &complement, f_avg),
        };
        let lobe_norm = match scheme {
            Compensation::Turquin => Vec3::ZERO,
            _ => {
                let mut norm = DVec3::ZERO;
                for c in 0..3 {
                    let h: [f32; ALBEDO_TABLE_SIZE] = core::array::from_fn(|i| lobe[i][c]);
                    norm[c] = core::f64::consts::PI * profile_average(&h, alpha);
                }
                norm.as_vec3()
            }
        };
        let axis = Axis::new(alpha);
        let mixing = scheme != Compensation::Turquin && !single.is_specular() && complement_average > 0.0;
        let mixture = MixtureTable::new(|k| {
            // E ≥ 0.2 at every node: p is positive wherever the added lobe is sampled
            let p = if mixing { 1.0 - row_at(&complement, axis.cell(mu_cell_centre(k))) } else { 1.0 };
            [p, 1.0 - p]
        });
        Ok(Self {
            single,
            scheme,
            mixing,
            alpha,
            axis,
            mixture,
            complement,
            complement_average,
            profile,
            lobe,
            lobe_norm,
            fresnel_average,
            fresnel_normal,
            fresnel_ms,
            scale,
        })
    }
}

impl<S: MicrosurfaceSlope> CompensatedConductor<S> {
    /// The scheme.
    pub fn scheme(&self) -> Compensation {
        self.scheme
    }

    /// The uncompensated single-scattering BSDF of the same material.
    pub fn single_scattering(&self) -> &MicrofacetBsdf<S, Conductor> {
        &self.single
    }

    /// The roughness the tables are read at, √(αx αy).
    pub fn table_alpha(&self) -> f32 {
        self.alpha
    }

    /// E(μ) as this BSDF interpolates it (F = 1 single-scattering albedo), for μ ∈ [0, 1];
    /// `None` outside (NaN included).
    pub fn directional_albedo(&self, mu: f32) -> Option<f32> {
        (0.0..=1.0).contains(&mu).then(|| 1.0 - self.complement_at(mu))
    }

    /// E_avg = 2∫₀¹ E(μ) μ dμ of the interpolated E (exact for it, in f64).
    pub fn average_albedo(&self) -> f32 {
        (1.0 - self.complement_average) as f32
    }

    /// The albedo ∫ f_ms cos θi dωi of the additive lobe for a view at cos θo = μ, per RGB
    /// channel: F_ms (1 − E(μ)) for [`Compensation::KullaConty`], the per-order model g(μ)
    /// (interpolated linearly in x between the nodes) for [`Compensation::PerOrder`]. `None`
    /// for [`Compensation::Turquin`] (no additive lobe) and unless μ ∈ [0, 1].
    pub fn multiple_scattering_albedo(&self, mu: f32) -> Option<Vec3> {
        if self.scheme == Compensation::Turquin || !(0.0..=1.0).contains(&mu) {
            return None;
        }
        Some(self.lobe_at(self.axis.cell(mu)) * self.lobe_norm)
    }

    /// F_avg = 2∫₀¹ F(μ) μ dμ per RGB channel (Gauss–Legendre, error below 1e-7).
    pub fn fresnel_average(&self) -> Vec3 {
        self.fresnel_average
    }

    /// F0 = F(μ = 1) per RGB channel.
    pub fn fresnel_normal(&self) -> Vec3 {
        self.fresnel_normal
    }

    /// Kulla and Conty's F_ms = F_avg² E_avg / (1 − F_avg (1 − E_avg)) per RGB channel (1 for
    /// F = 1).
    pub fn fresnel_multiple_scattering(&self) -> Vec3 {
        self.fresnel_ms
    }

    /// 1 − E(μ) for μ ∈ [0, 1] (a direction's cosine): linear interpolation on the direction
    /// axis x = √(μ (1 + α)/(μ + α)). Branch-free.
    #[inline(always)]
    fn complement_at(&self, mu: f32) -> f32 {
        row_at(&self.complement, self.axis.cell(mu))
    }

    /// Whether the sampler mixes in the additive lobe's profile for the view `wo`: a view
    /// above the horizon of an additive lobe with energy.
    #[inline(always)]
    fn mixes(&self, wo: Vec3) -> bool {
        self.mixing && wo.z > 0.0
    }

    /// The additive lobe's factor h at (cell, fraction) of the direction axis.
    #[inline(always)]
    fn lobe_at(&self, (i, f): (usize, f32)) -> Vec3 {
        self.lobe[i].lerp(self.lobe[i + 1], f)
    }

    /// The additive lobe h(μo) h(μi) of directions above the horizon (both cells from one
    /// division; symmetric in its arguments), 0 unless both are above it.
    #[inline(always)]
    fn added(&self, mu_o: f32, mu_i: f32) -> Vec3 {
        if !(mu_o > 0.0 && mu_i > 0.0) {
            return Vec3::ZERO;
        }
        let (cell_o, cell_i) = self.axis.cells(mu_o, mu_i);
        self.lobe_at(cell_o) * self.lobe_at(cell_i)
    }

    /// The mixture density p pdf_ss + (1 − p) d(μi) μi/π at a light direction of cosine
    /// `mu_i` for a view above the horizon at cos θo = `mu_o` (the profile's density is 0 below
    /// the horizon). Every density of this BSDF is this expression: pdf, eval_with_pdf and
    /// both branches of sample agree bit for bit.
    #[inline(always)]
    fn mixture_pdf(&self, mu_o: f32, pdf_ss: f32, mu_i: f32) -> f32 {
        self.mixture_pdf_above(mu_o, pdf_ss, mu_i.max(0.0))
    }

    /// [`Self::mixture_pdf`] for a light above the horizon (`mu_i` ≥ 0), the same bits.
    #[inline(always)]
    fn mixture_pdf_above(&self, mu_o: f32, pdf_ss: f32, mu_i: f32) -> f32 {
        let (p, added) = self.mixture_parts(mu_o, mu_i);
        p * pdf_ss + added
    }

    /// The mixture's weight p of single scattering and its added term (1 − p) d(μi) μi/π:
    /// [`Self::mixture_pdf_above`] is p pdf_ss + added. `pdf` looks them up before it computes
    /// the mirror density, so that their latencies overlap (criterion, three 3 s runs each:
    /// Kulla–Conty 9.02–9.06 → 8.93–9.04 ns).
    #[inline(always)]
    fn mixture_parts(&self, mu_o: f32, mu_i: f32) -> (f32, f32) {
        let [p, q] = *self.mixture.at(mu_o);
        (p, q * self.profile.pdf(mu_i))
    }

    /// Single scattering's density at a pair of valid directions with `wo` above the horizon:
    /// for `wi` above it the mirror facets' density (the function single scattering's `pdf`,
    /// `eval_with_pdf` and `sample` share, called here without their repeated checks), else
    /// single scattering's `pdf`. The same bits as `self.single.pdf(wo, wi)`.
    #[inline(always)]
    fn single_pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if wi.z > 0.0 {
            let pdf = SingleScattering::<S, Conductor>::mirror_density(self.single.surface().slope(), wo, wi);
            if pdf.is_finite() { pdf } else { 0.0 }
        } else {
            self.single.pdf(wo, wi)
        }
    }

    /// Single scattering's f·cos θi and density at a pair of directions above the horizon, in
    /// the form its sampler gives them for a sampled direction: F(ωo·ωh) G2/G1 · (As/A) · pdf,
    /// with G2/G1 = 1/(1 + Λi/(1 + Λo)) from the f32 Λ, As/A the ratio of the sampler's area to
    /// the projected area of ωo (below 1 for GGX's bounded cap, else 1) and F at the half
    /// vector of the f32 directions (within 1e-5 of eval's f64 form, as the sampler's weight is).
    #[inline(always)]
    fn single_at(&self, wo: Vec3, wi: Vec3) -> (Vec3, f32) {
        let surface = self.single.surface();
        let slope = surface.slope();
        let pdf = self.single_pdf(wo, wi);
        let shadowing = 1.0 / (1.0 + slope.lambda_unchecked(wi) / (1.0 + slope.lambda_unchecked(wo)));
        // the sampler's density is D/(4 As), f·cos θi = F (G2/G1) D/(4 A): As/A = 1 but for
        // GGX's bounded cap
        let areas = slope.mirror_sampling_area_unchecked(wo) / slope.projected_area_unchecked(wo);
        // wo + wi ≠ 0 above the horizon
        let cos = wo.dot((wo + wi).normalize());
        (surface.material().fresnel(cos) * (shadowing * areas * pdf), pdf)
    }

    /// Turquin's factor 1 + F0 (1 − E)/E for a view complement `c_o`.
    #[inline(always)]
    fn turquin_factor(&self, c_o: f32) -> Vec3 {
        Vec3::ONE + self.scale * (c_o / (1.0 - c_o))
    }

    /// 1 − E(μo) of a view direction above the horizon, 0 otherwise (no compensation).
    #[inline(always)]
    fn view_complement(&self, wo: Vec3) -> f32 {
        if wo.z > 0.0 { self.complement_at(wo.z) } else { 0.0 }
    }
}

impl<S: MicrosurfaceSlope> Bsdf for CompensatedConductor<S> {
    #[inline]
    fn flags(&self) -> BsdfFlags {
        self.single.flags()
    }

    #[inline]
    fn eval_keyed(&self, wo: Vec3, wi: Vec3, key: u64) -> BsdfValue {
        if self.single.is_specular() || !valid_direction(wo) || !valid_direction(wi) {
            return self.single.eval_keyed(wo, wi, key);
        }
        let v = self.single.eval_valid(wo, wi, key);
        let f = match self.scheme {
            Compensation::KullaConty | Compensation::PerOrder => v.f + self.added(wo.z, wi.z),
            Compensation::Turquin => v.f * self.turquin_factor(self.view_complement(wo)),
        };
        BsdfValue { f, exact: true }
    }

    #[inline]
    fn sample_keyed(&self, wo: Vec3, uc: f32, u: Vec2, key: u64) -> Option<BsdfSample> {
        if self.scheme == Compensation::Turquin {
            let mut s = self.single.sample_keyed(wo, uc, u, key)?;
            if !self.single.is_specular() {
                s.weight *= self.turquin_factor(self.view_complement(wo));
            }
            return if s.weight.is_finite() { Some(s) } else { None };
        }
        if !self.mixes(wo) || !valid_direction(wo) || !valid_uniforms(uc, u) {
            return self.single.sample_keyed(wo, uc, u, key);
        }
        let [p, _] = *self.mixture.at(wo.z);
        // the view's lobe factor, off the path from the sampled direction to the weight
        let h_o = self.lobe_at(self.axis.cell(wo.z));
        let (wi, f_cos_ss, pdf_ss) = if uc < p {
            // the single-scattering lobe's sample of a conductor seen from above (what its
            // `sample_keyed` runs after the checks done here; uc only chose the lobe): its weight
            // × pdf is f·cos θi, its density that of `single_pdf`, its direction above the horizon
            let surface = self.single.surface();
            let s = SingleScattering::sample_mirror_front(surface.slope(), surface.material(), wo, u.x, u.y)?;
            (s.wo, s.weight * s.pdf, s.pdf)
        } else {
            let wi = self.profile.sample(u)?;
            let (f_cos, pdf) = self.single_at(wo, wi);
            (wi, f_cos, pdf)
        };
        // (wi is above the horizon; its cell from its own division, a few ulps from eval's
        // shared one)
        let f_cos = f_cos_ss + h_o * self.lobe_at(self.axis.cell(wi.z)) * wi.z;
        mixture_sample(wo, wi, f_cos, self.mixture_pdf(wo.z, pdf_ss, wi.z), 1.0)
    }

    #[inline(always)]
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        // Turquin (and a mirror, or no energy to restore) samples the single-scattering lobe,
        // whose pdf validates the directions
        if !self.mixes(wo) || !valid_direction(wo) || !valid_direction(wi) || wi.z <= 0.0 {
            // (a light below the horizon: single scattering's density, 0 for a view from above
            // — the mixture's p·0 + q·0)
            return self.single.pdf(wo, wi);
        }
        // the mixture's lookups first (`mixture_pdf_above`'s expression, the same bits)
        let (p, added) = self.mixture_parts(wo.z, wi.z);
        // `single_pdf` of a light above the horizon, without its test
        let pdf_ss = SingleScattering::<S, Conductor>::mirror_density(self.single.surface().slope(), wo, wi);
        p * if pdf_ss.is_finite() { pdf_ss } else { 0.0 } + added
    }

    #[inline]
    fn eval_with_pdf_keyed(&self, wo: Vec3, wi: Vec3, key: u64) -> (BsdfValue, f32) {
        let (v, pdf_ss) = self.single.eval_with_pdf_keyed(wo, wi, key);
        if self.single.is_specular() || !valid_direction(wo) || !valid_direction(wi) {
            return (v, pdf_ss);
        }
        match self.scheme {
            Compensation::KullaConty | Compensation::PerOrder => {
                let f = v.f + self.added(wo.z, wi.z);
                let pdf = if self.mixes(wo) { self.mixture_pdf(wo.z, pdf_ss, wi.z) } else { pdf_ss };
                (BsdfValue { f, exact: true }, pdf)
            }
            Compensation::Turquin => {
                (BsdfValue { f: v.f * self.turquin_factor(self.view_complement(wo)), exact: true }, pdf_ss)
            }
        }
    }
}

/// 1 − E at the direction nodes for roughness α: the table's two roughness rows around
/// r = √α blended linearly (as its bilinear interpolation does), from the complements of the
/// f32 nodes (exact in f32 for E ≥ 1/2, and every E node is above 0.2).
pub(crate) fn blended_complement(table: &AlbedoTable, alpha: f32) -> [f32; ALBEDO_TABLE_SIZE] {
    let nodes = table.directional_nodes();
    let t = alpha.sqrt() * LAST;
    let j = (t as usize).min(ALBEDO_TABLE_SIZE - 2);
    let f = f64::from(t - j as f32);
    let mut out = [0.0; ALBEDO_TABLE_SIZE];
    for (i, o) in out.iter_mut().enumerate() {
        let lo = 1.0 - f64::from(nodes[j * ALBEDO_TABLE_SIZE + i]);
        let hi = 1.0 - f64::from(nodes[(j + 1) * ALBEDO_TABLE_SIZE + i]);
        *o = (lo + f * (hi - lo)) as f32;
    }
    out
}

/// The factor h = g/√(π ḡ) of the per-order lobe g(μo) g(μi)/(π ḡ) at the direction nodes
/// ([`Compensation::PerOrder`]): the order tables' two roughness rows around r = √α blended
/// as [`blended_complement`] blends E's, g = (1 − E) Σ_k e_k F̄^k/Σ_k e_k per channel (pure
/// order 2 where the walk recorded no higher order), ḡ in closed form for g linear in x per
/// cell ([`profile_average`]). In f64.
fn per_order_lobe(
    orders: &ScatteringOrderTable,
    alpha: f32,
    complement: &[f32; ALBEDO_TABLE_SIZE],
    f_avg: DVec3,
) -> [Vec3; ALBEDO_TABLE_SIZE] {
    let t = alpha.sqrt() * LAST;
    let (j, f) = node_cell(t, ALBEDO_TABLE_SIZE);
    let f = f64::from(f);
    let mut g = [[0.0f32; ALBEDO_TABLE_SIZE]; 3];
    for i in 0..ALBEDO_TABLE_SIZE {
        let e: [f64; ORDER_TABLES] = core::array::from_fn(|k| {
            let nodes = orders.directional_nodes(k);
            let (lo, hi) = (
                f64::from(nodes[j * ALBEDO_TABLE_SIZE + i]),
                f64::from(nodes[(j + 1) * ALBEDO_TABLE_SIZE + i]),
            );
            lo + f * (hi - lo)
        });
        let total: f64 = e.iter().sum();
        for (c, g) in g.iter_mut().enumerate() {
            let fbar = f_avg[c];
            let ratio = if total > 0.0 {
                let (last, tail) = (e[ORDER_TABLES - 2], e[ORDER_TABLES - 1]);
                let mut weighted: f64 = e[..ORDER_TABLES - 1]
                    .iter()
                    .enumerate()
                    .map(|(k, &ek)| ek * fbar.powi(k as i32 + 2))
                    .sum();
                if last > 0.0 {
                    // the tail as the geometric continuation e_K ρ^m of order K = 6
                    let rho = tail / (last + tail);
                    weighted +=
                        last * fbar.powi(LAST_TABULATED_ORDER as i32) * rho * fbar / (1.0 - rho * fbar);
                } else {
                    // no walk of this node ended at order K but some went beyond (the tables'
                    // noise: a few of 2¹⁶ walks): no ratio to continue, so the tail is placed at
                    // the first order it can have, K + 1 (ρ = 1 made it 0·∞ = NaN for F̄ = 1)
                    weighted += tail * fbar.powi(LAST_TABULATED_ORDER as i32 + 1);
                }
                weighted / total
            } else {
                fbar * fbar
            };
            g[i] = (f64::from(complement[i]) * ratio) as f32;
        }
    }
    let mut h = [Vec3::ZERO; ALBEDO_TABLE_SIZE];
    for (c, g) in g.iter().enumerate() {
        let average = profile_average(g, alpha);
        let norm = if average > 0.0 { 1.0 / (core::f64::consts::PI * average).sqrt() } else { 0.0 };
        for (h, &gi) in h.iter_mut().zip(g) {
            h[c] = (f64::from(gi) * norm) as f32;
        }
    }
    debug_assert!(h.iter().all(|v| v.is_finite()), "per-order lobe not finite at α = {alpha}: {h:?}");
    h
}

/// F_avg = 2∫₀¹ F(μ) μ dμ per channel, by composite Gauss–Legendre.
fn fresnel_average(conductor: &Conductor) -> Vec3 {
    let h = 1.0 / FRESNEL_PANELS as f64;
    let mut sum = DVec3::ZERO;
    for panel in 0..FRESNEL_PANELS {
        let mid = (panel as f64 + 0.5) * h;
        for &(x, w) in &GL16 {
            for mu in [mid - 0.5 * h * x, mid + 0.5 * h * x] {
                sum += w * mu * conductor.fresnel(mu as f32).as_dvec3();
            }
        }
    }
    (sum * h).as_vec3()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fresnel::ComplexIor;

    /// The added lobe's branch of the sampler takes single scattering's f·cos θi and density
    /// in its sampler's form (`single_at`): the density is `pdf`'s, bit for bit, and f is
    /// within 1e-5 of `eval`'s (relative, largest channel) on 20 000 random pairs of directions
    /// above the horizon per case, GGX and Beckmann, α from 0.05 to 1, gold and copper.
    #[test]
    fn single_at_matches_eval_and_pdf() {
        fn check<S: AlbedoTabulated>(slope: S, conductor: Conductor, worst: &mut f32) {
            let b = CompensatedConductor::new(slope, conductor, Compensation::KullaConty).unwrap();
            let mut state = 0x9e37_79b9_7f4a_7c15u64;
            let mut next = || {
                state = state.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
                ((state >> 40) as f32 + 0.5) / (1u64 << 24) as f32
            };
            let mut dir = || {
                let z: f32 = next();
                let phi = core::f32::consts::TAU * next();
                let s = (1.0 - z * z).max(0.0).sqrt();
                Vec3::new(s * phi.cos(), s * phi.sin(), z)
            };
            for _ in 0..20_000 {
                let (wo, wi) = (dir(), dir());
                let (f_cos, pdf) = b.single_at(wo, wi);
                assert_eq!(pdf, b.single.pdf(wo, wi), "wo = {wo}, wi = {wi}");
                let f = b.single.eval(wo, wi).f;
                if f.max_element() < f32::MIN_POSITIVE {
                    continue;
                }
                let err = ((f_cos / wi.z) - f).abs().max_element() / f.max_element();
                *worst = worst.max(err);
            }
        }
        let mut worst = 0.0f32;
        for alpha in [0.05f32, 0.3, 1.0] {
            for ior in [ComplexIor::GOLD, ComplexIor::COPPER] {
                check(Ggx::isotropic(alpha).unwrap(), Conductor::new(ior), &mut worst);
                check(Beckmann::isotropic(alpha).unwrap(), Conductor::new(ior), &mut worst);
            }
        }
        println!("single_at against eval: largest relative difference {worst:.2e}");
        assert!(worst <= 1e-5, "largest relative difference {worst:e}");
    }
}
