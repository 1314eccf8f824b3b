//! The technique chooser's decision map (`microsurface::techniques::Choice`): for each slope
//! family and material, over the roughness α, the technique it picks per albedo error budget.
//! Deterministic (the chooser reads the crate's tables and its measured bounds), so the quick
//! and the full run draw the same map.

use microsurface::compensation::AlbedoTabulated;
use microsurface::techniques::{Budgeted, Choice, ChosenTechnique};
use microsurface::{Beckmann, ComplexIor, Conductor, Dielectric, Ggx};

/// The budgets of the map's panels (hemispherical albedo error).
pub const BUDGETS: [f32; 3] = [0.005, 0.01, 0.03];
/// Roughnesses per row, log-spaced over [`ALPHA_RANGE`].
pub const ALPHA_STEPS: usize = 61;
/// The map's roughness range.
pub const ALPHA_RANGE: (f32, f32) = (0.01, 2.0);

/// One row of the map: a slope family and a material, the choice per budget and roughness.
pub struct Row {
    pub label: String,
    /// `choices[budget][k]` at `alphas()[k]`.
    pub choices: Vec<Vec<Choice>>,
}

/// The map's roughnesses.
pub fn alphas() -> Vec<f32> {
    let (lo, hi) = ALPHA_RANGE;
    (0..ALPHA_STEPS).map(|k| lo * (hi / lo).powf(k as f32 / (ALPHA_STEPS - 1) as f32)).collect()
}

fn row<M: Budgeted>(label: String, material: M, ggx: bool) -> Row {
    fn over<S: AlbedoTabulated, M: Budgeted>(slope: impl Fn(f32) -> S, m: &M) -> Vec<Vec<Choice>> {
        BUDGETS
            .iter()
            .map(|&b| {
                alphas().iter().map(|&a| Choice::new(&slope(a), m, b).expect("valid α and budget")).collect()
            })
            .collect()
    }
    let choices = if ggx {
        over(|a| Ggx::isotropic(a).expect("valid α"), &material)
    } else {
        over(|a| Beckmann::isotropic(a).expect("valid α"), &material)
    };
    Row { label, choices }
}

/// Every row: GGX and Beckmann × F = 1, gold, copper, aluminium, glass of η ∈ {1.33, 1.5, 2}.
pub fn map() -> Vec<Row> {
    let mut rows = Vec::new();
    for (ggx, family) in [(true, "GGX"), (false, "Beckmann")] {
        for (name, ior) in [
            ("F = 1", None),
            ("gold", Some(ComplexIor::GOLD)),
            ("copper", Some(ComplexIor::COPPER)),
            ("aluminium", Some(ComplexIor::ALUMINIUM)),
        ] {
            let c = ior.map_or_else(Conductor::perfect, Conductor::new);
            rows.push(row(format!("{family} {name}"), c, ggx));
        }
        for eta in [1.33f32, 1.5, 2.0] {
            rows.push(row(format!("{family} glass {eta}"), Dielectric::new(eta).expect("valid η"), ggx));
        }
    }
    rows
}

/// A technique's short name.
pub fn short(t: ChosenTechnique) -> &'static str {
    match t {
        ChosenTechnique::SingleScattering => "single",
        ChosenTechnique::Compensated => "compensated",
        ChosenTechnique::RandomWalk => "walk",
    }
}

/// The choices along α in words: the technique of each run of roughnesses and where it
/// changes ("single < 0.11 ≤ compensated < 1.04 ≤ walk", the α of the map's grid).
pub fn transitions(choices: &[Choice]) -> String {
    let alphas = alphas();
    let mut s = short(choices[0].technique).to_string();
    for k in 1..choices.len() {
        if choices[k].technique != choices[k - 1].technique {
            s.push_str(&format!(" < {:.3} ≤ {}", alphas[k], short(choices[k].technique)));
        }
    }
    s
}
