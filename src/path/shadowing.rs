//! Full-spherical masking and the per-vertex shadowing factors of the position-free path
//! integral (Wang et al. 2022, §3.3–3.4), for both height models.

use crate::material::Event;
use crate::slope::MicrosurfaceSlope;
use crate::special::ln_gamma;
use glam::Vec3;

/// How the shadowing of consecutive segments is correlated through the microsurface heights.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Shadowing {
    /// Height-uncorrelated (Wang et al. 2022, §3.3): products of full-spherical G1 terms.
    /// Reciprocal.
    Uncorrelated,
    /// Height-correlated (Wang et al. 2022, §3.4, eqs. 17–23): closer to the height-tracing
    /// random walk of Heitz et al. 2016, not reciprocal.
    #[default]
    Correlated,
}

/// 1 + L̃(ω) = |1 + Λ(ω)| for an incident direction ω in its side frame: the inverse of the
/// full-spherical masking G1(ω) = 1/|1 + Λ(ω)| (Wang et al. 2022, eq. 10), which exceeds 1
/// for light arriving from below the macrosurface. Below the horizon |1 + Λ(ω)| = Λ(−ω) is
/// evaluated directly, without cancellation, and in f64 ([`MicrosurfaceSlope::lambda64`]):
/// it is tiny there for small α. In [0, ∞]: 0 straight from below, and also where Λ(−ω)
/// underflows f64 (Beckmann, |cot θ|/αᵢ > 26.6; the masking ratios of such a vertex are then
/// formed from ln Λ, see `PositionFree::relative_shadowing`).
///
/// Saturates at [`LAMBDA_SATURATION`] (exactly grazing directions, where the exact value is +∞).
#[inline(always)]
pub(crate) fn inv_g1<S: MicrosurfaceSlope>(slope: &S, w: Vec3) -> f64 {
    let k = if w.z >= 0.0 { 1.0 + slope.lambda64(w) } else { slope.lambda64(-w) };
    k.min(LAMBDA_SATURATION)
}

/// The largest Λ and 1 + L̃ the shadowing factors take (`f32::MAX`, as the f32 Λ saturates):
/// at exactly grazing directions the exact value is +∞, which would turn
/// ln Γ(1 + k) − ln Γ(1 + k + Λ) into ∞ − ∞. Every factor is 0 or 1 to f64 precision from
/// far below it on.
pub(crate) const LAMBDA_SATURATION: f64 = f32::MAX as f64;

/// The role of a vertex in a path: the one the path leaves the microsurface from, or one it
/// continues from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum VertexRole {
    /// The path leaves through the outgoing direction.
    Last,
    /// The path continues along the outgoing direction.
    /// (Only the multiple-bounce estimators continue a path.)
    #[cfg_attr(not(feature = "position-free"), allow(dead_code))]
    Middle,
}

/// The shadowing factors of one vertex: `last` when the path leaves through the outgoing
/// direction, `middle` when it continues (Wang et al. 2022, eqs. 7–8, 12–13 and 17–23,
/// regrouped per vertex as incident masking × exit or continue factor).
///
/// `k_in` = 1 + L̃ of the incident direction, `exit` = Λ of the outgoing direction in its own
/// side frame where it can exit (points up there), `None` where it cannot; the [`Event`] tells
/// whether the vertex keeps the side.
#[derive(Debug, Clone, Copy)]
pub(crate) struct VertexShadowing {
    /// Factor if this is the last vertex (0 when the outgoing direction cannot exit).
    pub last: f64,
    /// Factor if the path continues.
    pub middle: f64,
}

impl VertexShadowing {
    /// The factor of a vertex in the given role.
    #[inline(always)]
    pub(crate) fn factor(self, role: VertexRole) -> f64 {
        match role {
            VertexRole::Last => self.last,
            VertexRole::Middle => self.middle,
        }
    }
}

impl Shadowing {
    /// The shadowing factors of a vertex relative to its incident masking, k_in × S
    /// ([`Self::vertex`]), i.e. the factors by which the phase function p = v·k_in (rather
    /// than the vertex term v) is multiplied. `ratio` = Λo/k_in, which the caller forms
    /// without underflow.
    ///
    /// | | uncorrelated | correlated, reflection | correlated, transmission |
    /// |---|---|---|---|
    /// | last | 1/(1 + Λo) | 1/(1 + ratio) | k_in B(k_in, 1 + Λo) |
    /// | middle, can exit | Λo/(1 + Λo) | 1/(1 + 1/ratio) | 1 − k_in B(k_in, 1 + Λo) |
    /// | middle, cannot exit | 1 | 1 | 1 |
    ///
    /// Unlike k_in × [`Self::vertex`] this stays exact where k_in underflows: for a backfacing
    /// incident direction of a low-roughness Beckmann surface k_in = Λ(−ωin) and Λo are both
    /// of order e^{−a²}, and only their ratio matters. ratio = ∞ (k_in = 0 straight from
    /// below) gives last = 0, middle = 1. Relative error a few f64 ulps.
    #[inline]
    pub(crate) fn relative(self, k_in: f64, exit: Option<f64>, ratio: f64, event: Event) -> VertexShadowing {
        let Some(lambda_out) = exit else {
            return VertexShadowing { last: 0.0, middle: 1.0 };
        };
        match (self, event) {
            (Shadowing::Uncorrelated, _) => {
                let g1_out = 1.0 / (1.0 + lambda_out);
                VertexShadowing { last: g1_out, middle: lambda_out * g1_out }
            }
            (Shadowing::Correlated, Event::Reflection) => {
                VertexShadowing { last: 1.0 / (1.0 + ratio), middle: 1.0 / (1.0 + 1.0 / ratio) }
            }
            (Shadowing::Correlated, Event::Transmission) => {
                let ln_kb =
                    ln_gamma(1.0 + k_in) + ln_gamma(1.0 + lambda_out) - ln_gamma(1.0 + k_in + lambda_out);
                VertexShadowing { last: ln_kb.exp(), middle: -ln_kb.exp_m1() }
            }
        }
    }

    /// The shadowing factors of a vertex. With G1in = 1/k_in and Λo = `lambda_out`:
    ///
    /// | | uncorrelated | correlated, reflection | correlated, transmission |
    /// |---|---|---|---|
    /// | last | G1in/(1 + Λo) | 1/(k_in + Λo) | B(k_in, 1 + Λo) |
    /// | middle, can exit | G1in Λo/(1 + Λo) | G1in − 1/(k_in + Λo) | G1in − B(k_in, 1 + Λo) |
    /// | middle, cannot exit | G1in | G1in | G1in |
    ///
    /// The correlated middle factors are the differences written without cancellation:
    /// Λo/(k_in (k_in + Λo)) and −expm1(ln Γ(1 + k_in) + ln Γ(1 + Λo) − ln Γ(1 + k_in + Λo))/k_in.
    /// Both are ≥ 0 without clamping (for G1in > 1 too, see DESIGN.md, “Departures from the released code”).
    #[inline]
    pub(crate) fn vertex(self, k_in: f64, exit: Option<f64>, event: Event) -> VertexShadowing {
        let g1_in = 1.0 / k_in;
        let Some(lambda_out) = exit else {
            return VertexShadowing { last: 0.0, middle: g1_in };
        };
        match (self, event) {
            (Shadowing::Uncorrelated, _) => {
                let g1_out = 1.0 / (1.0 + lambda_out);
                VertexShadowing { last: g1_in * g1_out, middle: g1_in * lambda_out * g1_out }
            }
            (Shadowing::Correlated, Event::Reflection) => {
                let last = 1.0 / (k_in + lambda_out);
                VertexShadowing { last, middle: lambda_out * last * g1_in }
            }
            (Shadowing::Correlated, Event::Transmission) => {
                // k_in B(k_in, 1 + Λo) = exp(ln_kb)
                let ln_kb =
                    ln_gamma(1.0 + k_in) + ln_gamma(1.0 + lambda_out) - ln_gamma(1.0 + k_in + lambda_out);
                VertexShadowing { last: ln_kb.exp() * g1_in, middle: -ln_kb.exp_m1() * g1_in }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::special::beta;

    #[test]
    fn correlated_transmission_matches_the_beta_function() {
        for (k, l) in [(1.0, 0.5), (1.3, 2.0), (0.2, 7.0), (40.0, 1e-9)] {
            let v = Shadowing::Correlated.vertex(k, Some(l), Event::Transmission);
            let b = beta(k, 1.0 + l);
            assert!((v.last - b).abs() <= 1e-12 * b, "{k} {l}: {} vs {b}", v.last);
            assert!((v.middle - (1.0 / k - b)).abs() <= 1e-9 / k, "{k} {l}");
            assert!(v.middle >= 0.0);
        }
    }
}
