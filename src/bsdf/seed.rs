//! Deterministic randomness for the stochastic techniques behind the [`Bsdf`](super::Bsdf)
//! trait: a 64-bit hash of a call's arguments seeds a private PCG generator (the approach of
//! pbrt-v4's `LayeredBxDF`, whose generator is seeded by Hash(seed, ωo) and Hash(uc, u)), and
//! a generator that hands out the caller's uniforms before its own numbers.

use core::convert::Infallible;
use glam::{Vec2, Vec3};
use rand::TryRng;
use rand_pcg::Pcg64Mcg;

/// 2⁶⁴/φ, the Weyl increment of splitmix64: keeps the absorbed state away from the fixed
/// point 0 of [`mix64`].
const GOLDEN_GAMMA: u64 = 0x9e37_79b9_7f4a_7c15;
/// An odd constant that separates the two 64-bit halves of the generator state.
const SECOND_HALF: u64 = 0xd1b5_4a32_d192_ed03;
/// 2²⁴: the resolution of the crate's uniforms (`crate::rng::uniform` keeps the top 24 bits
/// of a `u32`).
const UNIFORM_STEPS: f32 = 16_777_216.0;
/// The largest uniform in steps of 2⁻²⁴ below 1.
const MAX_UNIFORM_STEP: u32 = (1 << 24) - 1;
/// The most caller uniforms a primed generator hands out.
const MAX_PRIMED: usize = 4;

/// The splitmix64 finalizer (Stafford's "Mix13"): a bijection of `u64` with full avalanche
/// (every input bit flips every output bit with probability ≈ ½).
#[inline(always)]
pub(crate) fn mix64(mut x: u64) -> u64 {
    x ^= x >> 30;
    x = x.wrapping_mul(0xbf58_476d_1ce4_e5b9);
    x ^= x >> 27;
    x = x.wrapping_mul(0x94d0_49bb_1331_11eb);
    x ^ (x >> 31)
}

/// A running hash of a call's arguments: every `absorb` adds the Weyl increment and the
/// word, then mixes, so that equal words at different positions hash differently.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Hasher(u64);

impl Hasher {
    /// A hash started from the BSDF's seed and the caller's key.
    #[inline(always)]
    pub(crate) fn new(seed: u64, key: u64) -> Self {
        Self(mix64(seed.wrapping_add(GOLDEN_GAMMA)) ^ key).absorb(0)
    }

    #[inline(always)]
    fn absorb(self, word: u64) -> Self {
        Self(mix64(self.0.wrapping_add(GOLDEN_GAMMA) ^ word))
    }

    /// Absorbs the bit patterns of two floats (so −0 and +0 differ, as do any two inputs
    /// whose bits differ).
    #[inline(always)]
    fn absorb_pair(self, a: f32, b: f32) -> Self {
        self.absorb(u64::from(a.to_bits()) | (u64::from(b.to_bits()) << 32))
    }

    /// Absorbs a direction and a direction (eval) — three words.
    #[inline(always)]
    pub(crate) fn directions(self, a: Vec3, b: Vec3) -> Self {
        self.absorb_pair(a.x, a.y).absorb_pair(a.z, b.x).absorb_pair(b.y, b.z)
    }

    /// Absorbs a direction and the caller's uniforms (sample) — three words.
    #[inline(always)]
    pub(crate) fn direction_uniforms(self, w: Vec3, uc: f32, u: Vec2) -> Self {
        self.absorb_pair(w.x, w.y).absorb_pair(w.z, uc).absorb_pair(u.x, u.y)
    }

    /// The PCG generator with this hash as its state (the second half of the 128-bit state
    /// is a second, independent mix of the hash).
    #[inline(always)]
    pub(crate) fn generator(self) -> Pcg64Mcg {
        let low = mix64(self.0 ^ SECOND_HALF);
        Pcg64Mcg::new((u128::from(self.0) << 64) | u128::from(low))
    }
}

/// A uniform in [0, 1) as the `u32` whose top 24 bits `crate::rng::uniform` turns back
/// into it, rounded down to a multiple of 2⁻²⁴ (the resolution of every uniform the crate
/// draws). Values outside [0, 1) never reach here (the callers check them).
#[inline(always)]
fn uniform_bits(u: f32) -> u32 {
    (((u * UNIFORM_STEPS) as u32).min(MAX_UNIFORM_STEP)) << 8
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

    /// A generator that starts with one number of its own private generator, then the
    /// caller's uniforms, then the private generator again (for walks whose first draw is a
    /// height, which the caller's sampler should not spend its stratified dimensions on).
    #[inline(always)]
    pub(crate) fn after_one_private(uniforms: &[f32], hash: H) -> Self {
        let mut rng = hash().generator();
        let mut primed = [0; MAX_PRIMED];
        primed[0] = rand::Rng::next_u32(&mut rng);
        for (p, &u) in primed[1..].iter_mut().zip(uniforms) {
            *p = uniform_bits(u);
        }
        Self { primed, len: (uniforms.len() + 1).min(MAX_PRIMED), next: 0, hash, rng: Some(rng) }
    }

    #[inline(always)]
    fn private(&mut self) -> &mut Pcg64Mcg {
        let hash = &self.hash;
        self.rng.get_or_insert_with(|| hash().generator())
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
        Ok(rand::Rng::next_u32(self.private()))
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
        let h = Hasher::new(1, 2).directions(Vec3::Z, Vec3::X);
        let mut r = PrimedRng::new(&[0.25, 0.5, 0.999_999_94], || h);
        assert_eq!(uniform(&mut r), 0.25);
        assert_eq!(uniform(&mut r), 0.5);
        assert_eq!(uniform(&mut r), 1.0 - 1.0 / UNIFORM_STEPS);
        let mut private = h.generator();
        assert_eq!(rand::Rng::next_u32(&mut r), rand::Rng::next_u32(&mut private));
        let mut r = PrimedRng::after_one_private(&[0.75], || h);
        let mut private = h.generator();
        assert_eq!(rand::Rng::next_u32(&mut r), rand::Rng::next_u32(&mut private));
        assert_eq!(uniform(&mut r), 0.75);
        assert_eq!(rand::Rng::next_u32(&mut r), rand::Rng::next_u32(&mut private));
    }

    #[test]
    fn hash_depends_on_every_argument() {
        let base = Hasher::new(3, 4).directions(Vec3::Z, Vec3::X).0;
        assert_ne!(base, Hasher::new(4, 4).directions(Vec3::Z, Vec3::X).0);
        assert_ne!(base, Hasher::new(3, 5).directions(Vec3::Z, Vec3::X).0);
        assert_ne!(base, Hasher::new(3, 4).directions(Vec3::X, Vec3::Z).0);
        assert_ne!(base, Hasher::new(3, 4).directions(Vec3::new(0.0, -0.0, 1.0), Vec3::X).0);
        assert_eq!(base, Hasher::new(3, 4).directions(Vec3::Z, Vec3::X).0);
    }
}
