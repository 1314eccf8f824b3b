//! The accuracy map: every f32 function of the crate against a double-precision reference
//! (`validation/src/reference.rs`, statrs special functions) on a dense grid — α
//! log-spaced over [1e-4, 4] (12 isotropic values and 5 anisotropic pairs, ratios up to 1e4),
//! cos θ over [−1, 1] down to 1e-9 and exactly 0 at the horizon (and sin θ = 1e-20, 1e-30 at
//! the poles), several azimuths; Fresnel terms on 2005 cosines.
//!
//! Error metric (see the reference module): e = |value − ref| / max(|ref|, floor); floor =
//! 1e-30 (relative error wherever |ref| ≥ 1e-30, well above the f32 subnormals), 1e-6 for
//! reflectances. Stated bounds, set by measurement on the functions without a defect:
//!
//! | group | bound | measured |
//! |---|---|---|
//! | Λ, G1, D, projected area, αᵢ | 1e-6 | 4.4e-7 (GGX D) |
//! | D_ωi | 5e-6 | 2.5e-6 (GGX, ωi below the horizon) |
//! | phase functions, single-scattering BSDFs | 1e-5 | 3.9e-6 (GGX dielectric reflection) |
//! | Fresnel terms | 1e-5 | 3.4e-6 (conductor) |
//!
//! Tests marked `#[ignore = "library bug: …"]` exceed their bound because of a defect found
//! here (root cause and fix in the report); un-ignore them once it is fixed.
use std::sync::OnceLock;
use validation::reference::{self, FunctionReport};

fn map() -> &'static [FunctionReport] {
    static MAP: OnceLock<Vec<FunctionReport>> = OnceLock::new();
    MAP.get_or_init(reference::accuracy_map)
}

/// Prints the worst cases of the functions whose name satisfies `select` and asserts their
/// bounds.
fn check(select: impl Fn(&str) -> bool) {
    let reports: Vec<FunctionReport> = map().iter().filter(|r| select(&r.name)).cloned().collect();
    assert!(!reports.is_empty(), "no function selected");
    println!("{}", reference::markdown_table(&reports));
    let failures: Vec<String> = reports
        .iter()
        .filter(|r| r.max_err() > r.bound)
        .map(|r| {
            let c = &r.worst[0];
            format!(
                "{}: error {:.3e} > {:.0e} at {} (value {:.9e}, reference {:.9e})",
                r.name, c.err, r.bound, c.params, c.value, c.reference
            )
        })
        .collect();
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

fn is(name: &str, prefix: &str, suffixes: &[&str]) -> bool {
    name.strip_prefix(prefix).is_some_and(|rest| suffixes.contains(&rest.trim()))
}

#[test]
fn ggx_direction_functions() {
    check(|n| is(n, "GGX", &["lambda", "g1", "d", "projected_area", "d_wi"]));
}

#[test]
fn beckmann_g1() {
    check(|n| is(n, "Beckmann", &["g1"]));
}

#[test]
fn beckmann_d() {
    check(|n| is(n, "Beckmann", &["d"]));
}

#[test]
fn beckmann_lambda_area_and_d_wi() {
    check(|n| is(n, "Beckmann", &["lambda", "projected_area", "d_wi"]));
}

#[test]
fn alpha_i() {
    check(|n| n.ends_with("alpha_i"));
}

#[test]
fn ggx_reflection_phase_functions_and_single_scattering() {
    check(|n| n.starts_with("GGX") && (n.contains("eval_phase") || n.contains("single")) && !transmission(n));
}

#[test]
fn beckmann_phase_functions_and_single_scattering() {
    check(|n| {
        n.starts_with("Beckmann") && (n.contains("eval_phase") || n.contains("single")) && !transmission(n)
    });
}

#[test]
fn dielectric_transmission() {
    check(transmission);
}

#[test]
fn fresnel_conductor() {
    check(|n| n == "fresnel_conductor");
}

#[test]
fn fresnel_dielectric() {
    check(|n| n.starts_with("fresnel_dielectric"));
}

/// Every function of the map is covered by exactly one test above.
#[test]
fn every_function_is_checked() {
    for r in map() {
        let n = r.name.as_str();
        let groups = [
            is(n, "GGX", &["lambda", "g1", "d", "projected_area", "d_wi"]),
            is(n, "Beckmann", &["g1"]),
            is(n, "Beckmann", &["d"]),
            is(n, "Beckmann", &["lambda", "projected_area", "d_wi"]),
            n.ends_with("alpha_i"),
            n.starts_with("GGX") && (n.contains("eval_phase") || n.contains("single")) && !transmission(n),
            n.starts_with("Beckmann")
                && (n.contains("eval_phase") || n.contains("single"))
                && !transmission(n),
            transmission(n),
            n == "fresnel_conductor",
            n.starts_with("fresnel_dielectric"),
        ];
        assert_eq!(groups.iter().filter(|&&g| g).count(), 1, "{n}");
    }
}

/// The transmission rows (phase functions and single scattering, both slopes).
fn transmission(name: &str) -> bool {
    name.contains("transmission")
}
