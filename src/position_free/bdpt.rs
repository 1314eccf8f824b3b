//! The bidirectional estimator (Wang et al. 2022, §4.2, eqs. 27–29), with the exact
//! per-strategy path densities and the balance heuristic.

use super::{BDPT_ROULETTE_FROM, PositionFree, Roulette};
use crate::contract::is_direction;
use crate::material::{Material, Side};
use crate::microsurface::ScatteringOrder;
use crate::path::{Exit, Incident, LAMBDA_RATIO_LOG_BELOW, PathModel};
use crate::path::{VertexRole, inv_g1};
use crate::rng::uniform;
use crate::slope::MicrosurfaceSlope;
use glam::{DVec3, Vec3};
use rand::Rng;

/// The longest sub-path: paths of up to 2 × 48 + 1 vertices are built. Longer paths carry a
/// negligible share of the energy (`tests/position_free/estimators.rs` bounds it below 1e-4).
pub const BDPT_MAX_SUBPATH: usize = 48;

/// A vertex of the camera sub-path, after the direction x_j was sampled at path vertex j.
#[derive(Debug, Clone, Copy)]
struct CameraVertex {
    /// The incident state at vertex j + 1: −x_j and its side.
    next: Incident,
    /// 1 + L̃ of that incident direction (the inverse of its masking).
    k_next: f64,
    /// Its connection to ωo (the last-vertex contribution without throughput).
    connection: DVec3,
    /// Product of the throughput ratios of vertices 1..=j (Russian roulette included).
    throughput: DVec3,
    /// Density of x_j given the incident direction at vertex j.
    pdf_forward: f64,
    /// Density of the incident direction at vertex j given x_j (the reverse density of x_{j−1}).
    pdf_reverse_prev: f64,
}

/// A vertex of the light sub-path, after its incident direction was sampled from its outgoing
/// one.
#[derive(Debug, Clone, Copy)]
struct LightVertex {
    /// The exit data of the reverse of its sampled incident direction: the outgoing direction
    /// of the next light vertex, and of the connection vertex of the strategies whose light
    /// side ends here.
    out_next: Exit,
    /// Product of the forward contributions / reverse densities of the light vertices so far.
    throughput: DVec3,
    /// Density of the incident direction given the outgoing one (how it was sampled).
    pdf_reverse: f64,
    /// Density of the outgoing direction given the incident one (0 for the vertex at ωo,
    /// whose outgoing direction is fixed).
    pdf_forward_out: f64,
}

// all bits zero (Side::Outside and None are the first variants): the slots are cleared, not copied
const EMPTY_CAMERA: CameraVertex = CameraVertex {
    next: Incident { w: Vec3::ZERO, side: Side::Outside },
    k_next: 0.0,
    connection: DVec3::ZERO,
    throughput: DVec3::ZERO,
    pdf_forward: 0.0,
    pdf_reverse_prev: 0.0,
};
const EMPTY_LIGHT: LightVertex = LightVertex {
    out_next: Exit { w: Vec3::ZERO, side: Side::Outside, lambda: None },
    throughput: DVec3::ZERO,
    pdf_reverse: 0.0,
    pdf_forward_out: 0.0,
};

/// The vertices of a sub-path stored inline; the rest go to an overflow array formed only when a
/// sub-path grows beyond them.
const INLINE_VERTICES: usize = 8;

/// The vertices of one sub-path: the first [`INLINE_VERTICES`] inline, the rest (up to
/// [`BDPT_MAX_SUBPATH`]) in an array formed only when the sub-path grows beyond them. Filling
/// all 48 slots of both sub-paths on every evaluation cost more than the connections of a
/// typical evaluation at α = 1 (DESIGN.md, “BDPT against PT”).
struct Vertices<T: Copy> {
    head: [T; INLINE_VERTICES],
    tail: Option<[T; BDPT_MAX_SUBPATH - INLINE_VERTICES]>,
    len: usize,
}

impl<T: Copy> Vertices<T> {
    /// No vertices; `empty` fills the slots.
    #[inline(always)]
    fn new(empty: T) -> Self {
        Self { head: [empty; INLINE_VERTICES], tail: None, len: 0 }
    }

    /// Appends a vertex (at most [`BDPT_MAX_SUBPATH`]); `empty` fills the overflow array when it
    /// is formed.
    #[inline(always)]
    fn push(&mut self, vertex: T, empty: T) {
        if self.len < INLINE_VERTICES {
            self.head[self.len] = vertex;
        } else {
            self.tail.get_or_insert([empty; BDPT_MAX_SUBPATH - INLINE_VERTICES])
                [self.len - INLINE_VERTICES] = vertex;
        }
        self.len += 1;
    }

    /// The vertex `i` (< the number pushed).
    #[inline(always)]
    fn get(&self, i: usize) -> &T {
        if i < INLINE_VERTICES {
            return &self.head[i];
        }
        match &self.tail {
            Some(tail) => &tail[i - INLINE_VERTICES],
            None => &self.head[INLINE_VERTICES - 1],
        }
    }
}

impl<S: MicrosurfaceSlope, M: Material> PositionFree<S, M> {
    /// Evaluates f·|cos θo| by bidirectional path tracing (Wang et al. 2022, eqs. 27–29).
    /// Unbiased and stochastic.
    ///
    /// A camera sub-path is sampled from ωi and a light sub-path from ωo (each with the
    /// phase-function sampler; the light sub-path samples incident directions from outgoing
    /// ones), each ended by Russian roulette from its second direction on (the camera's with
    /// the survival probability of [`PositionFree::eval_pt`], the light's with its throughput).
    /// Every pair of prefixes is joined through one connection vertex, and each path is
    /// weighted by the balance heuristic over all the ways of building a path of its length,
    /// P_s / Σ_t P_t with P_t = Π_{j≤t} p→(x_j) Π_{j>t} p←(x_j). Contributions are always
    /// evaluated from ωi to ωo, which keeps the non-reciprocal correlated model consistent.
    /// The densities are exact for conductors and dielectrics; for diffuse facets the MIS
    /// weights use [`Material::pdf_phase`]'s deterministic approximation. The weights still sum
    /// to one, which keeps the estimator unbiased in principle; in practice the approximation
    /// must also be small where a strategy's true density is negligible (a strategy given
    /// weight on paths it never samples loses their energy): below the horizon it is bounded
    /// by A(ωo)/(π A(ωi)), an upper bound of the true density (see [`crate::Diffuse`]).
    ///
    /// Invalid input ([policy](crate#invalid-input)): a `wi` or `wo` that is not a unit
    /// direction gives 0 (a debug assertion in debug builds).
    pub fn eval_bdpt(&self, wi: Vec3, wo: Vec3, order: ScatteringOrder, rng: &mut impl Rng) -> Vec3 {
        require!(is_direction(wi) && is_direction(wo), Vec3::ZERO; wi, wo);
        self.eval_bdpt_counted(wi, wo, order, rng).0
    }

    /// [`Self::eval_bdpt`] for validated directions, with the lengths of its camera and light
    /// sub-paths (sampled directions).
    #[inline(always)]
    pub(crate) fn eval_bdpt_counted(
        &self,
        wi: Vec3,
        wo: Vec3,
        order: ScatteringOrder,
        rng: &mut impl Rng,
    ) -> (Vec3, usize, usize) {
        let (Some(start), Some(wo_side)) =
            (PathModel::<S, M>::incident(wi), PathModel::<S, M>::exit_side(wo))
        else {
            return (Vec3::ZERO, 0, 0);
        };
        let last = order.last() as usize;
        let max_sub = (last - 1).min(BDPT_MAX_SUBPATH);
        let mut camera = Vertices::new(EMPTY_CAMERA);
        let mut light = Vertices::new(EMPTY_LIGHT);
        let to_wo = self.model.exit(wo, wo_side);
        let k_start = inv_g1(&self.model.slope, start.in_frame());
        // the (0, 0) connection (single scattering) first: the camera's roulette compares with it
        let single =
            order.includes(1).then(|| self.model.connect_known(start, k_start, to_wo, VertexRole::Last, rng));
        let roulette = Roulette::new(self, start, k_start, single);
        self.camera_subpath(start, k_start, to_wo, max_sub, &mut camera, &roulette, rng);
        self.light_subpath(to_wo, max_sub, &mut light, rng);
        let (n_camera, n_light) = (camera.len, light.len);
        let paths = Subpaths { start, k_start, to_wo, single, camera: &camera, light: &light };

        let mut sum = DVec3::ZERO;
        for s in 0..=n_camera {
            for t in 0..=n_light {
                let n = s + t + 1;
                if n > last || !order.includes(n as u32) {
                    continue;
                }
                let throughput = paths.throughput(s, t);
                if throughput == DVec3::ZERO {
                    continue;
                }
                let Some(c) = self.connect_subpaths(&paths, s, t, rng) else { continue };
                sum += throughput * c.contribution * paths.balance_weight(s, t, &c);
            }
        }
        (sum.as_vec3(), n_camera, n_light)
    }

    /// The connection of the first `s` camera directions to the first `t` light directions
    /// through one vertex (the camera end's incident direction to the light end's outgoing
    /// one): its contribution without the sub-paths' throughputs and the two densities of its
    /// direction pair; `None` where it contributes nothing. For t = 0 the connection to ωo,
    /// which the camera sub-path computed as it went (s ≥ 1).
    fn connect_subpaths(
        &self,
        paths: &Subpaths<'_>,
        s: usize,
        t: usize,
        rng: &mut impl Rng,
    ) -> Option<Connection> {
        let (at, k_at) = paths.camera_end(s);
        let out = paths.exit(t);
        let connection = if t == 0 {
            let (contribution, reverse) = match s {
                0 => (paths.single?, 0.0),
                _ => {
                    let contribution = paths.camera.get(s - 1).connection;
                    if contribution == DVec3::ZERO {
                        return None;
                    }
                    // p← from ωo, whose projected area is (1 + Λo) cos θo
                    let area =
                        out.lambda.and_then(|lambda| known_area(out.side.frame(out.w).z, 1.0 + lambda));
                    let reverse = at.towards(out).reversed().with_incident_area(area);
                    (
                        contribution,
                        f64::from(self.model.material.pdf_phase_unchecked(&self.model.slope, &reverse)),
                    )
                }
            };
            Connection { contribution, forward: 0.0, reverse }
        } else if k_at < LAMBDA_RATIO_LOG_BELOW || (M::VERTEX_HAS_INCIDENT_AREA && k_at < 1.0) {
            // a backfacing camera end whose Λ(−ωin) is below f64's range, or whose vertex term
            // carries Λ(−ωin) itself (diffuse facets: it underflows f32 below 1e-38, and the
            // connection was lost, BDPT's order 3 from below at a = 28.9 7.5 % low): v·S =
            // p·(k_in S) with the relative factor (see `connect_known`); the densities separately
            let factor = self.model.relative_shadowing(at, k_at, out).middle;
            if factor == 0.0 {
                return None;
            }
            let it = at.towards(out);
            let phase = self.model.material.eval_phase_unchecked(&self.model.slope, &it, rng);
            Connection {
                contribution: phase.as_dvec3() * factor,
                forward: f64::from(self.model.material.pdf_phase_unchecked(&self.model.slope, &it)),
                reverse: f64::from(
                    self.model.material.pdf_phase_unchecked(&self.model.slope, &it.reversed()),
                ),
            }
        } else {
            let factor = self.model.shadowing_factor(at, k_at, out, VertexRole::Middle);
            if factor == 0.0 {
                return None;
            }
            let (v, forward, reverse) =
                self.model.material.connection_unchecked(&self.model.slope, &at.towards(out), rng);
            Connection {
                contribution: v.as_dvec3() * factor,
                forward: f64::from(forward),
                reverse: f64::from(reverse),
            }
        };
        (connection.contribution != DVec3::ZERO).then_some(connection)
    }

    /// Samples up to `max` directions from ωi into `out`.
    #[allow(clippy::too_many_arguments)]
    fn camera_subpath(
        &self,
        start: Incident,
        k_start: f64,
        to_wo: Exit,
        max: usize,
        out: &mut Vertices<CameraVertex>,
        roulette: &Roulette,
        rng: &mut impl Rng,
    ) {
        let mut at = start;
        let mut k_at = k_start;
        let mut throughput = DVec3::ONE;
        for j in 0..max {
            let Some((next, k_next, ratio)) = self.extend_known(at, k_at, rng) else { return };
            throughput *= ratio;
            if throughput == DVec3::ZERO {
                return;
            }
            if j + 1 >= BDPT_ROULETTE_FROM {
                let q = roulette.survival(self, throughput, next, k_next);
                if f64::from(uniform(rng)) >= q {
                    return;
                }
                throughput /= q;
            }
            // the densities of x_j and of its reverse, with the projected areas A = (1 + L̃)cos θ
            // the step already knows (1 + Λ(x) for x facing up: 1 + k_next)
            let x = -next.w;
            let step = at.to(x, next.side).with_incident_area(known_area(at.in_frame().z, k_at));
            let pdf_forward = f64::from(self.model.material.pdf_phase_unchecked(&self.model.slope, &step));
            let reverse = step.reversed().with_incident_area(known_area(-next.in_frame().z, 1.0 + k_next));
            let pdf_reverse_prev =
                f64::from(self.model.material.pdf_phase_unchecked(&self.model.slope, &reverse));
            // the connection of the new vertex to ωo, the (s, 0) strategy's
            let connection = self.model.connect_known(next, k_next, to_wo, VertexRole::Last, rng);
            let vertex = CameraVertex { next, k_next, connection, throughput, pdf_forward, pdf_reverse_prev };
            out.push(vertex, EMPTY_CAMERA);
            (at, k_at) = (next, k_next);
        }
    }

    /// Samples up to `max` incident directions backwards from ωo (exit data `to_wo`) into
    /// `out`. Each vertex contributes v(ωin, ωout)·S / p←(ωin | ωout), where
    /// v/p← = w·(ηo/ηi)²·A(ωout)/|cos θin| (w: the sample weight, A: the projected area of
    /// ωout in its side frame).
    fn light_subpath(&self, to_wo: Exit, max: usize, out: &mut Vertices<LightVertex>, rng: &mut impl Rng) {
        let mut b = to_wo;
        let mut throughput = DVec3::ONE;
        for i in 0..max {
            let s = self.model.material.sample_phase_unchecked(&self.model.slope, b.w, b.side, rng);
            let a = Incident { w: s.wo, side: s.side };
            let a_frame = a.in_frame();
            let k_in = inv_g1(&self.model.slope, a_frame);
            if a.w.z == 0.0 || k_in == 0.0 || !k_in.is_finite() {
                return;
            }
            // the vertex at ωo is the path's last, every later one a middle vertex
            let role = if i == 0 { VertexRole::Last } else { VertexRole::Middle };
            // A(ωout) = (1 + Λ(ωout)) cos θout where ωout faces up in its frame (Λ known)
            let b_frame_z = b.side.frame(b.w).z;
            let b_area = b.lambda.and_then(|lambda| known_area(b_frame_z, 1.0 + lambda));
            let factor = self.model.shadowing_factor(a, k_in, b, role)
                * f64::from(self.model.material.relative_eta_sq(a.side, b.side))
                * f64::from(
                    b_area.unwrap_or_else(|| self.model.slope.projected_area_unchecked(b.side.frame(b.w))),
                )
                / f64::from(a.w.z.abs());
            throughput *= s.weight.as_dvec3() * factor;
            if throughput == DVec3::ZERO || !throughput.is_finite() {
                return;
            }
            if i + 1 >= BDPT_ROULETTE_FROM {
                let q = throughput.max_element().min(1.0);
                if f64::from(uniform(rng)) >= q {
                    return;
                }
                throughput /= q;
            }
            let step = a.to(b.w, b.side).with_incident_area(known_area(a_frame.z, k_in));
            let reverse = step.reversed().with_incident_area(b_area);
            let pdf_reverse = f64::from(self.model.material.pdf_phase_unchecked(&self.model.slope, &reverse));
            let pdf_forward_out = if i == 0 {
                0.0
            } else {
                f64::from(self.model.material.pdf_phase_unchecked(&self.model.slope, &step))
            };
            // −a can leave the surface where a points down in its frame, and then its Λ is
            // 1 + L̃ of a (Λ(−ω) = −1 − Λ(ω)): the exit data without another Λ
            let out_next = Exit { w: -a.w, side: a.side, lambda: (a_frame.z < 0.0).then_some(k_in) };
            out.push(LightVertex { out_next, throughput, pdf_reverse, pdf_forward_out }, EMPTY_LIGHT);
            b = out_next;
        }
    }
}

/// The camera and light sub-paths of one bidirectional evaluation with the data their
/// connections share.
struct Subpaths<'a> {
    /// The incident state at the first vertex (ωi).
    start: Incident,
    /// 1 + L̃ of ωi in its side frame.
    k_start: f64,
    /// The exit data of ωo.
    to_wo: Exit,
    /// The (0, 0) connection (single scattering), where the evaluated orders include it.
    single: Option<DVec3>,
    /// The sampled camera vertices.
    camera: &'a Vertices<CameraVertex>,
    /// The sampled light vertices.
    light: &'a Vertices<LightVertex>,
}

impl Subpaths<'_> {
    /// The incident state and its 1 + L̃ at the end of the first `s` camera directions.
    #[inline(always)]
    fn camera_end(&self, s: usize) -> (Incident, f64) {
        match s {
            0 => (self.start, self.k_start),
            _ => {
                let v = self.camera.get(s - 1);
                (v.next, v.k_next)
            }
        }
    }

    /// The exit data of the outgoing direction at the end of the first `t` light directions:
    /// ωo for t = 0.
    #[inline(always)]
    fn exit(&self, t: usize) -> Exit {
        match t {
            0 => self.to_wo,
            _ => self.light.get(t - 1).out_next,
        }
    }

    /// The product of the two sub-paths' throughputs for the prefixes of lengths `s`, `t`.
    #[inline(always)]
    fn throughput(&self, s: usize, t: usize) -> DVec3 {
        let camera = if s == 0 { DVec3::ONE } else { self.camera.get(s - 1).throughput };
        let light = if t == 0 { DVec3::ONE } else { self.light.get(t - 1).throughput };
        camera * light
    }

    /// The balance-heuristic weight of the path of `s` camera directions, the connection `c`
    /// and `t` light directions (n = s + t + 1 vertices, directions x_1 … x_{n−1}), from the
    /// densities the sub-paths stored ([`balance_weight_of`]).
    #[inline(always)]
    fn balance_weight(&self, s: usize, t: usize, c: &Connection) -> f64 {
        let n = s + t + 1;
        // p→(x_j): camera steps, then the connection, then the light steps read forwards
        let forward = |j: usize| {
            if j <= s {
                self.camera.get(j - 1).pdf_forward
            } else if j == s + 1 {
                c.forward
            } else {
                self.light.get(n - j).pdf_forward_out
            }
        };
        // p←(x_j): the camera's reverse densities, the connection's, then the light's sampled ones
        let reverse = |j: usize| {
            if j < s {
                self.camera.get(j).pdf_reverse_prev
            } else if j == s {
                c.reverse
            } else {
                self.light.get(n - j - 1).pdf_reverse
            }
        };
        balance_weight_of(n - 1, s, forward, reverse)
    }
}

/// One connection between the sub-paths: its contribution and the densities of its direction
/// pair, p→ of the connecting direction from the camera side and p← of the camera end's
/// incident direction given it.
#[derive(Debug, Clone, Copy)]
struct Connection {
    contribution: DVec3,
    forward: f64,
    reverse: f64,
}

/// The projected area A(ω) = (1 + L̃(ω)) cos θ of a direction facing up in its side frame
/// (z-component `z` > 0) with 1 + L̃ = `k` known, rounded once to f32 (`None` otherwise: the
/// materials form a backfacing direction's density in f64 from the slope): the area the
/// densities of [`Material::pdf_phase`] would otherwise evaluate again.
#[inline(always)]
fn known_area(z: f32, k: f64) -> Option<f32> {
    (z > 0.0).then(|| (k * f64::from(z)) as f32)
}

/// The balance-heuristic weight P_s / Σ_t P_t of the strategy that sampled s directions
/// from the camera side, for a path whose directions x_1 … x_{n−1} have forward densities
/// `forward[j−1]` and reverse densities `reverse[j−1]` (P_t = Π_{j≤t} p→_j Π_{j>t} p←_j).
#[cfg(test)]
fn balance_weight(forward: &[f64], reverse: &[f64], s: usize) -> f64 {
    balance_weight_of(forward.len(), s, |j| forward[j - 1], |j| reverse[j - 1])
}

/// The balance-heuristic weight P_s / Σ_t P_t of the strategy that sampled s of the `dirs`
/// directions x_1 … x_dirs from the camera side, with the forward and reverse densities of x_j
/// given by `forward(j)` and `reverse(j)` (P_t = Π_{j≤t} p→_j Π_{j>t} p←_j). Computed from the
/// ratios P_t/P_s, whose factors are sampled densities (> 0).
#[inline(always)]
fn balance_weight_of(
    dirs: usize,
    s: usize,
    forward: impl Fn(usize) -> f64,
    reverse: impl Fn(usize) -> f64,
) -> f64 {
    let mut total = 1.0;
    let mut r = 1.0;
    for j in (s + 1)..=dirs {
        r *= density_ratio(forward(j), reverse(j));
        total += r;
    }
    r = 1.0;
    for j in (1..=s).rev() {
        r *= density_ratio(reverse(j), forward(j));
        total += r;
    }
    if total.is_finite() { 1.0 / total } else { 0.0 }
}

/// The factor p_other/p_sampled of one direction in the ratio P_t/P_s of two strategies' path
/// densities: 0 where the other strategy's density is 0 (it cannot sample the direction),
/// whatever the sampled strategy's density evaluated to. A direction the estimator sampled
/// has a positive density, but `pdf_phase` at the f32 direction can be 0 where f32 does not
/// resolve the phase function's lobe (a backfacing incident direction of a smooth Beckmann
/// surface whose visible normals have ωi·ωm ≲ 1e-6, see [`PositionFree::sample_single`]):
/// 0/0 made the balance weight NaN and dropped the path. At a = 28.9 (α = 0.02, θi = 120°)
/// this hit 3 % of the camera steps while the reflection half vector was formed from the
/// unnormalized f32 directions (BDPT's albedo from below was 0.991 instead of 1), and none
/// since. Where only the sampled density is 0, the ratio is +∞ and the weight 0.
#[inline(always)]
fn density_ratio(other: f64, sampled: f64) -> f64 {
    if other == 0.0 { 0.0 } else { other / sampled }
}

#[cfg(test)]
mod tests {
    use super::balance_weight;

    #[test]
    fn balance_weights_of_all_strategies_sum_to_one() {
        let forward = [0.3, 2.0, 0.7, 1.1];
        let reverse = [0.9, 0.4, 1.5, 0.2];
        let total: f64 = (0..=forward.len()).map(|s| balance_weight(&forward, &reverse, s)).sum();
        assert!((total - 1.0).abs() < 1e-12, "{total}");
    }
}
