//! The pre-generated inputs of the BSDF benches (`benches/bsdf.rs`) and of the profiling driver
//! that counts their instructions (`tools/src/bin/profile_compensated.rs`): `N` views uniform on the
//! upper hemisphere, `N` light directions (upper hemisphere, or the whole sphere for a
//! transmitting material) and `N` triples of uniforms, from a fixed seed.

use core::f32::consts::TAU;
use glam::{Vec2, Vec3};
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64Mcg;

/// The number of inputs (a power of two: a rotation through them is a mask).
pub const N: usize = 1024;

/// A uniform direction on the upper hemisphere (or the whole sphere), never horizontal.
fn direction(rng: &mut Pcg64Mcg, sphere: bool) -> Vec3 {
    let u = 1.0 - rng.random::<f32>(); // (0, 1]
    let z = if sphere && rng.random::<bool>() { -u } else { u };
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = TAU * rng.random::<f32>();
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// Views, light directions and uniforms, `N` of each.
pub struct Inputs {
    pub wo: Vec<Vec3>,
    pub wi: Vec<Vec3>,
    pub uc: Vec<f32>,
    pub u: Vec<Vec2>,
}

/// The inputs of generator `seed`, light directions on the whole sphere if `transmits`.
pub fn inputs(transmits: bool, seed: u64) -> Inputs {
    let mut rng = Pcg64Mcg::seed_from_u64(seed);
    let wo = (0..N).map(|_| direction(&mut rng, false)).collect();
    let wi = (0..N).map(|_| direction(&mut rng, transmits)).collect();
    let uc = (0..N).map(|_| rng.random::<f32>()).collect();
    let u = (0..N).map(|_| Vec2::new(rng.random(), rng.random())).collect();
    Inputs { wo, wi, uc, u }
}
