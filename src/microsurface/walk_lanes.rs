//! The random walk in lanes: many walks of [`Microsurface::sample`] at once, eight in flight,
//! each lane refilled with the next query when its walk ends (supplement §3.1, Algorithm 3).
//!
//! A lane carries one path: its ray, its height (ln C¹, or the undrawn rate of an opaque
//! walk, `walk::Depth`), its weight, its bounce count, and its own generator. Every formula is
//! the scalar walk's kernel: Λ ([`lambda_and_area_of`]), the height step
//! ([`escapes_without_log`], [`step_ln_c1`], the logarithm `ln_f32` lane by lane), the
//! spherical-cap visible normal ([`sample_spherical_cap_of`]), the reflection and its Newton
//! renormalization, the Fresnel term ([`reflectance_of`]); the rare forms the scalar walk
//! branches to (a cap point near −v̂, a Fresnel cosine below 0.05, a reflection far from unit
//! length) are the scalar material's sampler for that lane. The lanes draw their uniforms from
//! their own generators, so a walk in lanes is not the scalar walk's bits but the same
//! distribution (two-sample tests per order in `tests/walk/lanes.rs`).

use super::Microsurface;
use super::geometry::{escapes_without_log, step_ln_c1};
use super::walk::{MAX_BOUNCES, WalkSample};
use crate::error::Error;
use crate::fresnel::reflectance_of;
use crate::height::MicrosurfaceHeight;
use crate::lanes::{F32x8, LaneLoop, Lanes, V3, WIDTH, dispatch};
use crate::material::{LaneMaterial, Material};
use crate::rng::TAIL_CUT;
use crate::slope::{MicrosurfaceSlope, lambda_and_area_of, sample_spherical_cap_of};
use crate::soa::{Channels, Directions, check_len};
use crate::special::ln_f32;
use glam::{Vec3, Vec3A};
use rand::SeedableRng;

/// The outputs of [`Microsurface::sample_batch`], one element per query: the exit direction,
/// the weight f·|cos θo|/pdf and the number of bounces, 0 where [`Microsurface::sample`]
/// returns `None` (then the direction and the weight are 0).
#[derive(Debug)]
pub struct WalkOutputs<'a> {
    /// The exit directions ωo.
    pub wo: Channels<'a>,
    /// The weights per RGB channel.
    pub weight: Channels<'a>,
    /// The bounces of each walk (0: no sample).
    pub bounces: &'a mut [u32],
}

impl WalkOutputs<'_> {
    fn check(&self, n: usize) -> Result<(), Error> {
        self.wo.check("wo", n)?;
        self.weight.check("weight", n)?;
        check_len("bounces", n, self.bounces.len())
    }

    #[inline]
    fn set(&mut self, i: usize, s: Option<WalkSample>) {
        match s {
            Some(s) => {
                self.wo.set(i, s.wo);
                self.weight.set(i, s.weight);
                self.bounces[i] = s.bounces;
            }
            None => {
                self.wo.set(i, Vec3::ZERO);
                self.weight.set(i, Vec3::ZERO);
                self.bounces[i] = 0;
            }
        }
    }
}

/// The splitmix64 state of query `i`'s stream from `seed` (a lane's generator is reseeded with
/// each query, so that query i's walk depends on (seed, i) only, not on the lane or the order
/// in which the lanes finish).
#[inline(always)]
fn stream(seed: u64, i: usize) -> u64 {
    mix64(seed ^ mix64((i as u64).wrapping_add(0x632b_e59b_d9b4_e019)))
}

/// The splitmix64 finalizer.
#[inline(always)]
fn mix64(z: u64) -> u64 {
    let z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    let z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// splitmix64's increment.
const GOLDEN: u64 = 0x9e37_79b9_7f4a_7c15;

/// 2⁻²⁴.
const INV_2_POW_24: f32 = 1.0 / 16_777_216.0;

/// Eight splitmix64 generators (Steele, Lea and Flood 2014), one per lane.
struct LaneRng([u64; WIDTH]);

impl LaneRng {
    /// Two uniforms per lane from one 64-bit output, as `rng::uniform_pair` forms them: the 24
    /// high bits of the low word and the top 24 bits.
    #[inline(always)]
    fn pair(&mut self) -> (F32x8, F32x8) {
        let (mut a, mut b) = ([0.0f32; WIDTH], [0.0f32; WIDTH]);
        for k in 0..WIDTH {
            self.0[k] = self.0[k].wrapping_add(GOLDEN);
            let bits = mix64(self.0[k]);
            a[k] = ((bits as u32) >> 8) as f32 * INV_2_POW_24;
            b[k] = (bits >> 40) as f32 * INV_2_POW_24;
        }
        (F32x8(a), F32x8(b))
    }
}

/// ln(1 − cut_tails(u)) in each lane (the walks' logarithm, `ln_f32`), and 1 − cut_tails(u).
#[inline(always)]
fn ln_one_minus(u: F32x8) -> (F32x8, F32x8) {
    let one_minus_u = F32x8::lit(1.0) - u.clamp(F32x8::lit(TAIL_CUT), F32x8::lit(1.0 - TAIL_CUT));
    (F32x8(one_minus_u.0.map(ln_f32)), one_minus_u)
}

/// The walks of a GGX conductor in lanes.
struct WalkLoop<'s, 'a, 'b, H, S, M> {
    surface: &'s Microsurface<H, S, M>,
    ax: f32,
    ay: f32,
    fresnel: Option<(Vec3A, Vec3A)>,
    wi: &'s Directions<'a>,
    seed: u64,
    out: &'s mut WalkOutputs<'b>,
}

/// The state of the eight lanes.
struct Lanes8 {
    /// The ray leaving the current point (−ωi at the start).
    wr: V3<F32x8>,
    /// ln C¹ (≤ 0), or the rate of an undrawn depth (> 0); 0 above the surface.
    depth: F32x8,
    weight: [F32x8; 3],
    bounces: [u32; WIDTH],
    /// The query of each lane; `usize::MAX` for an idle lane.
    query: [usize; WIDTH],
    rng: LaneRng,
}

impl<H: MicrosurfaceHeight, S: MicrosurfaceSlope, M: Material> WalkLoop<'_, '_, '_, H, S, M> {
    /// The scalar walk for query `i` (outside the lanes' domain: a view from below, an invalid
    /// direction), from its own generator.
    #[inline(never)]
    fn scalar(&mut self, i: usize) {
        let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(stream(self.seed, i));
        self.out.set(i, self.surface.sample(self.wi.get(i), &mut rng));
    }

    /// Starts query `i` in lane `k` if the lanes walk it; otherwise answers it with the scalar
    /// walk and returns false.
    #[inline(never)]
    fn start(&mut self, lanes: &mut Lanes8, k: usize, i: usize) -> bool {
        let wi = self.wi.get(i);
        // the lanes walk from above: a unit ωi with ωi.z > 0 (`Microsurface::sample` checks
        // the same); a transparent or absorbing start is the scalar walk's
        if !(crate::contract::is_direction(wi) && wi.z > 0.0) {
            self.scalar(i);
            return false;
        }
        lanes.wr.x.0[k] = -wi.x;
        lanes.wr.y.0[k] = -wi.y;
        lanes.wr.z.0[k] = -wi.z;
        lanes.depth.0[k] = 0.0;
        for w in &mut lanes.weight {
            w.0[k] = 1.0;
        }
        lanes.bounces[k] = 0;
        lanes.query[k] = i;
        lanes.rng.0[k] = stream(self.seed, i);
        true
    }

    /// Fills lane `k` with the next query the lanes walk, or leaves it idle.
    #[inline(never)]
    fn refill(&mut self, lanes: &mut Lanes8, k: usize, next: &mut usize) {
        lanes.query[k] = usize::MAX;
        while *next < self.wi.len() {
            let i = *next;
            *next += 1;
            if self.start(lanes, k, i) {
                return;
            }
        }
        // an idle lane walks a harmless ray whose results are dropped
        lanes.wr.z.0[k] = -1.0;
        lanes.wr.x.0[k] = 0.0;
        lanes.wr.y.0[k] = 0.0;
        lanes.depth.0[k] = 0.0;
    }

    /// The scalar material's sample of the mirror facet for lane `k` (the rare forms).
    #[inline(never)]
    fn scalar_facet(&self, wi: Vec3, u1: f32, u2: f32) -> (Vec3, Vec3) {
        let s = self.surface.material().sample_mirror_unchecked(self.surface.slope(), wi, u1, u2);
        (s.wo, s.weight)
    }
}

impl<H: MicrosurfaceHeight, S: MicrosurfaceSlope, M: Material> LaneLoop for WalkLoop<'_, '_, '_, H, S, M> {
    #[inline(always)]
    fn run(&mut self) {
        let zero = F32x8::lit(0.0);
        let one = F32x8::lit(1.0);
        let (ax, ay) = (F32x8::lit(self.ax), F32x8::lit(self.ay));
        let mut lanes = Lanes8 {
            wr: V3::new(zero, zero, -one),
            depth: zero,
            weight: [one; 3],
            bounces: [0; WIDTH],
            query: [usize::MAX; WIDTH],
            rng: LaneRng([0; WIDTH]),
        };
        let mut next = 0;
        for k in 0..WIDTH {
            self.refill(&mut lanes, k, &mut next);
        }
        while lanes.query.iter().any(|&q| q != usize::MAX) {
            let w = lanes.wr;
            let (lambda, _) = lambda_and_area_of(ax, ay, w);
            let (ua, ub) = lanes.rng.pair();
            let (u1, u2) = lanes.rng.pair();
            let depth = lanes.depth;
            // the next intersection (`Microsurface::next_hit` of an opaque walk)
            let from_above = depth.eq(zero) & w.z.lt(zero);
            let undrawn = depth.gt(zero);
            let up = w.z.gt(zero);
            let closed_form = undrawn & up;
            // an undrawn depth seen by a ray going up: it escapes with probability a/(a + Λ)
            let escapes_closed = ua.lt(depth / (depth + lambda));
            // otherwise the height is drawn (from a e^{aℓ} if undrawn) and stepped
            let (ln_a, _) = ln_one_minus(ua);
            let (drawn_undrawn, _) = step_ln_c1(-one, -depth, zero, ln_a);
            let drawn = F32x8::select(undrawn, drawn_undrawn, depth);
            let (ln_b, one_minus_b) = ln_one_minus(ub);
            let quick = w.z.ge(zero) & escapes_without_log(lambda, drawn, one_minus_b);
            let (stepped, escapes_step) = step_ln_c1(w.z, lambda, drawn, ln_b);
            let escapes =
                (closed_form & escapes_closed) | (!from_above & !closed_form & (quick | escapes_step));
            lanes.depth = F32x8::select(from_above, -lambda, F32x8::select(closed_form, depth, stepped));
            // the facet: a visible normal of ωi = −ωr, the mirror reflection, its Fresnel weight
            let wi = V3::new(-w.x, -w.y, -w.z);
            let (m, cap_ok) = sample_spherical_cap_of(ax, ay, wi, u1, u2);
            let c = wi.dot(m);
            let k2 = F32x8::lit(2.0) * c;
            let r = V3::new(k2 * m.x - wi.x, k2 * m.y - wi.y, k2 * m.z - wi.z);
            let r_len_sq = r.length_squared();
            let nearly_unit = (r_len_sq - one).abs().le(F32x8::lit(1.0 / 4096.0));
            let wo = r.scale(F32x8::lit(1.5) - F32x8::lit(0.5) * r_len_sq);
            let (fresnel, common) = match self.fresnel {
                None => ([one; 3], cap_ok & nearly_unit),
                Some((t0, m4)) => {
                    let cos = c.abs().min(one);
                    let f = |t: f32, q: f32| reflectance_of(cos, F32x8::lit(t), F32x8::lit(q));
                    (
                        [f(t0.x, m4.x), f(t0.y, m4.y), f(t0.z, m4.z)],
                        cap_ok & nearly_unit & c.ge(F32x8::lit(0.05)),
                    )
                }
            };
            let escaped = escapes.bits();
            let common = common.bits();
            let mut new_wr = wo;
            let mut weight = [0, 1, 2].map(|ch| lanes.weight[ch] * fresnel[ch]);
            for k in 0..WIDTH {
                let i = lanes.query[k];
                if i == usize::MAX {
                    continue;
                }
                if escaped >> k & 1 == 1 {
                    let s = WalkSample {
                        wo: Vec3::new(w.x.0[k], w.y.0[k], w.z.0[k]),
                        weight: Vec3::new(lanes.weight[0].0[k], lanes.weight[1].0[k], lanes.weight[2].0[k]),
                        bounces: lanes.bounces[k],
                    };
                    self.out.set(i, Some(s));
                    self.refill(&mut lanes, k, &mut next);
                    continue;
                }
                if common >> k & 1 == 0 {
                    let (o, f) =
                        self.scalar_facet(Vec3::new(wi.x.0[k], wi.y.0[k], wi.z.0[k]), u1.0[k], u2.0[k]);
                    new_wr.x.0[k] = o.x;
                    new_wr.y.0[k] = o.y;
                    new_wr.z.0[k] = o.z;
                    for (ch, fc) in [f.x, f.y, f.z].into_iter().enumerate() {
                        weight[ch].0[k] = lanes.weight[ch].0[k] * fc;
                    }
                }
                lanes.bounces[k] += 1;
                let absorbed = weight.iter().all(|ch| ch.0[k] == 0.0);
                if absorbed || lanes.bounces[k] >= MAX_BOUNCES {
                    self.out.set(i, None);
                    self.refill(&mut lanes, k, &mut next);
                    continue;
                }
                lanes.wr.x.0[k] = new_wr.x.0[k];
                lanes.wr.y.0[k] = new_wr.y.0[k];
                lanes.wr.z.0[k] = new_wr.z.0[k];
                for ch in 0..3 {
                    lanes.weight[ch].0[k] = weight[ch].0[k];
                }
            }
        }
    }
}

impl<H: MicrosurfaceHeight, S: MicrosurfaceSlope, M: Material> Microsurface<H, S, M> {
    /// Samples one walk for each incident direction `wi[i]` (as [`Microsurface::sample`]), eight
    /// at a time, each lane refilled with the next query when its walk ends; writes
    /// [`WalkOutputs`]. Query i's walk is a function of (`seed`, i) only. The walks of GGX
    /// conductors from above run in lanes; every other configuration and query (dielectrics,
    /// other slopes, views from below, invalid directions) runs the scalar walk with a generator
    /// seeded from (`seed`, i). Either way each walk has the distribution of
    /// [`Microsurface::sample`] (not its bits: the lanes have their own generators).
    ///
    /// # Errors
    /// [`Error::LengthMismatch`] if an output slice is not as long as `wi`.
    pub fn sample_batch(
        &self,
        wi: &Directions<'_>,
        seed: u64,
        out: &mut WalkOutputs<'_>,
    ) -> Result<(), Error> {
        out.check(wi.len())?;
        let lanes = match (self.slope().ggx_roughness(), self.material().lane_material()) {
            (Some((ax, ay)), LaneMaterial::Conductor(fresnel)) => Some((ax, ay, fresnel)),
            _ => None,
        };
        let Some((ax, ay, fresnel)) = lanes else {
            for i in 0..wi.len() {
                let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(stream(seed, i));
                out.set(i, self.sample(wi.get(i), &mut rng));
            }
            return Ok(());
        };
        dispatch(&mut WalkLoop { surface: self, ax, ay, fresnel, wi, seed, out });
        Ok(())
    }
}
