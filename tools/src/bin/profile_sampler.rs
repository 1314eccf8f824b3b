//! A profiling driver for the visible-normal samplers (`sample_d_wi`, as in `benches/geometry.rs`'s
//! `sample_d_wi` group): `calls` samples at polar angle θ from 4096 precomputed inputs (random
//! azimuths and uniforms), for instruction counts under `valgrind --tool=callgrind`. Run it with
//! two call counts and take the difference per call: that removes the start-up, the inputs and
//! the Beckmann guess table's one-time build, and leaves the sampler plus a few instructions of
//! loop.
//!
//! Usage: `profile_sampler {beckmann|ggx} theta calls [α]` (α = 0.5 by default)

use microsurface::glam::Vec3;
use microsurface::slope::MicrosurfaceSlope;
use microsurface::{Beckmann, Ggx};
use std::hint::black_box;

/// Inputs cycled through by the loop.
const INPUTS: usize = 4096;

/// A small deterministic generator of uniforms in [0, 1) (SplitMix64).
fn uniforms(seed: &mut u64) -> f32 {
    *seed = seed.wrapping_add(0x9e37_79b9_7f4a_7c15);
    let mut z = *seed;
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^= z >> 31;
    (z >> 40) as f32 / (1u64 << 24) as f32
}

fn run<S: MicrosurfaceSlope>(slope: S, theta: f64, calls: usize) -> f32 {
    let mut seed = 17;
    let inputs: Vec<(Vec3, f32, f32)> = (0..INPUTS)
        .map(|_| {
            let phi = f64::from(uniforms(&mut seed)) * std::f64::consts::TAU;
            let w = Vec3::new(
                (theta.sin() * phi.cos()) as f32,
                (theta.sin() * phi.sin()) as f32,
                theta.cos() as f32,
            );
            (w.normalize(), uniforms(&mut seed), uniforms(&mut seed))
        })
        .collect();
    let mut sum = 0.0f32;
    for k in 0..calls {
        let (w, u1, u2) = inputs[k % INPUTS];
        sum += black_box(&slope).sample_d_wi(black_box(w), u1, u2).z;
    }
    sum
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let (slope, theta, calls, alpha) = match &args[..] {
        [_, s, t, c] => (s, t, c, 0.5),
        [_, s, t, c, a] => (s, t, c, a.parse().expect("a roughness")),
        _ => panic!("usage: profile_sampler {{beckmann|ggx}} theta calls [α]"),
    };
    let theta: f64 = theta.parse().expect("an angle");
    let calls: usize = calls.parse().expect("a call count");
    let sum = match slope.as_str() {
        "beckmann" => run(Beckmann::isotropic(alpha).expect("valid roughness"), theta, calls),
        "ggx" => run(Ggx::isotropic(alpha).expect("valid roughness"), theta, calls),
        _ => panic!("unknown slope {slope}"),
    };
    println!("{slope} θ = {theta}: {calls} calls, sum of m.z {sum}");
}
