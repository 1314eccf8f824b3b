//! Energy-compensated dielectrics with the random walk's split between reflection and
//! transmission: the single-scattering microfacet BSDF plus separable (rank-1) lobes of the
//! higher orders' reflected and transmitted energy, from the walk's tables
//! ([`DielectricWalkTable`]), in the manner of Kulla and Conty 2017.

use super::conductor::{AlbedoTabulated, ONE_MINUS_ULP, Tables, check_tabulated, mixture_sample};
use super::lobe_profile::{
    DirectionAxis, MU_CELLS, MixtureTable, MuProfile, mu_cell_centre, mu_cell_masses, profile_average, row_at,
};
use crate::albedo::{DIELECTRIC_TABLE_SIZE, DielectricWalkTable};
use crate::bsdf::{Bsdf, BsdfFlags, BsdfSample, BsdfValue, Transport, valid_direction, valid_uniforms};
use crate::bsdf::{MicrofacetBsdf, Technique};
use crate::error::Error;
use crate::material::{Dielectric, Side};
use crate::single_scattering::SingleScattering;
use crate::slope::{Beckmann, Ggx, MicrosurfaceSlope};
use core::f64::consts::PI;
use glam::{Vec2, Vec3};

/// The cells (index, fraction) of the view's and the light's cosine on the direction axis.
type Cells = ((usize, f32), (usize, f32));

/// Nodes of the walk tables' direction axis.
const PROFILE_NODES: usize = DIELECTRIC_TABLE_SIZE;

/// The smallest share of the single-scattering lobe in the sampling mixture, relative to the
/// lobes' total: keeps its density positive wherever it scatters, should the tables give it
/// no energy (η → 1 at grazing views).
const MIN_SINGLE_SHARE: f64 = 1e-3;

/// A slope family with the random walk's dielectric tables: the families a
/// [`KullaContyDielectric`] can be built on.
pub trait WalkTabulated: AlbedoTabulated {
    /// The family's higher-order dielectric tables.
    const DIELECTRIC_WALK: DielectricWalkTable;
}

impl WalkTabulated for Ggx {
    const DIELECTRIC_WALK: DielectricWalkTable = DielectricWalkTable::GGX;
}

impl WalkTabulated for Beckmann {
    const DIELECTRIC_WALK: DielectricWalkTable = DielectricWalkTable::BECKMANN;
}

/// The rows and samplers of one side of the interface (the side of the view).
#[derive(Debug, Clone, Copy, PartialEq)]
struct SideLobes {
    /// The sampling mixture's probabilities of the single-scattering, the reflection and the
    /// transmission lobe per cell of the view's uniform μ axis: E_ss : ΔR : c ΔT at the cell's
    /// centre (E_ss = R_ss + T_ss), normalized.
    mixture: MixtureTable<3>,
    /// The added lobes' factors of the view at the direction nodes, by whether the light
    /// crosses the interface: ΔR of this side, and ΔT of this side times its reciprocity
    /// factor c.
    view_rows: [[f32; PROFILE_NODES]; 2],
    /// Their factors of the light: ΔR of this side, c ΔT of the other side.
    light_rows: [[f32; PROFILE_NODES]; 2],
    /// Their normalizations: 1/(π ΔR̄), and 1/(π c ΔT̄) of the other side times the transport
    /// factor of a transmission from this side (0 without a lobe).
    scales: [f32; 2],
    /// 1/(π c ΔT̄) of the other side (0 without a lobe).
    transmitted_scale: f32,
    /// The samplers of the light's factor times μ: ΔR(μ) μ of this side, ΔT(μ) μ of the other.
    profiles: [MuProfile; 2],
}

/// A dielectric microfacet BSDF compensated with the random walk's higher orders, reflection
/// and transmission apart: the exact single-scattering BSDF of [`MicrofacetBsdf`]
/// (height-correlated Smith, dielectric Fresnel, [`Technique::SingleScattering`]) plus two
/// separable lobes,
///
/// f = f_ss + f_R + f_T,
/// f_R(ωo, ωi) = ΔR_a(μo) ΔR_a(μi) / (π ΔR̄_a)                (ωi on the view's side a),
/// f_T(ωo, ωi) = c_a ΔT_a(μo) · c_b ΔT_b(μi) / (π c_b ΔT̄_b)   (ωi on the other side b),
///
/// with ΔR_s, ΔT_s the walk's reflected and transmitted energy of orders ≥ 2 for light from
/// side s ([`DielectricWalkTable`]: the walk of Heitz et al. 2016, supplement §3.4),
/// ḡ = 2∫₀¹ g(μ) μ dμ, and μ = |cos θ|. The additive separable form is Kulla and Conty's
/// (2017, *Revisiting Physically Based Shading at Imageworks*, the multiple-scattering lobe
/// (1 − E(μo))(1 − E(μi))/(π(1 − E_avg))), applied to each side's reflected and transmitted
/// higher orders instead of the conductor's 1 − E.
///
/// **Energy** (importance transport, the flux): ∫ f_R cos dωi = ΔR_a(μo) and
/// ∫ f_T |cos| dωi = c_a ΔT_a(μo) for every view, so the albedo is
/// R_ss + T_ss + ΔR + c_a ΔT = 1 up to the tables' errors and the factor c_a, with the walk's
/// split between reflection and transmission.
///
/// **Reciprocity.** Detailed balance in a medium of index n (equilibrium radiance ∝ n²) makes
/// the flux BSDF of a transmission satisfy n_a² f(ωa, ωb) = n_b² f(ωb, ωa) (Veach 1997, §5.2,
/// in importance form). The rank-1 f_T satisfies it if and only if n_a² c_a ΔT̄_a =
/// n_b² c_b ΔT̄_b, which the walk's own higher orders satisfy (they are the difference of two
/// reciprocal BSDFs) up to the tables' noise and interpolation. The factors c enforce it
/// exactly: with L = ln(η² ΔT̄_in/ΔT̄_out) (η = n_in/n_out), ln c_out = w L and
/// ln c_in = −(1 − w) L, where w = v_out/(v_out + v_in) is the share of the relative variance
/// v = Var(ΔT̄)/ΔT̄² of the outside average (from the nodes' standard errors through the
/// blend and the linear average): the noisier side absorbs more of the residual, and equal
/// noise splits it evenly (c_out = 1/c_in = √(η² ΔT̄_in/ΔT̄_out)).
/// [`Self::transmission_mismatch`] reports ΔT̄_out/(η² ΔT̄_in) − 1, and the albedo from side a
/// errs by (c_a − 1) ΔT_a(μo) for it. Without transmitted higher orders on either side
/// (an average of 0) there is no transmission lobe.
/// f_R is symmetric.
///
/// **Sampling.** A mixture chosen by the view's energies: per cell of a uniform μ axis of the
/// view (32 cells, one multiply and one truncation to find one) the probabilities of the
/// single-scattering sample, the reflection lobe and the transmission lobe are
/// E_ss : ΔR_a : c_a ΔT_a at the cell's centre (E_ss = R_ss + T_ss from
/// [`crate::compensation::DielectricAlbedoTable`], at least 1e-3 of the total), normalized at construction;
/// each lobe samples the profile g(μi) μi of its light factor on its hemisphere by cells of the
/// uniform μ axis (a density continuous and linear in μi² on each cell, a cell by its mass with
/// the alias method, φ uniform: no division, root or search to find a cell or its density).
/// `pdf` is the exact mixture density, and a sample's weight is f·|cos θi|/pdf at its
/// direction, with f and pdf computed as `eval` and `pdf` compute them (the density the same
/// bits; the single-scattering branch reuses its sampler's density, within 1e-5 of `pdf`'s).
///
/// **Tables.** Both families' tables at α = √(αx αy), blended in (α, η) once at
/// construction (both sides read the same (r, u) coordinate), the direction axis
/// x = √(μ (1 + α)/(μ + α)) interpolated linearly at run time; ΔR̄ and ΔT̄ are the exact
/// averages of the interpolated rows (closed form per cell).
///
/// **Transport.** [`Transport::Radiance`] (the default) multiplies transmissions by
/// (η_wo/η_wi)², as the single-scattering BSDF does; [`Transport::Importance`] is the flux
/// BSDF above.
///
/// **Special cases.** Effectively smooth surfaces (largest principal roughness below
/// [`crate::SMOOTH_ALPHA`]) and η = 1 are the Dirac lobes of the single-scattering BSDF,
/// uncompensated. A view or light on the horizon has no added lobe.
///
/// # Examples
/// ```
/// use microsurface::glam::{Vec2, Vec3};
/// use microsurface::{Bsdf, Dielectric, Ggx, KullaContyDielectric, Transport};
///
/// let glass = KullaContyDielectric::new(Ggx::isotropic(0.5)?, Dielectric::new(1.5)?)?
///     .with_transport(Transport::Importance);
/// let wo = Vec3::new(0.6, 0.0, 0.8);
/// let s = glass.sample(wo, 0.7, Vec2::new(0.4, 0.2)).expect("glass scatters");
/// let (f, pdf) = glass.eval_with_pdf(wo, s.wi);
/// assert!((pdf - s.pdf).abs() <= 1e-5 * pdf);
/// assert!((s.weight - f.f * s.wi.z.abs() / pdf).abs().max_element() <= 1e-4 * s.weight.max_element());
/// // reciprocal across the interface: f(out → in) = η² f(in → out) for the flux
/// let wi = Vec3::new(-0.3, 0.0, -(1.0f32 - 0.09).sqrt());
/// let (a, b) = (glass.eval(wo, wi).f.x, glass.eval(wi, wo).f.x);
/// assert!((a - 1.5 * 1.5 * b).abs() <= 1e-4 * a);
/// // beyond the tables
/// assert!(KullaContyDielectric::new(Ggx::isotropic(0.5)?, Dielectric::new(4.0)?).is_err());
/// # Ok::<(), microsurface::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KullaContyDielectric<S> {
    single: MicrofacetBsdf<S, Dielectric>,
    transport: Transport,
    /// The tables' roughness √(αx αy).
    alpha: f32,
    /// The walk tables' direction axis at this α.
    axis: DirectionAxis<PROFILE_NODES>,
    /// η_wi/η_wo of a transmission from outside (η) and from inside (1/η).
    transmitted_eta: [f32; 2],
    /// The view's side: outside (0), inside (1).
    sides: [SideLobes; 2],
    /// ΔT̄_out/(η² ΔT̄_in) − 1 of the interpolated tables (0 without transmission lobes).
    mismatch: f32,
}

impl<S: WalkTabulated> KullaContyDielectric<S> {
    /// The compensated BSDF of a dielectric interface on the given slopes (radiance
    /// transport).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] if √(αx αy) > [`MAX_TABULATED_ALPHA`](crate::compensation::MAX_TABULATED_ALPHA) (`"alpha"`) or the
    /// relative index η lies outside [1/[`MAX_TABULATED_ETA`](crate::compensation::MAX_TABULATED_ETA), [`MAX_TABULATED_ETA`](crate::compensation::MAX_TABULATED_ETA)] = [1/3, 3]
    /// (`"eta"`): the tables' range.
    pub fn new(slope: S, dielectric: Dielectric) -> Result<Self, Error> {
        let alpha = slope.albedo_alpha();
        let eta = dielectric.eta();
        check_tabulated(alpha, Some(eta), Tables::Walk)?;
        let eta_error = |value| Tables::Walk.eta_error(value);
        let single = MicrofacetBsdf::new(slope, dielectric)?.with_technique(Technique::SingleScattering);
        let empty = SideLobes {
            mixture: MixtureTable::new(|_| [1.0, 0.0, 0.0]),
            view_rows: [[0.0; PROFILE_NODES]; 2],
            light_rows: [[0.0; PROFILE_NODES]; 2],
            scales: [0.0; 2],
            transmitted_scale: 0.0,
            profiles: [MuProfile::EMPTY; 2],
        };
        let mut b = Self {
            single,
            transport: Transport::Radiance,
            alpha,
            axis: DirectionAxis::new(if single.is_specular() { 1.0 } else { alpha }),
            transmitted_eta: [eta, 1.0 / eta],
            sides: [empty; 2],
            mismatch: 0.0,
        };
        // a Dirac lobe is not compensated (and √(αx αy) may underflow to 0 there)
        if single.is_specular() {
            return Ok(b);
        }
        let mut averages = [0.0f64; 2];
        let mut variances = [0.0f64; 2];
        let mut single = [[0.0f32; MU_CELLS]; 2];
        let mut transmitted_profiles = [MuProfile::EMPTY; 2];
        // the averages are linear in the nodes: their weights, from the unit rows
        let node_weights: [f64; PROFILE_NODES] = core::array::from_fn(|i| {
            let mut unit = [0.0; PROFILE_NODES];
            unit[i] = 1.0;
            profile_average(&unit, alpha)
        });
        for (s, seen) in [eta, 1.0 / eta].into_iter().enumerate() {
            let (dr, dt) = S::DIELECTRIC_WALK.direction_row(alpha, seen).ok_or(eta_error(seen))?;
            // E_ss = R + T at the centres of the uniform μ cells (it only sets the sampling
            // mixture, for which any positive weights give an exact density)
            for (k, e) in single[s].iter_mut().enumerate() {
                let v = S::DIELECTRIC_ALBEDO.albedo(mu_cell_centre(k), alpha, seen).ok_or(eta_error(seen))?;
                *e = v.reflected + v.transmitted;
            }
            let side = &mut b.sides[s];
            side.view_rows = [dr, dt];
            let r_avg = profile_average(&dr, alpha);
            side.scales[0] = if r_avg > 0.0 { (1.0 / (PI * r_avg)) as f32 } else { 0.0 };
            side.profiles[0] = MuProfile::new(&mu_cell_masses(&dr, alpha));
            // the sampler of ΔT μ (the same for c ΔT, a constant factor), for light crossing
            // from the other side
            transmitted_profiles[s] = MuProfile::new(&mu_cell_masses(&dt, alpha));
            averages[s] = profile_average(&dt, alpha);
            let var = S::DIELECTRIC_WALK.transmitted_row_variance(alpha, seen).ok_or(eta_error(seen))?;
            variances[s] = node_weights.iter().zip(var).map(|(w, v)| w * w * f64::from(v)).sum();
        }
        // reciprocity: c_out ΔT̄_out = η² c_in ΔT̄_in; the log-ratio L = ln(η² ΔT̄_in/ΔT̄_out) is
        // split by the averages' relative variances (ln c_out = w L, ln c_in = −(1 − w) L)
        let eta_sq = f64::from(eta) * f64::from(eta);
        let (m_out, m_in) = (averages[0], eta_sq * averages[1]);
        let c = if m_out > 0.0 && m_in > 0.0 {
            let log_ratio = (m_in / m_out).ln();
            let (v_out, v_in) =
                (variances[0] / (averages[0] * averages[0]), variances[1] / (averages[1] * averages[1]));
            let w = if v_out + v_in > 0.0 { v_out / (v_out + v_in) } else { 0.5 };
            b.mismatch = (m_out / m_in - 1.0) as f32;
            [(w * log_ratio).exp(), (-(1.0 - w) * log_ratio).exp()]
        } else {
            [0.0, 0.0]
        };
        for (side, c) in b.sides.iter_mut().zip(c) {
            for v in &mut side.view_rows[1] {
                *v = (f64::from(*v) * c) as f32;
            }
        }
        for s in 0..2 {
            // the transmission from side s is normalized by the other side's scaled average
            let other = c[1 - s] * averages[1 - s];
            let other_row = b.sides[1 - s].view_rows[1];
            let (axis, side) = (b.axis, &mut b.sides[s]);
            side.transmitted_scale = if other > 0.0 { (1.0 / (PI * other)) as f32 } else { 0.0 };
            side.light_rows = [side.view_rows[0], other_row];
            side.profiles[1] = transmitted_profiles[1 - s];
            side.mixture = MixtureTable::new(|k| {
                let cell = axis.cell(mu_cell_centre(k));
                let (dr, dt) = (row_at(&side.view_rows[0], cell), row_at(&side.view_rows[1], cell));
                let (dr, dt) = (f64::from(dr.max(0.0)), f64::from(dt.max(0.0)));
                let single = f64::from(single[s][k]).max(MIN_SINGLE_SHARE * (dr + dt));
                let total = single + dr + dt;
                if total > 0.0 {
                    let (p0, p1) = ((single / total) as f32, (dr / total) as f32);
                    [p0, p1, (1.0 - p0 - p1).max(0.0)]
                } else {
                    [1.0, 0.0, 0.0]
                }
            });
        }
        Ok(b.with_transport(Transport::Radiance))
    }
}

impl<S: MicrosurfaceSlope> KullaContyDielectric<S> {
    /// The same BSDF with the given transport mode.
    #[must_use]
    pub fn with_transport(self, transport: Transport) -> Self {
        let mut b = Self { single: self.single.with_transport(transport), transport, ..self };
        let eta = b.transmitted_eta[0];
        // (η_wo/η_wi)² of a transmission: from outside 1/η², from inside η²
        let radiance = [1.0 / (eta * eta), eta * eta];
        for (side, r) in b.sides.iter_mut().zip(radiance) {
            let transport = match transport {
                Transport::Radiance => r,
                Transport::Importance => 1.0,
            };
            side.scales[1] = side.transmitted_scale * transport;
        }
        b
    }

    /// The uncompensated single-scattering BSDF of the same material.
    pub fn single_scattering(&self) -> &MicrofacetBsdf<S, Dielectric> {
        &self.single
    }

    /// The roughness the tables are read at, √(αx αy).
    pub fn table_alpha(&self) -> f32 {
        self.alpha
    }

    /// ΔT̄_out/(η² ΔT̄_in) − 1: how far the interpolated tables are from the reciprocity of the
    /// walk's higher orders (0 when there is no transmission lobe). The lobes are made
    /// reciprocal by splitting it evenly between the sides (see the type's documentation).
    pub fn transmission_mismatch(&self) -> f32 {
        self.mismatch
    }

    /// The added albedo (ΔR, c ΔT) of a view with |cos θo| = μ ∈ [0, 1] on `side`, as this
    /// BSDF interpolates it (importance transport); `None` outside [0, 1] (NaN included).
    pub fn higher_orders(&self, mu: f32, side: Side) -> Option<(f32, f32)> {
        if !(0.0..=1.0).contains(&mu) {
            return None;
        }
        let s = &self.sides[side_index(side)];
        let cell = self.axis.cell(mu);
        Some((row_at(&s.view_rows[0], cell), row_at(&s.view_rows[1], cell)))
    }

    /// The added lobe f_R or f_T at (wo, wi), both off the horizon, from their cells.
    #[inline(always)]
    fn added(a: &SideLobes, (cell_o, cell_i): Cells, wo: Vec3, wi: Vec3) -> Vec3 {
        let c = crossing(wo, wi);
        Vec3::splat(row_at(&a.view_rows[c], cell_o) * row_at(&a.light_rows[c], cell_i) * a.scales[c])
    }

    /// The view's side and its mixture probabilities (single, reflection, transmission).
    #[inline(always)]
    fn view(&self, wo: Vec3) -> (&SideLobes, [f32; 3]) {
        let a = &self.sides[side_index(Side::above_or_inside(wo.z))];
        (a, *a.mixture.at(wo.z.abs()))
    }

    /// The mixture density at wi (off the horizon) for the view's side `a` and probabilities
    /// `p`: no table of the direction axis, one lookup of the uniform μ axis.
    #[inline(always)]
    fn mixture_pdf(a: &SideLobes, p: [f32; 3], wo: Vec3, wi: Vec3, pdf_ss: f32) -> f32 {
        let c = crossing(wo, wi);
        p[0] * pdf_ss + p[1 + c] * a.profiles[c].pdf(wi.z.abs())
    }

    /// Single scattering's density at valid directions off the horizon of a rough surface:
    /// its research-layer density without the trait's repeated checks (the same bits as
    /// `self.single.pdf(wo, wi)`).
    #[inline(always)]
    fn single_pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        let surface = self.single.surface();
        let pdf = SingleScattering::new(*surface.slope(), *surface.material()).pdf_unchecked(wo, wi);
        if pdf.is_finite() { pdf } else { 0.0 }
    }

    /// The cells of both directions on the direction axis (one division).
    #[inline(always)]
    fn cells(&self, wo: Vec3, wi: Vec3) -> Cells {
        self.axis.cells(wo.z.abs(), wi.z.abs())
    }

    /// Whether the added lobes answer for (wo, wi): a rough surface, valid directions off the
    /// horizon.
    #[inline(always)]
    fn compensates(&self, wo: Vec3, wi: Vec3) -> bool {
        !self.single.is_specular() && valid_direction(wo) && valid_direction(wi) && wo.z != 0.0 && wi.z != 0.0
    }
}

/// Whether the light crosses the interface (1) or stays on the view's side (0).
#[inline(always)]
fn crossing(wo: Vec3, wi: Vec3) -> usize {
    usize::from((wi.z > 0.0) != (wo.z > 0.0))
}

/// The index of a side in [`KullaContyDielectric::sides`].
#[inline(always)]
fn side_index(side: Side) -> usize {
    match side {
        Side::Outside => 0,
        Side::Inside => 1,
    }
}

impl<S: MicrosurfaceSlope> Bsdf for KullaContyDielectric<S> {
    #[inline]
    fn flags(&self) -> BsdfFlags {
        self.single.flags()
    }

    #[inline]
    fn eval_keyed(&self, wo: Vec3, wi: Vec3, key: u64) -> BsdfValue {
        if !self.compensates(wo, wi) {
            return self.single.eval_keyed(wo, wi, key);
        }
        let v = self.single.eval_valid(wo, wi, key);
        let (a, _) = self.view(wo);
        BsdfValue { f: v.f + Self::added(a, self.cells(wo, wi), wo, wi), exact: true }
    }

    #[inline]
    fn sample_keyed(&self, wo: Vec3, uc: f32, u: Vec2, key: u64) -> Option<BsdfSample> {
        if self.single.is_specular() || !valid_direction(wo) || !valid_uniforms(uc, u) || wo.z == 0.0 {
            return self.single.sample_keyed(wo, uc, u, key);
        }
        let (a, p) = self.view(wo);
        let (wi, f_cos_ss, pdf_ss) = if uc < p[0] {
            // the single-scattering lobe: its sample carries f·|cos θi| (weight × pdf) and its
            // density
            let s = self.single.sample_keyed(wo, (uc / p[0]).min(ONE_MINUS_ULP), u, key)?;
            (s.wi, s.weight * s.pdf, s.pdf)
        } else {
            // the added lobe of the light's side: its profile's direction on the view's side,
            // mirrored through the interface for a transmission
            let c = usize::from(uc >= p[0] + p[1]);
            let w = a.profiles[c].sample(u)?;
            let wi = if (wo.z > 0.0) == (c == 0) { w } else { -w };
            // f and the density as eval and pdf compute them
            (wi, self.single.eval_keyed(wo, wi, key).f * wi.z.abs(), self.single_pdf(wo, wi))
        };
        if wi.z == 0.0 {
            return None;
        }
        let f_cos = f_cos_ss + Self::added(a, self.cells(wo, wi), wo, wi) * wi.z.abs();
        let eta = self.transmitted_eta[side_index(Side::above_or_inside(wo.z))];
        mixture_sample(wo, wi, f_cos, Self::mixture_pdf(a, p, wo, wi, pdf_ss), eta)
    }

    #[inline]
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if !self.compensates(wo, wi) {
            return self.single.pdf(wo, wi);
        }
        let (a, p) = self.view(wo);
        Self::mixture_pdf(a, p, wo, wi, self.single_pdf(wo, wi))
    }

    #[inline]
    fn eval_with_pdf_keyed(&self, wo: Vec3, wi: Vec3, key: u64) -> (BsdfValue, f32) {
        let (v, pdf_ss) = self.single.eval_with_pdf_keyed(wo, wi, key);
        if !self.compensates(wo, wi) {
            return (v, pdf_ss);
        }
        let (a, p) = self.view(wo);
        let pdf = Self::mixture_pdf(a, p, wo, wi, pdf_ss);
        (BsdfValue { f: v.f + Self::added(a, self.cells(wo, wi), wo, wi), exact: true }, pdf)
    }
}
