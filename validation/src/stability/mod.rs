//! The crate's stability report: the accuracy map (worst cases per function of the f32 crate
//! against the double-precision reference model [`crate::reference`] on a dense grid over
//! the whole parameter domain) and the stiff-walk table ([`stiff`]: white-furnace albedo ±
//! standard error and mean walk length of every estimator at α = 1e-3, α = 4, θi = 1.57 rad
//! and near total internal reflection). Printed by `lab/src/bin/stability.rs`, asserted by
//! `tests/special/accuracy_map.rs` and `tests/walk/stiff.rs`.

pub mod stiff;

use crate::reference;

/// The whole stability report as markdown: the accuracy map, then the stiff-walk table.
pub fn markdown() -> String {
    let mut out = String::from("# Stability report\n\n## Accuracy map\n\n");
    out += &format!(
        "Error e = |value − reference| / max(|reference|, floor), reference in f64 (statrs) on the same \
         f32 inputs; floor = {:.0e} (relative error wherever |reference| ≥ 1e-30), {:.0e} for reflectances. \
         Grid: α log-spaced over [1e-4, 4] (12 isotropic, 5 anisotropic up to 1e4:1), cos θ from ±1 down to \
         1e-9 and exactly 0, 6 azimuths (4 for pairs of directions). Three worst cases per function.\n\n",
        reference::TINY,
        reference::REFLECTANCE_FLOOR
    );
    let map = reference::accuracy_map();
    out += &format!("{}\n", reference::markdown_table(&map));
    out += "## Stiff walks\n\n";
    out += &format!(
        "∫ eval dωo by importance sampling (mixture {:.0}% phase function + {:.0}% cosine, exact densities); \
         expected 1 (non-absorptive). Mean bounces of `sample()` against the stated bound.\n\n",
        100.0 * stiff::PHASE_SHARE,
        100.0 * (1.0 - stiff::PHASE_SHARE)
    );
    out += &format!("{}\n", stiff::markdown_table(&stiff::all_runs()));
    out
}
