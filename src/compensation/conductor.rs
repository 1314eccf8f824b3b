//! The compensated conductor: the single-scattering microfacet BRDF plus the energy of the
//! higher orders restored from the albedo tables (`AlbedoTable`) and the walk's per-order
//! tables, with a deterministic eval, an exact pdf and a sampler (Kulla and Conty 2017;
//! Turquin 2019), built per hit from shared tables ([`ConductorTables`]).
//!
//! **Tables.** E(μ) is the slope family's `AlbedoTable` at α = √(αx αy), interpolated as the
//! table does (bilinear in the direction coordinate x = √(μ (1 + α)/(μ + α)) and r = √α), from
//! the complements 1 − E of its nodes (exact in f64, rounded once), so that 1 − E keeps its
//! relative precision where E → 1. The added lobes are normalized by the average of what they
//! interpolate at this α (not the shipped E_avg table): 2∫(1 − E) μ dμ in closed form per cell,
//! tabulated at 32 sub-steps of each roughness cell and interpolated linearly (within 4e-4
//! relative at α ≥ 1e-3, 4e-5 at α ≥ 1e-2), so that the Kulla–Conty lobe integrates to
//! F_ms (1 − E(μo)) and the white furnace errs by the table's interpolation error alone.
//!
//! **Sampling** (Kulla–Conty and the walk's orders): with probability p = E(μo) (the lobes'
//! energies for F = 1; E at the centre of μo's cell of a uniform μ axis of 32 cells, blended
//! between the two roughness rows, any p ∈ (0, 1] giving an exact mixture) the caller's u
//! drives the exact visible-normal sample of the single-scattering lobe; otherwise the added
//! lobe's profile (1 − E(μi)) μi is sampled as the mixture of its two roughness rows' profiles
//! (each at its row's α, chosen with probability ∝ blend weight × the row's mass), each a
//! density continuous and linear in μi² on the cells of the uniform μ axis, a cell chosen by
//! the alias method. The density is the mixture p pdf_ss + (1 − p) d(μi) μi/π, exact, the
//! same bits in `pdf`, `eval_with_pdf` and the sample. Turquin samples and has the density of
//! the single-scattering lobe.

use super::compensated::{Compensated, CompensatedMaterial, Compensation};
use super::conductor_tables::{ConductorTables, RoughnessCells, bilinear};
use super::fresnel_average::fresnel_average;
use super::shared::{NOTHING, Shared, mixture_sample};
use crate::albedo::{ALBEDO_DIRECTIONS, DirectionAxis, ORDER_TABLE_SIZE, node_cell};
use crate::bsdf::MicrofacetBsdf;
use crate::bsdf::{Bsdf, BsdfFlags, BsdfSample, BsdfValue, Transport, unit_directions, unit_view};
use crate::compensation::AlbedoTabulated;
use crate::error::Error;
use crate::fresnel::ComplexIor;
use crate::material::Conductor;
use crate::single_scattering::SingleScattering;
use crate::slope::MicrosurfaceSlope;
use core::f32::consts::PI;
use glam::{Vec2, Vec3, Vec3A, Vec4};

/// The albedo table's last direction node index, and the per-order tables'.
const LAST_X: f32 = (ALBEDO_DIRECTIONS - 1) as f32;
const LAST_O: f32 = (ORDER_TABLE_SIZE - 1) as f32;

/// The per-hit state of a compensated conductor: a few scalars and the shared tables.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ConductorLobes {
    tables: Shared<ConductorTables>,
    /// The direction axis at the hit's α.
    axis: DirectionAxis,
    /// The albedo table's roughness cell of α and the fraction in it.
    row: (u32, f32),
    /// The per-order tables' roughness cell of α and the fraction in it.
    order_row: (u32, f32),
    /// The probability of the upper row's profile in the added lobe's sampler.
    upper: f32,
    /// Whether the sampler mixes in the added lobe (an additive scheme with energy on a rough
    /// surface).
    pub(super) mixing: bool,
    /// F̄ = F_avg per channel (Kulla–Conty and the walk's orders).
    fresnel_average: Vec3A,
    /// Kulla–Conty: F_ms/(π C); the walk's orders: 1/(π ḡ) per channel; Turquin: F0.
    scale: Vec3A,
}

impl ConductorLobes {
    /// The lobes of a Dirac mirror: none.
    fn none(tables: &'static ConductorTables) -> Self {
        Self {
            tables: Shared(tables),
            axis: DirectionAxis::NONE,
            row: (0, 0.0),
            order_row: (0, 0.0),
            upper: 0.0,
            mixing: false,
            fresnel_average: Vec3A::ZERO,
            scale: Vec3A::ZERO,
        }
    }

    /// The albedo table's roughness cell.
    #[inline(always)]
    fn row(&self) -> (usize, f32) {
        cell(self.row)
    }

    /// The direction coordinates x of two cosines in [0, 1] from one division.
    #[inline(always)]
    pub(super) fn coordinates(&self, mu_o: f32, mu_i: f32) -> (f32, f32) {
        self.axis.coordinates(mu_o, mu_i)
    }

    /// The direction coordinate x of one cosine in [0, 1].
    #[inline(always)]
    pub(super) fn coordinate(&self, mu: f32) -> f32 {
        self.axis.coordinate(mu)
    }

    /// 1 − E at the direction coordinate x.
    #[inline(always)]
    fn complement(&self, x: f32) -> f32 {
        self.tables.0.complement_at(node_cell(x * LAST_X, ALBEDO_DIRECTIONS), self.row())
    }

    /// Σ_k F̄ᵏ φ_k at the direction coordinate x per channel (orders 2 … 6 and the tail at 7),
    /// by Horner's scheme.
    #[inline(always)]
    fn order_series(&self, x: f32) -> Vec3A {
        let [a, b] =
            self.tables.0.fractions_at(node_cell(x * LAST_O, ORDER_TABLE_SIZE), cell(self.order_row));
        series(self.fresnel_average, a, b)
    }

    /// The added lobe's factor g(μ) at the direction coordinate x with 1 − E = `c`:
    /// Kulla–Conty c (the constant F_ms is in the scale), the walk's orders c Σ_k F̄ᵏ φ_k.
    #[inline(always)]
    fn factor(&self, scheme: Compensation, x: f32, c: f32) -> Vec3A {
        match scheme {
            Compensation::Walk => c * self.order_series(x),
            _ => Vec3A::splat(c),
        }
    }

    /// The mixture's probability p of single scattering for a view at cos θo = `mu_o`.
    #[inline(always)]
    fn single_share(&self, mu_o: f32) -> f32 {
        let k = super::lobe_profile::mu_cell(mu_o);
        let (j, f) = self.row();
        // (one bounds check for both rows)
        let rows = &self.tables.0.rows[j..j + 2];
        let (a, b) = (rows[0].single[k], rows[1].single[k]);
        a + f * (b - a)
    }

    /// The added lobe's sampling density d(μi) μi/π at a light of cosine `mu_i` ≥ 0.
    #[inline(always)]
    fn profile_pdf(&self, mu_i: f32) -> f32 {
        let j = self.row().0;
        let rows = &self.tables.0.rows[j..j + 2];
        let (a, b) = (rows[0].profile.pdf(mu_i), rows[1].profile.pdf(mu_i));
        a + self.upper * (b - a)
    }

    /// The mixture's weight p of single scattering and its added term (1 − p) d(μi) μi/π.
    #[inline(always)]
    pub(super) fn mixture_parts(&self, mu_o: f32, mu_i: f32) -> (f32, f32) {
        let p = self.single_share(mu_o);
        (p, (1.0 - p) * self.profile_pdf(mu_i))
    }

    /// The mixture density p pdf_ss + (1 − p) d(μi) μi/π for a view above the horizon (the
    /// profile's density is 0 below the horizon). Every density of the BSDF is this
    /// expression: pdf, eval_with_pdf and both branches of sample agree bit for bit.
    #[inline(always)]
    fn mixture_pdf(&self, mu_o: f32, pdf_ss: f32, mu_i: f32) -> f32 {
        mixture_of(self.mixture_parts(mu_o, mu_i.max(0.0)), pdf_ss)
    }

    /// Turquin's factor 1 + F0 (1 − E)/E for a view complement `c_o`.
    #[inline(always)]
    pub(super) fn turquin_factor(&self, c_o: f32) -> Vec3 {
        Vec3::ONE + Vec3::from(self.scale) * (c_o / (1.0 - c_o))
    }

    /// The direction factors at every node of the albedo table's direction axis, for a batch
    /// (see [`Column`]).
    #[inline]
    pub(super) fn column(&self, scheme: Compensation) -> Column {
        let tables = self.tables.0;
        let (j, fr) = self.row();
        let order_row = cell(self.order_row);
        let (lower, upper) =
            (&tables.complement[j * ALBEDO_DIRECTIONS..], &tables.complement[(j + 1) * ALBEDO_DIRECTIONS..]);
        Column {
            corners: core::array::from_fn(|i| [lower[i], upper[i], lower[i + 1], upper[i + 1]]),
            fraction: fr,
            // (the walk's orders alone read the series)
            series: if scheme == Compensation::Walk {
                core::array::from_fn(|i| {
                    // the per-order axis's node below i and the fraction of its cell (a whole
                    // number of the albedo axis's cells, COARSE per cell)
                    let k = (i / COARSE).min(ORDER_TABLE_SIZE - 2);
                    let [a, b] = tables.fractions_at((k, (i - k * COARSE) as f32 / COARSE as f32), order_row);
                    series(self.fresnel_average, a, b)
                })
            } else {
                [Vec3A::ZERO; ALBEDO_DIRECTIONS]
            },
        }
    }
}

/// The albedo table's direction cells per cell of the per-order tables (the same axis x, the
/// per-order nodes every `COARSE`-th albedo node).
const COARSE: usize = (ALBEDO_DIRECTIONS - 1) / (ORDER_TABLE_SIZE - 1);
const _: () = assert!(COARSE * (ORDER_TABLE_SIZE - 1) == ALBEDO_DIRECTIONS - 1);

/// What the added lobe reads at a direction coordinate x ∈ [0, 1].
pub(super) trait DirectionFactors {
    /// 1 − E.
    fn complement_at(&self, x: f32) -> f32;
    /// The walk's orders' factor g = (1 − E) Σ_k F̄ᵏ φ_k per channel.
    fn walk_factor_at(&self, x: f32) -> Vec3A;
}

/// The tables' bilinear lookups at the lobe's roughness.
impl DirectionFactors for ConductorLobes {
    #[inline(always)]
    fn complement_at(&self, x: f32) -> f32 {
        self.complement(x)
    }
    #[inline(always)]
    fn walk_factor_at(&self, x: f32) -> Vec3A {
        self.factor(Compensation::Walk, x, self.complement(x))
    }
}

/// The direction factors of a [`ConductorLobes`] at its roughness, laid out for a batch, where
/// they are read at many directions: 1 − E as the four corners of each direction cell of the
/// lobe's two roughness rows (one 16-byte read per lookup, interpolated as the lobes
/// interpolate them: the same bits), and Σ_k F̄ᵏ φ_k per channel at the albedo table's
/// direction nodes. The per-order tables' nodes are every third node of the same axis, so
/// that the series, linear in the fractions, interpolates between the albedo nodes as the
/// lobes interpolate it between theirs: the walk's factor is the lobes' within rounding, 1e-6
/// per channel of its largest value at the ends of the cell (the unit test
/// `column_reads_the_lobes_within_rounding`).
pub(super) struct Column {
    /// 1 − E at the corners of direction cell i: (lower row, upper row) at node i, then at
    /// node i + 1.
    corners: [[f32; 4]; ALBEDO_DIRECTIONS - 1],
    /// The fraction of the lobe's roughness in its cell of the rows.
    fraction: f32,
    series: [Vec3A; ALBEDO_DIRECTIONS],
}

impl Column {
    /// 1 − E in direction cell `(i, t)`: the lobes' bilinear interpolation ([`bilinear`]).
    #[inline(always)]
    fn complement_in(&self, (i, t): (usize, f32)) -> f32 {
        bilinear(self.corners[i], t, self.fraction)
    }
}

impl DirectionFactors for Column {
    #[inline(always)]
    fn complement_at(&self, x: f32) -> f32 {
        self.complement_in(node_cell(x * LAST_X, ALBEDO_DIRECTIONS))
    }
    #[inline(always)]
    fn walk_factor_at(&self, x: f32) -> Vec3A {
        let (i, t) = node_cell(x * LAST_X, ALBEDO_DIRECTIONS);
        let (a, b) = (self.series[i], self.series[i + 1]);
        self.complement_in((i, t)) * (a + t * (b - a))
    }
}

/// The mixture density p pdf_ss + added from the parts (p, added) of
/// [`ConductorLobes::mixture_parts`].
#[inline(always)]
pub(super) fn mixture_of((p, added): (f32, f32), pdf_ss: f32) -> f32 {
    p * pdf_ss + added
}

/// A table cell (index, fraction) as stored in [`ConductorLobes`] (a u32 index: 8 bytes).
#[inline(always)]
fn narrow((i, f): (usize, f32)) -> (u32, f32) {
    // (a cell of a table of fewer than 256 rows)
    (i as u32, f)
}

/// A stored table cell as the tables index it.
#[inline(always)]
fn cell((i, f): (u32, f32)) -> (usize, f32) {
    (i as usize, f)
}

/// F0 of a conductor per channel (1 for F = 1).
#[inline(always)]
fn normal_reflectance(conductor: &Conductor) -> Vec3A {
    conductor.ior().map_or(Vec3A::ONE, ComplexIor::normal_reflectance)
}

/// Σ_k F̄ᵏ φ_k = F̄² ((φ2 + F̄ φ3) + F̄² (φ4 + F̄ φ5) + F̄⁴ (φ6 + F̄ φ7)) per channel, with φ the
/// lanes (φ2, φ3, φ4, φ5), (φ6, φ7, ·, ·): Estrin's scheme, four multiplications deep where
/// Horner's is seven (every term ≥ 0 for F̄ ∈ [0, 1]: no cancellation in either).
#[inline(always)]
fn series(f: Vec3A, a: Vec4, b: Vec4) -> Vec3A {
    let pair = |even: f32, odd: f32| Vec3A::splat(even) + f * odd;
    let f2 = f * f;
    f2 * ((pair(a.x, a.y) + f2 * pair(a.z, a.w)) + (f2 * f2) * pair(b.x, b.y))
}

impl CompensatedMaterial for Conductor {
    type Lobes = ConductorLobes;

    #[inline(always)]
    fn lobes<S: AlbedoTabulated>(
        single: &MicrofacetBsdf<S, Self>,
        scheme: Compensation,
    ) -> Result<ConductorLobes, Error> {
        let tables = ConductorTables::of(S::ALBEDO.family());
        // a Dirac mirror is not compensated (and √(αx αy) may underflow to 0 there)
        if single.is_specular() {
            return Ok(ConductorLobes::none(tables));
        }
        let conductor = single.surface().material();
        let alpha = single.surface().slope().albedo_alpha();
        let RoughnessCells { row, order_row, step } = RoughnessCells::of(alpha.sqrt());
        let lobes = ConductorLobes {
            axis: DirectionAxis::new(alpha),
            row: narrow(row),
            ..ConductorLobes::none(tables)
        };
        if scheme == Compensation::Turquin {
            // the view's 1 − E and F0: nothing else (the averages are the queries')
            return Ok(ConductorLobes { scale: normal_reflectance(conductor), ..lobes });
        }
        let [a, b] = tables.averages_at(step);
        let c = a.x;
        let f = conductor.ior().map_or(Vec3A::ONE, |ior| tables.fresnel.lookup(ior));
        // the lobe's scale as a quotient per channel
        let (numerator, denominator) = match scheme {
            // no energy lost (every node of the row is 1): nothing to restore
            _ if c <= 0.0 => (Vec3A::ZERO, Vec3A::ONE),
            // F_ms/(π C), F_ms = F̄² E_avg/(1 − F̄ C) (the denominator is ≥ E_avg > 0)
            Compensation::KullaConty => (f * f * (1.0 - c), (Vec3A::ONE - f * c) * (PI * c)),
            // 1/(π ḡ), ḡ = Σ_k F̄ᵏ m_k (> 0 for F̄ > 0: m_2 > 0 wherever C > 0)
            _ => {
                let average = series(f, Vec4::new(a.y, a.z, a.w, b.x), Vec4::new(b.y, b.z, 0.0, 0.0));
                let positive = average.cmpgt(Vec3A::ZERO);
                (
                    Vec3A::select(positive, Vec3A::ONE, Vec3A::ZERO),
                    Vec3A::select(positive, PI * average, Vec3A::ONE),
                )
            }
        };
        // the profile mixture of the two rows, by blend weight × mass: the upper row's
        // probability, in the scale's division (one SIMD division for both)
        let (j, fr) = row;
        let rows = &tables.rows[j..j + 2];
        let (lower, upper) = ((1.0 - fr) * rows[0].mass, fr * rows[1].mass);
        let total = lower + upper;
        let has_mass = total > 0.0;
        let (upper, total) = if has_mass { (upper, total) } else { (0.0, 1.0) };
        let quotient = numerator.extend(upper) / denominator.extend(total);
        let scale = Vec3A::from_vec4(quotient);
        Ok(ConductorLobes {
            order_row: narrow(order_row),
            upper: quotient.w,
            mixing: c > 0.0 && has_mass,
            fresnel_average: f,
            scale,
            ..lobes
        })
    }

    #[inline(always)]
    fn lobes_with_transport(lobes: ConductorLobes, _transport: Transport) -> ConductorLobes {
        lobes
    }
}

/// The compensated conductor (see [`Compensated`] for the type; this block, its queries).
///
/// **Cost.** Construction finds the cells of r = √α on the tables' three roughness axes at
/// once (SIMD lanes), reads the averages at the sub-step of r (one pair of entries) and the two
/// rows' masses, F_avg from its table over the complex index ([`Compensation::Walk`] and
/// [`Compensation::KullaConty`]: one load of a cell's four corners per channel, the channels in
/// SIMD lanes; F0 for [`Compensation::Turquin`]) and forms the lobe's scale and the sampler's
/// row probability (one SIMD division for both): about 410 instructions for `Walk`, 390 for
/// `KullaConty` and 235 for `Turquin`, the single-scattering BSDF's own 130 included (GGX gold,
/// callgrind, `tools/src/bin/profile_per_hit.rs`; `DESIGN.md`, "Speed of the compensated
/// lobes"). Eval adds to the single-scattering eval one (Turquin) or two (sharing one division)
/// bilinear lookups of 1 − E and, for the walk's orders, of the order fractions; pdf two lookups
/// of the uniform μ axis per roughness row; sample the lookups of eval and pdf (measured in
/// `README.md`).
///
/// **The walk's orders** ([`Compensation::Walk`]) restore each channel's energy from the
/// walk's per-order energies ([`super::ScatteringOrderTable`], standard error ≤ 1.95e-3 per
/// node) instead of Kulla and Conty's series in E_avg: for F = 1 it is the Kulla–Conty lobe;
/// for coloured metals it follows the walk where the series does not (GGX gold, copper,
/// aluminium at α = 1: albedo within 0.5 % of the walk against 3–4 % for Kulla–Conty,
/// `lab --bin compensation`), but its F̄ = F_avg per bounce misses the grazing-facet Fresnel of
/// the higher orders for grazing views at small α (gold at α = 0.1, μo = 0.1: 3 % low, as
/// Kulla–Conty).
impl<S: MicrosurfaceSlope> Compensated<S, Conductor> {
    /// E(μ) as this BSDF interpolates it (F = 1 single-scattering albedo), for μ ∈ [0, 1];
    /// `None` outside (NaN included).
    pub fn directional_albedo(&self, mu: f32) -> Option<f32> {
        (0.0..=1.0).contains(&mu).then(|| 1.0 - self.lobes.complement(self.lobes.coordinate(mu)))
    }

    /// E_avg = 2∫₀¹ E(μ) μ dμ of the interpolated E (its closed form, tabulated at sub-steps
    /// of the roughness cells: relative error of 1 − E_avg below 4e-4 at α ≥ 1e-3).
    pub fn average_albedo(&self) -> f32 {
        1.0 - self.complement_average()
    }

    /// C = 1 − E_avg of the interpolated E at this α (0 for a Dirac mirror).
    fn complement_average(&self) -> f32 {
        if self.single.is_specular() {
            return 0.0;
        }
        self.lobes.tables.0.complement_average(RoughnessCells::of(self.alpha.sqrt()).step)
    }

    /// The albedo ∫ f_ms cos θi dωi of the additive lobe for a view at cos θo = μ, per RGB
    /// channel: F_ms (1 − E(μ)) for [`Compensation::KullaConty`], the per-order model
    /// g(μ) = (1 − E(μ)) Σ_k φ_k(μ) F̄ᵏ for [`Compensation::Walk`]. `None` for
    /// [`Compensation::Turquin`] (no additive lobe) and unless μ ∈ [0, 1].
    pub fn multiple_scattering_albedo(&self, mu: f32) -> Option<Vec3> {
        if self.scheme == Compensation::Turquin || !(0.0..=1.0).contains(&mu) {
            return None;
        }
        if self.single.is_specular() {
            return Some(Vec3::ZERO);
        }
        let l = &self.lobes;
        let x = l.coordinate(mu);
        let c = l.complement(x);
        Some(match self.scheme {
            Compensation::Walk => Vec3::from(c * l.order_series(x)),
            _ => self.fresnel_multiple_scattering() * c,
        })
    }

    /// F_avg = 2∫₀¹ F(μ) μ dμ per RGB channel (from its table over the complex index: within
    /// 2e-5 for the crate's presets and 1e-4 for k ≥ 0.3 against quadrature; 1 for F = 1).
    pub fn fresnel_average(&self) -> Vec3 {
        self.single.surface().material().ior().map_or(Vec3::ONE, |ior| fresnel_average(ior).into())
    }

    /// F0 = F(μ = 1) per RGB channel.
    pub fn fresnel_normal(&self) -> Vec3 {
        normal_reflectance(self.single.surface().material()).into()
    }

    /// Kulla and Conty's F_ms = F_avg² E_avg / (1 − F_avg (1 − E_avg)) per RGB channel (1 for
    /// F = 1).
    pub fn fresnel_multiple_scattering(&self) -> Vec3 {
        let f = self.fresnel_average();
        let c = self.complement_average();
        f * f * (1.0 - c) / (Vec3::ONE - f * c)
    }

    /// Whether the sampler mixes in the additive lobe's profile for the view `wo`: a view
    /// above the horizon of an additive lobe with energy.
    #[inline(always)]
    fn mixes(&self, wo: Vec3) -> bool {
        self.lobes.mixing && wo.z > 0.0
    }

    /// f of a rough surface at valid directions from single scattering's `f_ss` at the same
    /// directions: f_ss plus the additive lobe (Kulla–Conty, the walk's orders) or f_ss times
    /// Turquin's factor of the view. Every evaluation of the BSDF (`eval`, `eval_with_pdf`, the
    /// batch calls) is this expression in three steps: [`Self::coordinates_of`],
    /// [`Self::lookups_at`] and [`Self::compose`].
    #[inline(always)]
    pub(super) fn compensated_f(&self, wo: Vec3, wi: Vec3, f_ss: Vec3) -> Vec3 {
        let scheme = self.scheme;
        let (xo, xi, weight) = self.coordinates_of(scheme, wo.z, wi.z);
        if weight > 0.0 {
            self.compose(scheme, f_ss, self.lookups_at(scheme, &self.lobes, xo, xi), weight)
        } else {
            f_ss
        }
    }

    /// The direction coordinates that f's compensation reads at cosines μo and μi (the
    /// lobes' `scheme`, an argument so that a batch's loops see it as a constant), and its
    /// weight: 1 where the scheme compensates (both directions above the horizon for the
    /// additive lobes, the view for Turquin's factor), 0 elsewhere. Branch-free (a batch runs
    /// it in vectorized lanes).
    #[inline(always)]
    pub(super) fn coordinates_of(&self, scheme: Compensation, mu_o: f32, mu_i: f32) -> (f32, f32, f32) {
        let lobes = &self.lobes;
        let one = |above: bool| if above { 1.0 } else { 0.0 };
        match scheme {
            Compensation::Turquin => (lobes.coordinate(mu_o.max(0.0)), 0.0, one(mu_o > 0.0)),
            _ => {
                let (xo, xi) = lobes.coordinates(mu_o.max(0.0), mu_i.max(0.0));
                (xo, xi, one(mu_o > 0.0 && mu_i > 0.0))
            }
        }
    }

    /// What the scheme reads at the direction coordinates of [`Self::coordinates_of`]:
    /// g(μo) g(μi) per channel for the walk's orders, (1 − E(μo)) (1 − E(μi)) for
    /// Kulla–Conty, 1 − E(μo) for Turquin; from `factors` (the lobes' tables, or a batch's
    /// [`Column`]).
    #[inline(always)]
    pub(super) fn lookups_at<F: DirectionFactors>(
        &self,
        scheme: Compensation,
        factors: &F,
        xo: f32,
        xi: f32,
    ) -> Vec3 {
        match scheme {
            Compensation::Walk => Vec3::from(factors.walk_factor_at(xo) * factors.walk_factor_at(xi)),
            Compensation::KullaConty => Vec3::splat(factors.complement_at(xo) * factors.complement_at(xi)),
            Compensation::Turquin => Vec3::splat(factors.complement_at(xo)),
        }
    }

    /// f from single scattering's `f_ss`, the scheme's `lookups` and the weight of
    /// [`Self::coordinates_of`]: f_ss + scale · lookups · weight for the additive lobes, f_ss
    /// times Turquin's factor of the view's 1 − E · weight (a weight of 0 gives f_ss, a NaN
    /// gives NaN). Branch-free (a batch runs it in vectorized lanes).
    #[inline(always)]
    pub(super) fn compose(&self, scheme: Compensation, f_ss: Vec3, lookups: Vec3, weight: f32) -> Vec3 {
        let lobes = &self.lobes;
        match scheme {
            Compensation::Turquin => f_ss * lobes.turquin_factor(lookups.x * weight),
            _ => f_ss + Vec3::from(lobes.scale) * lookups * weight,
        }
    }

    /// Turquin's sample weight from single scattering's sample `weight` for the view `wo`
    /// (valid): scaled by the view's factor on a rough surface, as f is ([`Self::compose`]);
    /// `None` where not finite. Every sample of Turquin's scheme (`sample`, the batch call) ends
    /// with this expression.
    #[inline(always)]
    pub(super) fn turquin_weight(&self, wo: Vec3, weight: Vec3) -> Option<Vec3> {
        let weight = if self.single.is_specular() {
            weight
        } else {
            let turquin = Compensation::Turquin;
            let (xo, _, w) = self.coordinates_of(turquin, wo.z, 0.0);
            self.compose(turquin, weight, self.lookups_at(turquin, &self.lobes, xo, 0.0), w)
        };
        weight.is_finite().then_some(weight)
    }

    /// The density at valid directions from single scattering's `pdf_ss` at the same
    /// directions: the sampling mixture's p pdf_ss + (1 − p) d(μi) μi/π where the sampler mixes
    /// and the light is above the horizon, else `pdf_ss` (a light below the horizon of a view
    /// from above has density 0 in both lobes). Every density of the BSDF but the sample's
    /// (`pdf`, `eval_with_pdf`, the batch calls) is this expression: [`Self::mixes_at`], then
    /// [`ConductorLobes::mixture_parts`] and [`mixture_of`] where it mixes.
    #[inline(always)]
    pub(super) fn compensated_pdf(&self, wo: Vec3, wi: Vec3, pdf_ss: f32) -> f32 {
        if self.mixes_at(wo.z, wi.z) {
            mixture_of(self.lobes.mixture_parts(wo.z, wi.z), pdf_ss)
        } else {
            pdf_ss
        }
    }

    /// Whether the density at directions of cosines μo and μi is the sampling mixture's: the
    /// sampler mixes for the view ([`Self::mixes`]) and the light is above the horizon.
    #[inline(always)]
    pub(super) fn mixes_at(&self, mu_o: f32, mu_i: f32) -> bool {
        self.lobes.mixing && mu_o > 0.0 && mu_i > 0.0
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
}

impl<S: MicrosurfaceSlope> Bsdf for Compensated<S, Conductor> {
    #[inline]
    fn flags(&self) -> BsdfFlags {
        self.single.flags()
    }

    #[inline]
    fn eval_keyed(&self, wo: Vec3, wi: Vec3, key: u64) -> BsdfValue {
        unit_directions!(wo, wi, NOTHING, self.eval_keyed(wo, wi, key));
        let v = self.single.eval_valid(wo, wi, key);
        if self.single.is_specular() {
            return v;
        }
        BsdfValue { f: self.compensated_f(wo, wi, v.f), exact: true }
    }

    #[inline]
    fn sample_keyed(&self, wo: Vec3, uc: f32, u: Vec2, key: u64) -> Option<BsdfSample> {
        unit_view!(wo, uc, u, None, self.sample_keyed(wo, uc, u, key));
        let lobes = &self.lobes;
        if self.scheme == Compensation::Turquin {
            let s = self.single.sample_keyed(wo, uc, u, key)?;
            return Some(BsdfSample { weight: self.turquin_weight(wo, s.weight)?, ..s });
        }
        if !self.mixes(wo) {
            return self.single.sample_keyed(wo, uc, u, key);
        }
        let p = lobes.single_share(wo.z);
        // the view's lobe factor, off the path from the sampled direction to the weight
        let xo = lobes.coordinate(wo.z);
        let g_o = lobes.factor(self.scheme, xo, lobes.complement(xo));
        let (wi, f_cos_ss, pdf_ss) = if uc < p {
            // the single-scattering lobe's sample of a conductor seen from above (what its
            // `sample_keyed` runs after the checks done here; uc only chose the lobe): its weight
            // × pdf is f·cos θi, its density that of `single_pdf`, its direction above the horizon
            let surface = self.single.surface();
            let s = SingleScattering::sample_mirror_front(surface.slope(), surface.material(), wo, u.x, u.y)?;
            (s.wo, s.weight * s.pdf, s.pdf)
        } else {
            // the upper row's profile with its probability (uc rescaled to the added lobe's
            // share without a division)
            let j = lobes.row().0 + usize::from(uc < p + lobes.upper * (1.0 - p));
            let wi = lobes.tables.0.rows[j].profile.sample(u)?;
            let (f_cos, pdf) = self.single_at(wo, wi);
            (wi, f_cos, pdf)
        };
        // (wi is above the horizon; its coordinate from its own division, a few ulps from
        // eval's shared one)
        let xi = lobes.coordinate(wi.z);
        let g_i = lobes.factor(self.scheme, xi, lobes.complement(xi));
        let f_cos = f_cos_ss + Vec3::from(lobes.scale * g_o * g_i * wi.z);
        mixture_sample(wo, wi, f_cos, lobes.mixture_pdf(wo.z, pdf_ss, wi.z), 1.0)
    }

    #[inline(always)]
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        unit_directions!(wo, wi, 0.0, self.pdf(wo, wi));
        // Turquin (and a mirror, or no energy to restore) samples the single-scattering lobe
        if !self.mixes_at(wo.z, wi.z) {
            // (a light below the horizon: single scattering's density, 0 for a view from above
            // — the mixture's p·0 + q·0)
            return self.single.pdf(wo, wi);
        }
        // `single_pdf` of a light above the horizon, without its test; `compensated_pdf`'s
        // mixture without its test
        let pdf_ss = SingleScattering::<S, Conductor>::mirror_density(self.single.surface().slope(), wo, wi);
        mixture_of(self.lobes.mixture_parts(wo.z, wi.z), if pdf_ss.is_finite() { pdf_ss } else { 0.0 })
    }

    #[inline]
    fn eval_with_pdf_keyed(&self, wo: Vec3, wi: Vec3, key: u64) -> (BsdfValue, f32) {
        unit_directions!(wo, wi, (NOTHING, 0.0), self.eval_with_pdf_keyed(wo, wi, key));
        let (v, pdf_ss) = self.single.eval_with_pdf_keyed(wo, wi, key);
        if self.single.is_specular() {
            return (v, pdf_ss);
        }
        let f = self.compensated_f(wo, wi, v.f);
        (BsdfValue { f, exact: true }, self.compensated_pdf(wo, wi, pdf_ss))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fresnel::ComplexIor;
    use crate::slope::{Beckmann, Ggx};

    /// A batch's [`Column`] reads the lobes' direction factors: 1 − E bit for bit, each channel
    /// of the walk's factor g within 1e-6 of that channel's largest value at the coordinate and
    /// the ends of its cell (the series interpolated after the roughness rows, not before; every
    /// direction node and cell midpoint, and 4096 random coordinates per case: GGX and
    /// Beckmann, α from 1e-3 to 1 across the roughness cells, gold, copper and F = 1).
    #[test]
    fn column_reads_the_lobes_within_rounding() {
        fn check<S: AlbedoTabulated>(slope: S, conductor: Conductor, worst: &mut f32) {
            let b = Compensated::with_scheme(slope, conductor, Compensation::Walk).unwrap();
            let column = b.lobes.column(Compensation::Walk);
            let mut state = 0x2545_f491_4f6c_dd1du64;
            let mut next = || {
                state = state.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
                ((state >> 40) as f32 + 0.5) / (1u64 << 24) as f32
            };
            let nodes = (0..2 * ALBEDO_DIRECTIONS - 1).map(|k| k as f32 / (2.0 * LAST_X));
            let xs: Vec<f32> = nodes.chain((0..4096).map(|_| next())).collect();
            for x in xs {
                let (c, g) = (b.lobes.complement_at(x), b.lobes.walk_factor_at(x));
                let (cc, gc) = (column.complement_at(x), column.walk_factor_at(x));
                // the largest value at the ends of x's cell (the interpolations' rounding scale)
                let i = node_cell(x * LAST_X, ALBEDO_DIRECTIONS).0 as f32;
                let ends = [i / LAST_X, (i + 1.0) / LAST_X].map(|e| b.lobes.walk_factor_at(e));
                let scale = g.max(ends[0]).max(ends[1]).max(Vec3A::splat(f32::MIN_POSITIVE));
                assert_eq!(
                    cc.to_bits(),
                    c.to_bits(),
                    "x = {x}: 1 − E = {c} by the lobes, {cc} by the column"
                );
                let err = ((gc - g).abs() / scale).max_element();
                assert!(err <= 1e-6, "x = {x}: g = {g} by the lobes, {gc} by the column");
                *worst = worst.max(err);
            }
        }
        let mut worst = 0.0f32;
        for alpha in [1e-3f32, 0.013, 0.05, 0.21, 0.5, 0.77, 1.0] {
            for conductor in
                [Conductor::new(ComplexIor::GOLD), Conductor::new(ComplexIor::COPPER), Conductor::perfect()]
            {
                check(Ggx::isotropic(alpha).unwrap(), conductor, &mut worst);
                check(Beckmann::isotropic(alpha).unwrap(), conductor, &mut worst);
            }
        }
        println!("column against the lobes: g within {worst:.2e} of its channel's largest value");
    }

    /// The added lobe's branch of the sampler takes single scattering's f·cos θi and density
    /// in its sampler's form (`single_at`): the density is `pdf`'s, bit for bit, and f is
    /// within 1e-5 of `eval`'s (relative, largest channel) on 20 000 random pairs of directions
    /// above the horizon per case, GGX and Beckmann, α from 0.05 to 1, gold and copper.
    #[test]
    fn single_at_matches_eval_and_pdf() {
        fn check<S: AlbedoTabulated>(slope: S, conductor: Conductor, worst: &mut f32) {
            let b = Compensated::with_scheme(slope, conductor, Compensation::KullaConty).unwrap();
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
