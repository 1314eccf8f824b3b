//! The albedo tables' interpolation error, for the report's figure: every shipped table
//! (conductor E(μ, α), dielectric R + T(μ, α, η) from both sides) looked up between its nodes
//! and compared with an adaptive quadrature of the crate's own single-scattering
//! `MicrofacetBsdf` — the model the tables tabulate, evaluated through the renderer API, so
//! the figure checks the table's interpolation and the generator's quadrature together.
//!
//! The quadrature runs over the normals visible from the view (`integrate_visible`, where
//! sharp and broad lobes are equally wide): each normal ωm maps to one reflected and one
//! refracted direction, and f·|cos θ| dω becomes f·|cos θ|·J(ωm) dωm with the Jacobians
//! J = dωi/dωm = 4|ωo·ωm| of the reflection and J = (ωo·ωm + η ωi·ωm)² / (η²|ωi·ωm|) of the
//! refraction (the inverses of Walter et al. 2007, eqs. 14 and 16).

use glam::Vec3;
use microsurface::compensation::{AlbedoTable, DielectricAlbedoTable};
use microsurface::{Beckmann, Bsdf, Conductor, Dielectric, Ggx, MicrofacetBsdf, Technique, Transport};
use validation::quadrature::{SlopeFamily, VisibleTolerance, integrate_visible};

/// The roughnesses of the curves: between the tables' nodes (r = √α on 32 or 16 nodes).
pub const TABLE_ALPHAS: [f32; 4] = [0.03, 0.12, 0.4, 0.9];

/// The relative index of the dielectric panels (between η nodes), and its inverse from inside.
pub const TABLE_ETA: f32 = 1.45;

/// The smallest direction cosine of the curves (log axis down to it).
pub const MIN_MU: f64 = 1e-3;

/// The quadrature's tolerances: far below the table errors the figure resolves (≳ 1e-5).
const TOLERANCE: VisibleTolerance = VisibleTolerance { abs_tol: 1e-6, rel_tol: 1e-6, max_depth: 5 };

/// The slope family of a panel.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Family {
    Ggx,
    Beckmann,
}

impl Family {
    pub const ALL: [Family; 2] = [Family::Ggx, Family::Beckmann];

    pub fn label(self) -> &'static str {
        match self {
            Family::Ggx => "GGX",
            Family::Beckmann => "Beckmann",
        }
    }
}

/// What a panel tabulates.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Tabulated {
    /// The conductor's E(μ, α) with F = 1.
    Conductor,
    /// The dielectric's R + T seen from outside, η = [`TABLE_ETA`].
    DielectricOutside,
    /// The dielectric's R + T seen from inside, η = 1/[`TABLE_ETA`].
    DielectricInside,
}

impl Tabulated {
    pub const ALL: [Tabulated; 3] =
        [Tabulated::Conductor, Tabulated::DielectricOutside, Tabulated::DielectricInside];

    pub fn label(self) -> String {
        match self {
            Tabulated::Conductor => "conductor E (F = 1)".into(),
            Tabulated::DielectricOutside => format!("dielectric R + T, η = {TABLE_ETA}"),
            Tabulated::DielectricInside => format!("dielectric R + T, η = 1/{TABLE_ETA}"),
        }
    }

    /// The relative index seen by the light (1 for the conductor).
    fn eta(self) -> f32 {
        match self {
            Tabulated::Conductor => 1.0,
            Tabulated::DielectricOutside => TABLE_ETA,
            Tabulated::DielectricInside => 1.0 / TABLE_ETA,
        }
    }
}

/// One curve: table − quadrature against μ at one α.
#[derive(Debug, Clone)]
pub struct TableCurve {
    pub family: Family,
    pub tabulated: Tabulated,
    pub alpha: f32,
    /// (μ, table value, quadrature value).
    pub points: Vec<(f64, f64, f64)>,
}

impl TableCurve {
    /// The largest |table − quadrature| of the curve.
    pub fn max_error(&self) -> f64 {
        self.points.iter().map(|&(_, t, q)| (t - q).abs()).fold(0.0, f64::max)
    }
}

/// The direction cosines of a curve: log-spaced from [`MIN_MU`] to 1.
pub fn mus(count: usize) -> Vec<f64> {
    let n = count.max(2);
    (0..n).map(|i| MIN_MU.powf(1.0 - i as f64 / (n - 1) as f64)).collect()
}

/// Every (family, tabulated, α) job of the figure, at the roughnesses `alphas`.
pub fn jobs(alphas: &[f32]) -> Vec<(Family, Tabulated, f32)> {
    let mut jobs = Vec::new();
    for family in Family::ALL {
        for tabulated in Tabulated::ALL {
            for &alpha in alphas {
                jobs.push((family, tabulated, alpha));
            }
        }
    }
    jobs
}

/// One curve at `count` direction cosines.
pub fn curve(family: Family, tabulated: Tabulated, alpha: f32, count: usize) -> TableCurve {
    let points = mus(count)
        .into_iter()
        .map(|mu| {
            let (table, quadrature) = match family {
                Family::Ggx => point(Ggx::isotropic(alpha).expect("valid α"), family, tabulated, alpha, mu),
                Family::Beckmann => {
                    point(Beckmann::isotropic(alpha).expect("valid α"), family, tabulated, alpha, mu)
                }
            };
            (mu, table, quadrature)
        })
        .collect();
    TableCurve { family, tabulated, alpha, points }
}

/// The table value and the quadrature at one (μ, α).
fn point<S: SlopeFamily>(slope: S, family: Family, tabulated: Tabulated, alpha: f32, mu: f64) -> (f64, f64) {
    let mu32 = mu as f32;
    let wo = Vec3::new((1.0 - mu * mu).max(0.0).sqrt() as f32, 0.0, mu32);
    let table = match tabulated {
        Tabulated::Conductor => {
            let table = if family == Family::Ggx { AlbedoTable::GGX } else { AlbedoTable::BECKMANN };
            f64::from(table.directional(mu32, alpha).expect("in the table's range"))
        }
        _ => {
            let table = if family == Family::Ggx {
                DielectricAlbedoTable::GGX
            } else {
                DielectricAlbedoTable::BECKMANN
            };
            let v = table.albedo(mu32, alpha, tabulated.eta()).expect("in the table's range");
            f64::from(v.reflected) + f64::from(v.transmitted)
        }
    };
    let quadrature = match tabulated {
        Tabulated::Conductor => {
            let bsdf = MicrofacetBsdf::new(slope, Conductor::perfect())
                .expect("valid conductor")
                .with_technique(Technique::SingleScattering);
            albedo(&bsdf, slope, wo, 1.0)
        }
        _ => {
            let eta = tabulated.eta();
            let bsdf = MicrofacetBsdf::new(slope, Dielectric::new(eta).expect("valid η"))
                .expect("valid dielectric")
                .with_technique(Technique::SingleScattering)
                .with_transport(Transport::Importance);
            albedo(&bsdf, slope, wo, eta)
        }
    };
    (table, quadrature)
}

/// ∫ f(ωo, ωi)|cos θi| dωi of a single-scattering BSDF seen from `wo` (above the surface), by
/// quadrature over the normals visible from `wo`: the reflection, and for `eta` ≠ 1 the
/// refraction into the other side (relative index `eta`, transmitted over incident).
fn albedo<S: SlopeFamily>(bsdf: &impl Bsdf, slope: S, wo: Vec3, eta: f32) -> f64 {
    let transmits = eta != 1.0;
    let eta = f64::from(eta);
    let alpha = (slope.alpha_x(), slope.alpha_y());
    integrate_visible(alpha, S::TAILS.cross_map(), wo, TOLERANCE, |m| {
        let (o, n) = (wo.as_dvec3(), m.as_dvec3());
        let c = o.dot(n);
        if c <= 0.0 {
            return 0.0;
        }
        let mut sum = 0.0;
        let wr = (2.0 * c * n - o).normalize();
        if wr.z > 0.0 {
            let f = f64::from(bsdf.eval(wo, wr.as_vec3()).f.x);
            sum += f * wr.z * 4.0 * c;
        }
        if transmits {
            let sin2_t = (1.0 - c * c) / (eta * eta);
            if sin2_t < 1.0 {
                let cos_t = (1.0 - sin2_t).sqrt();
                let wt = ((c / eta - cos_t) * n - o / eta).normalize();
                if wt.z < 0.0 {
                    let f = f64::from(bsdf.eval(wo, wt.as_vec3()).f.x);
                    let ct = wt.dot(n);
                    let jacobian = (c + eta * ct).powi(2) / (eta * eta * ct.abs());
                    sum += f * (-wt.z) * jacobian;
                }
            }
        }
        sum
    })
}
