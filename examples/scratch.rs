use glam::Vec3;
use microsurface::*;
use rand::SeedableRng;
fn main() {
    let b = Beckmann::isotropic(0.05).unwrap();
    let th = 2.8f32;
    let wi = Vec3::new(th.sin(), 0.0, th.cos());
    let a = 0.05f64;
    let (wx, wz) = (wi.x as f64 * a, wi.z as f64);
    let kappa = wz / wx;
    let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(3);
    let (mut bad, mut minx, mut maxx, mut maxy) = (0, f64::MAX, f64::MIN, 0f64);
    for _ in 0..1_000_000 {
        let u1: f32 = rand::RngExt::random(&mut rng);
        let u2: f32 = rand::RngExt::random(&mut rng);
        let m = b.sample_d_wi(wi, u1, u2);
        let z = (m.z as f64).max(1e-300);
        let x = -(m.x as f64) / z / a;
        let y = -(m.y as f64) / z / a;
        minx = minx.min(x);
        maxx = maxx.max(x);
        maxy = maxy.max(y.abs());
        if x > kappa || b.d_wi(wi, m) == 0.0 {
            bad += 1;
            if bad < 5 {
                println!("bad: u1 {u1} u2 {u2} m {m:?} x {x} kappa {kappa} d_wi {}", b.d_wi(wi, m));
            }
        }
    }
    println!("bad {bad} x range [{minx}, {maxx}] kappa {kappa} max|y| {maxy}");
}
