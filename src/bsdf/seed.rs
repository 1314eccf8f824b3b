//! Deterministic randomness for the stochastic techniques behind the [`Bsdf`](super::Bsdf)
//! trait: a 64-bit hash of a call's arguments seeds a private PCG generator (the approach of
//! pbrt-v4's `LayeredBxDF`, whose generator is seeded by Hash(seed, ωo) and Hash(uc, u)), and
//! a generator that hands out the caller's uniforms before its own numbers.

use core::convert::Infallible;
use glam::{Vec2, Vec3};
use rand::TryRng;
use rand_pcg::Pcg64Mcg;

/// The top 24 bits of a `u32`, the ones `crate::rng::uniform` keeps.
const UNIFORM_MASK: u32 = 0xffff_ff00;
/// The most caller uniforms a primed generator hands out.
const MAX_PRIMED: usize = 4;

/// Odd 64-bit constants (the first digits of π, e and √2 in hexadecimal, forced odd) that
/// keep the inputs of [`mum`] away from 0 and break its symmetry.
const P: [u64; 7] = [
    0x243f_6a88_85a3_08d3,
    0x1319_8a2e_0370_7345,
    0xa409_3822_299f_31d1,
    0x082e_fa98_ec4e_6c89,
    0x4528_21e6_38d0_1377,
    0xbe54_66cf_34e9_0c6d,
    0xb7e1_5162_8aed_2a6b,
];

/// The folded 128-bit product of two words (wyhash's "mum"): one multiplication mixes 128
/// input bits into 64.
#[inline(always)]
fn mum(a: u64, b: u64) -> u64 {
    let r = u128::from(a) * u128::from(b);
    (r as u64) ^ ((r >> 64) as u64)
}

/// The bit patterns of two floats in one word (so −0 and +0 differ, as do any two inputs
/// whose bits differ).
#[inline(always)]
fn pair(a: f32, b: f32) -> u64 {
    u64::from(a.to_bits()) | (u64::from(b.to_bits()) << 32)
}

/// A 64-bit hash of a call's arguments: the BSDF's seed, the caller's key and three words of
/// float bits, wyhash-style: three independent folded products of the words (the processor
/// runs them in parallel; the seed enters two of them) and one more product of their
/// combination. About 12 cycles of latency (three dependent multiplications), against about
/// 30 for a splitmix64-finalized form and 70 for absorbing the six words one
/// splitmix64 round after another; its avalanche through the generator's first output is
/// measured by `one_input_bit_flips_half_the_output_bits`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Hasher(u64);

impl Hasher {
    #[inline(always)]
    fn of(seed: u64, key: u64, w: [u64; 3]) -> Self {
        let a = mum(seed ^ P[0], key ^ P[1]);
        let b = mum(w[0] ^ P[2], w[1] ^ P[3]);
        let c = mum(w[2] ^ P[4], seed ^ P[5]);
        Self(mum(a ^ b ^ P[6], c ^ P[0]))
    }

    /// The hash of an evaluation: seed, key and the directions (wo, wi).
    #[inline(always)]
    pub(crate) fn directions(seed: u64, key: u64, a: Vec3, b: Vec3) -> Self {
        // the pairs (x, y) and the two z, the pieces a `Vec3` is stored in
        Self::of(seed, key, [pair(a.x, a.y), pair(b.x, b.y), pair(a.z, b.z)])
    }

    /// The hash of a sample: seed, key, the direction wo and the caller's uniforms.
    #[inline(always)]
    pub(crate) fn direction_uniforms(seed: u64, key: u64, w: Vec3, uc: f32, u: Vec2) -> Self {
        Self::of(seed, key, [pair(w.x, w.y), pair(w.z, uc), pair(u.x, u.y)])
    }

    /// The PCG generator with this hash as its state (the second half of the 128-bit state
    /// is a second, independent mix of the hash: one more product).
    #[inline(always)]
    pub(crate) fn generator(self) -> Pcg64Mcg {
        let low = mum(self.0 ^ P[1], P[2]);
        Pcg64Mcg::new((u128::from(self.0) << 64) | u128::from(low))
    }
}

/// A uniform in [0, 1) as the `u32` whose top 24 bits `crate::rng::uniform` turns back
/// into it, rounded down to a multiple of 2⁻²⁴ (the resolution of every uniform the crate
/// draws). Values outside [0, 1) never reach here (the callers check them).
///
/// Read off the bits of 1 + u in f64, whose 52-bit mantissa is u·2⁵²: its top 24 bits are
/// ⌊u·2²⁴⌋. 1 + u is exact for u ≥ 2⁻²⁹ (the last bit of an f32 u is then ≥ 2⁻⁵²); smaller u
/// round to within 2⁻⁵² of 1, still below 1 + 2⁻²⁴, so ⌊u·2²⁴⌋ = 0 comes out as it should.
/// Four instructions instead of the saturating float-to-integer conversion's eight.
#[inline(always)]
fn uniform_bits(u: f32) -> u32 {
    // mantissa bits 51…28 to bits 31…8; the exponent falls off the top
    ((1.0 + f64::from(u)).to_bits() >> 20) as u32 & UNIFORM_MASK
}

/// A generator that returns the caller's uniforms first, then the numbers of a private PCG
/// generator. The research layer draws every uniform with one `next_u32` through
/// `crate::rng::uniform`, so the k-th uniform a walk draws is the k-th primed value (rounded
/// down to a multiple of 2⁻²⁴) as long as there are primed values left. The PCG generator is
/// built lazily, from the hash, when the primed values run out: single scattering never
/// pays for it.
pub(crate) struct PrimedRng<H: Fn() -> Hasher> {
    primed: [u32; MAX_PRIMED],
    len: usize,
    next: usize,
    hash: H,
    rng: Option<Pcg64Mcg>,
}

impl<H: Fn() -> Hasher> PrimedRng<H> {
    /// A generator returning `uniforms` (each in [0, 1), at most four) first, then the
    /// numbers of the PCG generator seeded by the hash `hash` computes (on first use).
    #[inline(always)]
    pub(crate) fn new(uniforms: &[f32], hash: H) -> Self {
        let mut primed = [0; MAX_PRIMED];
        for (p, &u) in primed.iter_mut().zip(uniforms) {
            *p = uniform_bits(u);
        }
        Self { primed, len: uniforms.len().min(MAX_PRIMED), next: 0, hash, rng: None }
    }

    /// The next number of the private generator, built on first use. Out of line and cold:
    /// the primed draws (all that single scattering of conductors and dielectrics makes)
    /// stay a load and a branch, small enough for `next_u32` to be inlined at every draw.
    #[cold]
    #[inline(never)]
    fn private_u32(&mut self) -> u32 {
        let hash = &self.hash;
        rand::Rng::next_u32(self.rng.get_or_insert_with(|| hash().generator()))
    }
}

/// [`PrimedRng`] for techniques that always draw beyond the caller's uniforms (the random
/// walk, the position-free estimators): the private generator is built up front, so that no
/// draw checks whether it exists.
pub(crate) struct PrimedPcg {
    primed: [u32; MAX_PRIMED],
    len: usize,
    next: usize,
    rng: Pcg64Mcg,
}

impl PrimedPcg {
    /// A generator returning `uniforms` (each in [0, 1), at most four) first, then the
    /// numbers of the PCG generator seeded by `hash`.
    #[inline(always)]
    #[cfg_attr(not(feature = "position-free"), allow(dead_code))]
    pub(crate) fn new(uniforms: &[f32], hash: Hasher) -> Self {
        let mut primed = [0; MAX_PRIMED];
        for (p, &u) in primed.iter_mut().zip(uniforms) {
            *p = uniform_bits(u);
        }
        Self { primed, len: uniforms.len().min(MAX_PRIMED), next: 0, rng: hash.generator() }
    }

    /// A generator that starts with one number of its own private generator, then the
    /// caller's uniforms, then the private generator again (for walks whose first draw is a
    /// height, which the caller's sampler should not spend its stratified dimensions on).
    #[inline(always)]
    pub(crate) fn after_one_private(uniforms: &[f32], hash: Hasher) -> Self {
        let mut rng = hash.generator();
        let mut primed = [0; MAX_PRIMED];
        primed[0] = rand::Rng::next_u32(&mut rng);
        for (p, &u) in primed[1..].iter_mut().zip(uniforms) {
            *p = uniform_bits(u);
        }
        Self { primed, len: (uniforms.len() + 1).min(MAX_PRIMED), next: 0, rng }
    }
}

impl TryRng for PrimedPcg {
    type Error = Infallible;

    #[inline(always)]
    fn try_next_u32(&mut self) -> Result<u32, Infallible> {
        if self.next < self.len {
            let x = self.primed[self.next];
            self.next += 1;
            return Ok(x);
        }
        Ok(rand::Rng::next_u32(&mut self.rng))
    }

    #[inline(always)]
    fn try_next_u64(&mut self) -> Result<u64, Infallible> {
        let lo = self.try_next_u32()?;
        let hi = self.try_next_u32()?;
        Ok(u64::from(lo) | (u64::from(hi) << 32))
    }

    fn try_fill_bytes(&mut self, dst: &mut [u8]) -> Result<(), Infallible> {
        for chunk in dst.chunks_mut(4) {
            let bytes = self.try_next_u32()?.to_le_bytes();
            chunk.copy_from_slice(&bytes[..chunk.len()]);
        }
        Ok(())
    }
}

impl<H: Fn() -> Hasher> TryRng for PrimedRng<H> {
    type Error = Infallible;

    #[inline(always)]
    fn try_next_u32(&mut self) -> Result<u32, Infallible> {
        if self.next < self.len {
            let x = self.primed[self.next];
            self.next += 1;
            return Ok(x);
        }
        Ok(self.private_u32())
    }

    #[inline(always)]
    fn try_next_u64(&mut self) -> Result<u64, Infallible> {
        let lo = self.try_next_u32()?;
        let hi = self.try_next_u32()?;
        Ok(u64::from(lo) | (u64::from(hi) << 32))
    }

    fn try_fill_bytes(&mut self, dst: &mut [u8]) -> Result<(), Infallible> {
        for chunk in dst.chunks_mut(4) {
            let bytes = self.try_next_u32()?.to_le_bytes();
            chunk.copy_from_slice(&bytes[..chunk.len()]);
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::uniform;

    #[test]
    fn primed_uniforms_come_back_first() {
        let h = Hasher::directions(1, 2, Vec3::Z, Vec3::X);
        let mut r = PrimedRng::new(&[0.25, 0.5, 0.999_999_94], || h);
        assert_eq!(uniform(&mut r), 0.25);
        assert_eq!(uniform(&mut r), 0.5);
        assert_eq!(uniform(&mut r), 1.0 - 1.0 / 16_777_216.0);
        let mut private = h.generator();
        assert_eq!(rand::Rng::next_u32(&mut r), rand::Rng::next_u32(&mut private));
        let mut r = PrimedPcg::after_one_private(&[0.75], h);
        let mut private = h.generator();
        assert_eq!(rand::Rng::next_u32(&mut r), rand::Rng::next_u32(&mut private));
        assert_eq!(uniform(&mut r), 0.75);
        assert_eq!(rand::Rng::next_u32(&mut r), rand::Rng::next_u32(&mut private));
        let mut r = PrimedPcg::new(&[0.25, 0.5], h);
        let mut private = h.generator();
        assert_eq!(uniform(&mut r), 0.25);
        assert_eq!(uniform(&mut r), 0.5);
        assert_eq!(rand::Rng::next_u32(&mut r), rand::Rng::next_u32(&mut private));
    }

    /// The bit trick of `uniform_bits` is ⌊u·2²⁴⌋·2⁸ across the f32s in [0, 1) (every 1024th
    /// bit pattern below 1e-6, every 61st above: 17 million values) and at the edge cases.
    #[test]
    fn uniform_bits_round_down_to_the_grid() {
        let reference = |u: f32| (((f64::from(u) * 16_777_216.0).floor()) as u32) << 8;
        let top = 1.0f32.to_bits();
        let mut bits = 0u32;
        while bits < top {
            let u = f32::from_bits(bits);
            assert_eq!(uniform_bits(u), reference(u), "u = {u:e}");
            bits += if u < 1e-6 { 1 << 10 } else { 61 };
        }
        for u in [0.0, -0.0, 1.0 - 1.0 / 16_777_216.0, 0.5, 2f32.powi(-24), 2f32.powi(-29), 1e-45] {
            assert_eq!(uniform_bits(u), reference(u), "u = {u:e}");
        }
    }

    #[test]
    fn hash_depends_on_every_argument() {
        let h = |seed, key, a, b| Hasher::directions(seed, key, a, b).0;
        let base = h(3, 4, Vec3::Z, Vec3::X);
        assert_ne!(base, h(4, 4, Vec3::Z, Vec3::X));
        assert_ne!(base, h(3, 5, Vec3::Z, Vec3::X));
        assert_ne!(base, h(4, 3, Vec3::Z, Vec3::X));
        assert_ne!(base, h(3, 4, Vec3::X, Vec3::Z));
        assert_ne!(base, h(3, 4, Vec3::new(0.0, -0.0, 1.0), Vec3::X));
        assert_eq!(base, h(3, 4, Vec3::Z, Vec3::X));
    }

    /// Avalanche of the seeded generator's first output: flipping any one of the 320 input
    /// bits (seed, key, six floats) flips each output bit with probability ½. Over 200 random
    /// inputs per bit, the mean number of flipped output bits is 32 ± 0.28 (binomial SE): the
    /// worst input bit must stay within 32 ± 2.
    #[test]
    fn one_input_bit_flips_half_the_output_bits() {
        let mut rng = Pcg64Mcg::new(0x5eed);
        let mut next = || rand::Rng::next_u64(&mut rng);
        let out = |w: [u64; 5]| {
            let f = |x: u64| f32::from_bits(x as u32);
            let g = |x: u64| f32::from_bits((x >> 32) as u32);
            let h = Hasher::directions(
                w[0],
                w[1],
                Vec3::new(f(w[2]), g(w[2]), f(w[3])),
                Vec3::new(g(w[3]), f(w[4]), g(w[4])),
            );
            rand::Rng::next_u64(&mut h.generator())
        };
        let inputs: Vec<[u64; 5]> = (0..200).map(|_| [next(), next(), next(), next(), next()]).collect();
        let mut worst = 0.0f64;
        for word in 0..5 {
            for bit in 0..64 {
                let flips: u32 = inputs
                    .iter()
                    .map(|&w| {
                        let mut v = w;
                        v[word] ^= 1 << bit;
                        (out(w) ^ out(v)).count_ones()
                    })
                    .sum();
                let mean = f64::from(flips) / inputs.len() as f64;
                worst = worst.max((mean - 32.0).abs());
            }
        }
        eprintln!(
            "avalanche: the worst of the 320 input bits flips {worst:.3} output bits away from 32 on average"
        );
        assert!(worst <= 2.0, "an input bit flips on average {worst} bits away from 32");
    }

    /// The strict avalanche criterion for the hash word itself (before the generator mixes it
    /// further): flipping any one of the 320 input bits flips each of the 64 output bits with
    /// probability ½. Over 2 000 random inputs per input bit, each of the 20 480 (input bit,
    /// output bit) frequencies has standard error 0.011; a Šidák family-wise level of 1e-3
    /// puts the bound at z = 6.1, i.e. |p − ½| ≤ 0.068.
    #[test]
    fn every_input_bit_flips_every_hash_bit_half_the_time() {
        const INPUTS: usize = 2_000;
        let mut rng = Pcg64Mcg::new(0xa5a5);
        let mut next = || rand::Rng::next_u64(&mut rng);
        let hash = |w: [u64; 5]| {
            let f = |x: u64| f32::from_bits(x as u32);
            let g = |x: u64| f32::from_bits((x >> 32) as u32);
            Hasher::directions(
                w[0],
                w[1],
                Vec3::new(f(w[2]), g(w[2]), f(w[3])),
                Vec3::new(g(w[3]), f(w[4]), g(w[4])),
            )
            .0
        };
        let inputs: Vec<[u64; 5]> = (0..INPUTS).map(|_| [next(), next(), next(), next(), next()]).collect();
        let mut worst = 0.0f64;
        for word in 0..5 {
            for bit in 0..64 {
                let mut flips = [0u32; 64];
                for &w in &inputs {
                    let mut v = w;
                    v[word] ^= 1 << bit;
                    let d = hash(w) ^ hash(v);
                    for (o, f) in flips.iter_mut().enumerate() {
                        *f += ((d >> o) & 1) as u32;
                    }
                }
                for f in flips {
                    worst = worst.max((f64::from(f) / INPUTS as f64 - 0.5).abs());
                }
            }
        }
        let se = (0.25 / INPUTS as f64).sqrt();
        eprintln!("strict avalanche: largest |p − ½| {worst:.4} ({:.1} standard errors)", worst / se);
        assert!(worst <= 6.1 * se, "an output bit flips with probability ½ ± {worst}");
    }
}
