//! The random walk in lanes: many walks of [`Microsurface::sample`] at once, 64 in flight and
//! stepped eight at a time, each path's slot refilled with the next query when its walk ends
//! (supplement §3.1, Algorithm 3).
//!
//! A lane carries one path: its ray, its height (ln C¹, or the undrawn rate of an opaque
//! walk, `walk::Depth`), its weight, its bounce count, and its own generator. Every formula is
//! the scalar walk's kernel: Λ ([`lambda_and_area_of`]), the height step
//! ([`escapes_without_log`], [`step_ln_c1`], with the lanes' logarithm [`ln_of`], within 4 ulps
//! of the scalar walk's), the
//! spherical-cap visible normal ([`sample_cap_of`]), the reflection and its Newton
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
use crate::lanes::{LaneLoop, V3, dispatch};
use crate::material::{LaneMaterial, Material};
use crate::rng::TAIL_CUT;
use crate::slope::{MicrosurfaceSlope, lambda_and_area_of, sample_cap_of};
use crate::soa::{Channels, Directions, check_len};
use crate::special::ln_of;
use glam::{Vec3, Vec3A};

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

/// The seed of query `i`'s generator under a batch's `keys` ([`stream_keys`]): four words
/// w₀ = h(l ⊕ k₀), w₁ = h(l ⊕ k₁), w₂ = h(w₀ ⊕ u ⊕ k₂), w₃ = h(w₁ ⊕ u ⊕ k₃) of the low and high
/// halves l, u of i, h MurmurHash3's bijective finalizer [`fmix32`]. (w₀, w₂) determine
/// (l, u), so every query of a batch has its own state. 32-bit words, so that the lanes
/// seed eight generators per AVX2 instruction. A lane's generator is reseeded with each query,
/// so query i's walk depends on (seed, i) only, not on the lane or the order in which the
/// lanes finish. The lanes make the words the state of their xoshiro128++ ([`xoshiro_of`]),
/// the scalar walk the state of its PCG ([`pcg_of`]).
#[inline(always)]
fn stream(keys: [u32; 4], i: usize) -> [u32; 4] {
    stream_of_halves(keys, i as u32, ((i as u64) >> 32) as u32)
}

/// [`stream`] of the query whose index has the low and high halves `l`, `u`.
#[inline(always)]
fn stream_of_halves(keys: [u32; 4], l: u32, u: u32) -> [u32; 4] {
    let (w0, w1) = (fmix32(l ^ keys[0]), fmix32(l ^ keys[1]));
    [w0, w1, fmix32(w0 ^ u ^ keys[2]), fmix32(w1 ^ u ^ keys[3])]
}

/// The keys of a batch's streams: the four words of two splitmix64 outputs of its seed.
#[inline(always)]
fn stream_keys(seed: u64) -> [u32; 4] {
    let (a, b) = (mix64(seed), mix64(seed.wrapping_add(0x9e37_79b9_7f4a_7c15)));
    [a as u32, (a >> 32) as u32, b as u32, (b >> 32) as u32]
}

/// MurmurHash3's 32-bit finalizer (Appleby 2011): a bijection of `u32` whose output bits each
/// depend on every input bit.
#[inline(always)]
fn fmix32(h: u32) -> u32 {
    let h = (h ^ (h >> 16)).wrapping_mul(0x85eb_ca6b);
    let h = (h ^ (h >> 13)).wrapping_mul(0xc2b2_ae35);
    h ^ (h >> 16)
}

/// The xoshiro128++ state of the seed words `w` ([`stream`]; the last word odd, so that the
/// state is never zero).
#[inline(always)]
fn xoshiro_of([a, b, c, d]: [u32; 4]) -> [u32; 4] {
    [a, b, c, d | 1]
}

/// The scalar walk's generator of the seed words `w` ([`stream`]).
#[inline(always)]
fn pcg_of([a, b, c, d]: [u32; 4]) -> rand_pcg::Pcg64Mcg {
    let word = |x: u32, y: u32| u128::from(x) | (u128::from(y) << 32);
    rand_pcg::Pcg64Mcg::new(word(a, b) | (word(c, d) << 64))
}

/// The splitmix64 finalizer.
#[inline(always)]
fn mix64(z: u64) -> u64 {
    let z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    let z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// 2⁻²⁴.
const INV_2_POW_24: f32 = 1.0 / 16_777_216.0;

/// The paths in flight: a multiple of the vector width, enough for the step's loop to run
/// in full vectors most of the time while lanes finish and refill.
const PATHS: usize = 64;

/// xoshiro128++ (Blackman and Vigna 2018), one per path: 32-bit words, so that the step's
/// loop draws its uniforms in eight-lane integer instructions.
#[inline(always)]
fn xoshiro(s: &mut [u32; 4]) -> u32 {
    let out = s[0].wrapping_add(s[3]).rotate_left(7).wrapping_add(s[0]);
    let t = s[1] << 9;
    s[2] ^= s[0];
    s[3] ^= s[1];
    s[1] ^= s[2];
    s[0] ^= s[3];
    s[2] ^= t;
    s[3] = s[3].rotate_left(11);
    out
}

/// A uniform on the 2⁻²⁴ grid of `rng::uniform` from 32 random bits.
#[inline(always)]
fn uniform_of(bits: u32) -> f32 {
    (bits >> 8) as f32 * INV_2_POW_24
}

/// ln(1 − cut_tails(u)) (the lanes' logarithm) and 1 − cut_tails(u).
#[inline(always)]
fn ln_one_minus(u: f32) -> (f32, f32) {
    let one_minus_u = 1.0 - u.clamp(TAIL_CUT, 1.0 - TAIL_CUT);
    (ln_of(one_minus_u), one_minus_u)
}

/// The state of the paths in flight, one array element per path.
struct Paths {
    /// The ray leaving the current point (−ωi at the start).
    wr: [[f32; PATHS]; 3],
    /// ln C¹ (≤ 0), or the rate of an undrawn depth (> 0); 0 above the surface.
    depth: [f32; PATHS],
    weight: [[f32; PATHS]; 3],
    bounces: [u32; PATHS],
    /// The query of each path; `usize::MAX` for an idle slot.
    query: [usize; PATHS],
    /// The four words of each path's generator.
    rng: [[u32; PATHS]; 4],
    /// The step's verdict: 0 continues with the lanes' facet; otherwise the bits
    /// [`ESCAPED`], [`SCALAR_FACET`], [`ENDED`].
    status: [u8; PATHS],
    /// The uniforms of the last step's facet.
    u: [[f32; PATHS]; 2],
    /// The ray and weight after the lanes' facet of the last step.
    next_wr: [[f32; PATHS]; 3],
    next_weight: [[f32; PATHS]; 3],
}

/// The ray escaped before the facet (its closed-form escape, or the height step's).
const ESCAPED: u8 = 1;
/// The facet is off the kernels' common path: the scalar sampler redoes it.
const SCALAR_FACET: u8 = 2;
/// The walk ends without a sample (absorbed, or the bounce cap).
const ENDED: u8 = 8;

/// One step of one path of a GGX conductor walk (`Microsurface::next_hit` of an opaque walk,
/// then the mirror facet of `Conductor::sample_mirror_unchecked`): the ray's next height or
/// escape (a first hit from above is undrawn; an undrawn depth seen from below escapes in
/// closed form; every other ray steps its height with Algorithm 1 in ln C¹, an undrawn depth
/// drawn first as `walk::Depth::drawn` draws it), the facet, and the verdict bits. Both
/// logarithms are formed in every lane (two lane logarithms cost less than a branch out of the
/// vectorized loop).
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn step(
    ax: f32,
    ay: f32,
    fresnel: Option<(Vec3A, Vec3A)>,
    w: V3<f32>,
    depth: f32,
    weight: [f32; 3],
    rng: &mut [u32; 4],
) -> (V3<f32>, f32, [f32; 3], u8, [f32; 2]) {
    let (lambda, _) = lambda_and_area_of(ax, ay, w);
    let (ua, ub) = (uniform_of(xoshiro(rng)), uniform_of(xoshiro(rng)));
    let (u1, u2) = (uniform_of(xoshiro(rng)), uniform_of(xoshiro(rng)));
    // the next intersection: a first hit from above is undrawn (rate −Λ = 1 + Λ(ωi)); an
    // undrawn depth seen by a ray going up escapes with probability a/(a + Λ); every other
    // ray's height is stepped with logarithms
    let from_above = depth == 0.0 && w.z < 0.0;
    let closed_form = depth > 0.0 && w.z > 0.0;
    let (ln_a, _) = ln_one_minus(ua);
    let (ln_b, one_minus_b) = ln_one_minus(ub);
    let drawn = if depth > 0.0 { step_ln_c1(-1.0, -depth, 0.0, ln_a).0 } else { depth };
    let quick = w.z >= 0.0 && escapes_without_log(lambda, drawn, one_minus_b);
    let (stepped, stepped_escapes) = step_ln_c1(w.z, lambda, drawn, ln_b);
    let escapes =
        if closed_form { ua < depth / (depth + lambda) } else { !from_above && (quick || stepped_escapes) };
    let next_depth = if from_above {
        -lambda
    } else if closed_form {
        depth
    } else {
        stepped
    };
    // the facet: a visible normal of ωi = −ωr, the mirror reflection, its Fresnel weight
    let wi = V3::new(-w.x, -w.y, -w.z);
    let (m, cap_ok) = sample_cap_of(ax, ay, wi, 2.0, u1, u2);
    let c = wi.dot(m);
    let k = 2.0 * c;
    let r = V3::new(k * m.x - wi.x, k * m.y - wi.y, k * m.z - wi.z);
    let r_len_sq = r.length_squared();
    let nearly_unit = (r_len_sq - 1.0).abs() <= 1.0 / 4096.0;
    let wo = r.scale(1.5 - 0.5 * r_len_sq);
    let (f, common) = match fresnel {
        None => ([1.0; 3], cap_ok && nearly_unit),
        Some((t0, m4)) => {
            let cos = c.abs().min(1.0);
            let f = |t: f32, q: f32| reflectance_of(cos, t, q);
            ([f(t0.x, m4.x), f(t0.y, m4.y), f(t0.z, m4.z)], cap_ok && nearly_unit && c >= 0.05)
        }
    };
    let status = u8::from(escapes) * ESCAPED + u8::from(!common) * SCALAR_FACET;
    (wo, next_depth, [weight[0] * f[0], weight[1] * f[1], weight[2] * f[2]], status, [u1, u2])
}

/// The queries next in line for the lanes, prepared in a loop the compiler vectorizes (their
/// directions read in full vectors, their generators seeded eight at a time with AVX2): two
/// blocks of [`PATHS`], so that a finishing pass, which refills at most [`PATHS`] slots, finds
/// them ready.
struct Incoming {
    /// −ωi of each query.
    wr: [[f32; 2 * PATHS]; 3],
    /// The four words of each query's generator ([`xoshiro_of`]).
    rng: [[u32; 2 * PATHS]; 4],
    /// Whether the lanes walk the query (a unit ωi from above); the scalar walk answers the
    /// others.
    lanes: [bool; 2 * PATHS],
    /// The query of element 0.
    first: usize,
    /// The elements prepared.
    len: usize,
    /// The elements taken.
    taken: usize,
}

impl Incoming {
    const EMPTY: Self = Self {
        wr: [[0.0; 2 * PATHS]; 3],
        rng: [[0; 2 * PATHS]; 4],
        lanes: [false; 2 * PATHS],
        first: 0,
        len: 0,
        taken: 0,
    };

    /// Drops the first block once it is taken and prepares queries up to two blocks (fewer at
    /// the end of the batch).
    #[inline(always)]
    fn top_up(&mut self, wi: &Directions<'_>, keys: [u32; 4]) {
        if self.taken >= PATHS {
            for c in &mut self.wr {
                c.copy_within(PATHS.., 0);
            }
            for c in &mut self.rng {
                c.copy_within(PATHS.., 0);
            }
            self.lanes.copy_within(PATHS.., 0);
            self.first += PATHS;
            self.len -= PATHS;
            self.taken -= PATHS;
        }
        let (x, y, z) = wi.slices();
        let len = (x.len() - self.first).min(2 * PATHS);
        let from = self.len;
        let (x, y, z) = (&x[self.first..][..len], &y[self.first..][..len], &z[self.first..][..len]);
        // the halves of query first + j in 32-bit words (j < 2³²: the high half carries at most
        // one), so that the loop has no 64-bit lane
        let (l0, u0) = (self.first as u32, ((self.first as u64) >> 32) as u32);
        for j in from..len {
            let w = Vec3::new(x[j], y[j], z[j]);
            // the lanes walk from above: a unit ωi with ωi.z > 0 (what `Microsurface::sample`
            // walks itself; a view from below is its `sample_from_below`)
            self.lanes[j] = crate::contract::is_direction(w) & (w.z > 0.0);
            self.wr[0][j] = -w.x;
            self.wr[1][j] = -w.y;
            self.wr[2][j] = -w.z;
            let l = l0.wrapping_add(j as u32);
            let g = xoshiro_of(stream_of_halves(keys, l, u0.wrapping_add(u32::from(l < l0))));
            for (c, g) in g.into_iter().enumerate() {
                self.rng[c][j] = g;
            }
        }
        self.len = len;
    }

    /// [`Incoming::top_up`] within a finishing pass, compiled apart: only where many queries
    /// are off the lanes' domain.
    #[cold]
    #[inline(never)]
    fn top_up_again(&mut self, wi: &Directions<'_>, keys: [u32; 4]) {
        self.top_up(wi, keys);
    }
}

/// The walks of a GGX conductor in lanes.
struct WalkLoop<'s, 'a, 'b, H, S, M> {
    surface: &'s Microsurface<H, S, M>,
    ax: f32,
    ay: f32,
    fresnel: Option<(Vec3A, Vec3A)>,
    wi: &'s Directions<'a>,
    /// The batch's stream keys ([`stream_keys`]).
    keys: [u32; 4],
    out: &'s mut WalkOutputs<'b>,
}

impl<H: MicrosurfaceHeight, S: MicrosurfaceSlope, M: Material> WalkLoop<'_, '_, '_, H, S, M> {
    /// The scalar walk for query `i` (outside the lanes' domain: a view from below, an invalid
    /// direction), from its own generator.
    #[inline(never)]
    fn scalar(&mut self, i: usize) {
        let mut rng = pcg_of(stream(self.keys, i));
        self.out.set(i, self.surface.sample(self.wi.get(i), &mut rng));
    }

    /// Fills slot `k` with the next query the lanes walk (answering the others with the scalar
    /// walk), or leaves it idle.
    #[inline(always)]
    fn refill(&mut self, p: &mut Paths, inc: &mut Incoming, k: usize) {
        loop {
            if inc.taken == inc.len {
                if inc.first + inc.len == self.wi.len() {
                    // an idle slot walks a harmless ray whose results are dropped
                    p.query[k] = usize::MAX;
                    for (c, v) in [0.0, 0.0, -1.0].into_iter().enumerate() {
                        p.wr[c][k] = v;
                        p.weight[c][k] = 1.0;
                    }
                    p.depth[k] = 0.0;
                    p.bounces[k] = 0;
                    return;
                }
                inc.top_up_again(self.wi, self.keys);
            }
            let j = inc.taken;
            inc.taken += 1;
            let i = inc.first + j;
            if inc.lanes[j] {
                p.query[k] = i;
                for c in 0..4 {
                    p.rng[c][k] = inc.rng[c][j];
                }
                for c in 0..3 {
                    p.wr[c][k] = inc.wr[c][j];
                    p.weight[c][k] = 1.0;
                }
                p.depth[k] = 0.0;
                p.bounces[k] = 0;
                return;
            }
            self.scalar(i);
        }
    }

    /// The step of every path (a loop the compiler vectorizes), then the commit of the paths
    /// that continue on the lanes' common path (another).
    #[inline(always)]
    fn step_all(&self, p: &mut Paths, fresnel: Option<(Vec3A, Vec3A)>) {
        for k in 0..PATHS {
            let w = V3::new(p.wr[0][k], p.wr[1][k], p.wr[2][k]);
            let weight = [p.weight[0][k], p.weight[1][k], p.weight[2][k]];
            let mut rng = [p.rng[0][k], p.rng[1][k], p.rng[2][k], p.rng[3][k]];
            let (wo, depth, weight, status, u) =
                step(self.ax, self.ay, fresnel, w, p.depth[k], weight, &mut rng);
            for (c, v) in [wo.x, wo.y, wo.z].into_iter().enumerate() {
                p.next_wr[c][k] = v;
            }
            for (c, v) in weight.into_iter().enumerate() {
                p.next_weight[c][k] = v;
            }
            p.depth[k] = depth;
            p.status[k] = status;
            for (c, v) in rng.into_iter().enumerate() {
                p.rng[c][k] = v;
            }
            p.u[0][k] = u[0];
            p.u[1][k] = u[1];
        }
        for k in 0..PATHS {
            let go = p.status[k] == 0;
            for c in 0..3 {
                p.wr[c][k] = if go { p.next_wr[c][k] } else { p.wr[c][k] };
                p.weight[c][k] = if go { p.next_weight[c][k] } else { p.weight[c][k] };
            }
            let bounces = p.bounces[k] + u32::from(go);
            p.bounces[k] = bounces;
            let absorbed = p.weight[0][k] == 0.0 && p.weight[1][k] == 0.0 && p.weight[2][k] == 0.0;
            p.status[k] |= u8::from(go && (absorbed || bounces >= MAX_BOUNCES)) * ENDED;
        }
    }

    /// The facet of a path that continues, off the lanes' common path: the scalar sampler's.
    #[inline(never)]
    fn scalar_facet(surface: &Microsurface<H, S, M>, p: &mut Paths, k: usize) {
        let wi = -Vec3::new(p.wr[0][k], p.wr[1][k], p.wr[2][k]);
        let (u1, u2) = (p.u[0][k], p.u[1][k]);
        let wm = surface.slope().sample_d_wi_unchecked(wi, u1, u2);
        let s = surface.material().mirror_reflection_unchecked(wi, wm);
        for (c, (w, f)) in
            [(s.wo.x, s.weight.x), (s.wo.y, s.weight.y), (s.wo.z, s.weight.z)].into_iter().enumerate()
        {
            p.wr[c][k] = w;
            p.weight[c][k] *= f;
        }
        p.bounces[k] += 1;
    }

    /// The finishing pass over the paths whose step did not commit (the bits of `pending`): the
    /// scalar facets, the outputs of the walks that exit or end, then the refill of their slots.
    #[inline(never)]
    fn finish_all(&mut self, p: &mut Paths, inc: &mut Incoming, mut pending: u64) {
        let surface = self.surface;
        let mut free = 0u64;
        {
            let (wo_x, wo_y, wo_z) = self.out.wo.slices();
            let (wt_r, wt_g, wt_b) = self.out.weight.slices();
            let n = wo_x.len();
            let (wo_y, wo_z, wt_r, wt_g, wt_b) =
                (&mut wo_y[..n], &mut wo_z[..n], &mut wt_r[..n], &mut wt_g[..n], &mut wt_b[..n]);
            let bounces = &mut self.out.bounces[..n];
            while pending != 0 {
                let k = pending.trailing_zeros() as usize;
                pending &= pending - 1;
                let i = p.query[k];
                if i >= n {
                    // an idle slot
                    continue;
                }
                let status = p.status[k];
                if status & ESCAPED == 0 {
                    if status & SCALAR_FACET != 0 {
                        Self::scalar_facet(surface, p, k);
                    }
                    let absorbed = (0..3).all(|c| p.weight[c][k] == 0.0);
                    if !(status & ENDED != 0 || absorbed || p.bounces[k] >= MAX_BOUNCES) {
                        continue;
                    }
                    // no sample: a zero direction, weight and bounce count
                    for c in 0..3 {
                        p.wr[c][k] = 0.0;
                        p.weight[c][k] = 0.0;
                    }
                    p.bounces[k] = 0;
                }
                wo_x[i] = p.wr[0][k];
                wo_y[i] = p.wr[1][k];
                wo_z[i] = p.wr[2][k];
                wt_r[i] = p.weight[0][k];
                wt_g[i] = p.weight[1][k];
                wt_b[i] = p.weight[2][k];
                bounces[i] = p.bounces[k];
                free |= 1 << k;
            }
        }
        while free != 0 {
            let k = free.trailing_zeros() as usize;
            free &= free - 1;
            self.refill(p, inc, k);
        }
    }

    /// Walks every query with the Fresnel term `fresnel` (fixed, so that the step's loop has
    /// no branch on it).
    #[inline(always)]
    fn walk(&mut self, fresnel: Option<(Vec3A, Vec3A)>) {
        let mut p = Paths {
            wr: [[0.0; PATHS], [0.0; PATHS], [-1.0; PATHS]],
            depth: [0.0; PATHS],
            weight: [[1.0; PATHS]; 3],
            bounces: [0; PATHS],
            query: [usize::MAX; PATHS],
            rng: [[1; PATHS]; 4],
            status: [0; PATHS],
            u: [[0.0; PATHS]; 2],
            next_wr: [[0.0; PATHS]; 3],
            next_weight: [[0.0; PATHS]; 3],
        };
        let mut inc = Incoming::EMPTY;
        inc.top_up(self.wi, self.keys);
        for k in 0..PATHS {
            self.refill(&mut p, &mut inc, k);
        }
        while p.query.iter().any(|&q| q != usize::MAX) {
            self.step_all(&mut p, fresnel);
            let mut pending = 0u64;
            for k in 0..PATHS {
                pending |= u64::from(p.status[k] != 0) << k;
            }
            inc.top_up(self.wi, self.keys);
            self.finish_all(&mut p, &mut inc, pending);
        }
    }
}

impl<H: MicrosurfaceHeight, S: MicrosurfaceSlope, M: Material> LaneLoop for WalkLoop<'_, '_, '_, H, S, M> {
    #[inline(always)]
    fn run(&mut self) {
        match self.fresnel {
            None => self.walk(None),
            Some(f) => self.walk(Some(f)),
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
            let keys = stream_keys(seed);
            for i in 0..wi.len() {
                let mut rng = pcg_of(stream(keys, i));
                out.set(i, self.sample(wi.get(i), &mut rng));
            }
            return Ok(());
        };
        dispatch(&mut WalkLoop { surface: self, ax, ay, fresnel, wi, keys: stream_keys(seed), out });
        Ok(())
    }
}
