//! The extreme uniforms carry no more probability than the model gives them.
//!
//! The crate's uniforms are multiples of 2⁻²⁴ in [0, 1 − 2⁻²⁴], each with probability 2⁻²⁴; a
//! renderer's f32 uniform in [0, 1) is at most 1 − 2⁻²⁴ too. Every sampler cuts the tails of
//! its quantiles at 2⁻²⁴ (see the crate's `rng` module): for u = 0 and u = 1 − 2⁻²⁴, the
//! probability that the model assigns beyond the sampled value, in the variable the uniform
//! drives, must be of the order of the bucket. It is computed here in double precision
//! (Gaussian tails from `statrs`' erfc, the visible-slope CDF by Simpson quadrature of its
//! density, the spherical cap and the disks in closed form) and required to be at least
//! `MIN_TAIL` = 2⁻²⁶ (a quarter of a bucket, which leaves room for the samplers' documented
//! approximations). Every sample must also have a positive, finite density where it lands.
//!
//! Before the fix u = 0 gave a Beckmann slope of −8.1 (tail 1e-30), a GGX cap point on the
//! pole of the cap (tail 0), a cosine direction on the horizon (density 0) and a first height
//! at the top of the surface (tail 0).

use glam::{DVec3, Vec3};
use microsurface::research::{
    GaussianHeight, HeightSample, MicrosurfaceGeometry, MicrosurfaceHeight, UniformHeight, concentric_disk,
    sample_cosine_hemisphere,
};
use microsurface::slope::MicrosurfaceSlope;
use microsurface::vndf::{
    BeckmannNewton, GgxDisk, GgxSphericalCap, SmithVndf, VCavity, VisibleNormalSampler,
};
use microsurface::{Beckmann, Ggx};
use statrs::function::erf::erfc;

/// A quarter of the uniforms' spacing: the smallest tail accepted beyond an extreme sample.
const MIN_TAIL: f64 = 1.0 / (1u64 << 26) as f64;
/// The largest uniform, 1 − 2⁻²⁴.
const U_MAX: f32 = 1.0 - 1.0 / 16_777_216.0;
/// The extreme uniforms.
const EXTREMES: [f32; 2] = [0.0, U_MAX];
/// Uniforms for the other coordinate of a 2D sampler.
const OTHERS: [f32; 5] = [0.0, 0.25, 0.5, 0.8, U_MAX];

/// Polar angles of the incident directions, from the zenith to far below the horizon.
const THETAS: [f64; 7] = [0.0, 0.3, 1.0, 1.45, 1.7, 2.2, 2.8];

struct Report {
    failures: Vec<String>,
    checked: usize,
    smallest: f64,
}

impl Report {
    fn new() -> Self {
        Self { failures: Vec::new(), checked: 0, smallest: f64::INFINITY }
    }

    fn tail(&mut self, what: String, tail: f64) {
        self.checked += 1;
        self.smallest = self.smallest.min(tail);
        if tail.is_nan() || tail < MIN_TAIL {
            self.failures.push(format!("{what}: tail beyond the sample {tail:.3e} < 2⁻²⁶ = {MIN_TAIL:.3e}"));
        }
    }

    fn density(&mut self, what: String, pdf: f32) {
        self.checked += 1;
        if pdf.is_nan() || pdf <= 0.0 || pdf.is_infinite() {
            self.failures.push(format!("{what}: density {pdf:e} at the sample"));
        }
    }

    fn finish(self, name: &str) {
        eprintln!(
            "{name}: {} checks, smallest tail {:.3e}, {} failures",
            self.checked,
            self.smallest,
            self.failures.len()
        );
        assert!(self.checked >= 20, "{name}: only {} checks", self.checked);
        assert!(
            self.failures.is_empty(),
            "{name}: {} failures:\n{}",
            self.failures.len(),
            self.failures.join("\n")
        );
    }
}

/// Composite Simpson's rule of `f` on [a, b] with `n` (even) intervals.
fn simpson(f: impl Fn(f64) -> f64, a: f64, b: f64, n: usize) -> f64 {
    let h = (b - a) / n as f64;
    let mut s = f(a) + f(b);
    for k in 1..n {
        s += f(a + k as f64 * h) * if k % 2 == 1 { 4.0 } else { 2.0 };
    }
    s * h / 3.0
}

/// The Gaussian slope tail ½ erfc(|x|) beyond x (density e^{−x²}/√π).
fn gaussian_tail(x: f64) -> f64 {
    0.5 * erfc(x.abs())
}

/// The visible-slope density ∝ (κ − x) e^{−x²} on x < κ (α = 1, cot θ = κ): the probabilities
/// below x and above x, by Simpson quadrature on [min(κ, 0) − 12, κ] (beyond it the density
/// is below e^{−144}).
fn visible_slope_tails(kappa: f64, x: f64) -> (f64, f64) {
    let f = |t: f64| (kappa - t) * (-t * t).exp();
    // the density's support that matters: [min(κ, 0) − 12, κ]
    let start = kappa.min(0.0) - 12.0;
    let total = simpson(f, start, kappa, 200_000);
    let below = if x <= start { 0.0 } else { simpson(f, start, x, 200_000) };
    let above = simpson(f, x.min(kappa), kappa, 20_000);
    (below / total, above / total)
}

/// Stretched slopes of a normal, in the azimuth frame of the stretched ωi: (x̃ along it, ỹ
/// across), and κ = cot θ of the stretched ωi (+∞ for ωi = +z).
fn stretched_slopes<S: MicrosurfaceSlope>(slope: &S, wi: Vec3, wm: Vec3) -> (f64, f64, f64) {
    let (ax, ay) = (f64::from(slope.alpha_x()), f64::from(slope.alpha_y()));
    let m = wm.as_dvec3();
    let (sx, sy) = (-m.x / m.z / ax, -m.y / m.z / ay);
    let (vx, vy, vz) = (ax * f64::from(wi.x), ay * f64::from(wi.y), f64::from(wi.z));
    let len = vx.hypot(vy);
    let (c, s) = if len > 0.0 { (vx / len, vy / len) } else { (1.0, 0.0) };
    let kappa = if len > 0.0 { vz / len } else { f64::INFINITY };
    (c * sx + s * sy, -s * sx + c * sy, kappa)
}

/// The tail beyond a Beckmann sample for uniforms (u1, u2) in the extreme set: the visible
/// slope along the azimuth (Gaussian for ωi = +z) for u1, the Gaussian slope across for u2.
fn beckmann_tails(r: &mut Report, what: &str, slope: &Beckmann, wi: Vec3, wm: Vec3, u1: f32, u2: f32) {
    let (x, y, kappa) = stretched_slopes(slope, wi, wm);
    if EXTREMES.contains(&u1) {
        let tail = if kappa.is_infinite() {
            gaussian_tail(x)
        } else {
            let (below, above) = visible_slope_tails(kappa, x);
            if u1 == 0.0 { below } else { above }
        };
        r.tail(format!("{what} u1 = {u1:e}, x̃ = {x}, κ = {kappa}"), tail);
    }
    if EXTREMES.contains(&u2) {
        r.tail(format!("{what} u2 = {u2:e}, ỹ = {y}"), gaussian_tail(y));
    }
}

fn direction(theta: f64, phi: f64) -> Vec3 {
    DVec3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos()).as_vec3()
}

fn roughnesses() -> [(f32, f32); 4] {
    [(1.0, 1.0), (0.3, 0.3), (1.0, 0.1), (0.05, 0.5)]
}

#[test]
fn beckmann_slope_samplers_keep_their_tails() {
    let mut r = Report::new();
    // the examples
    let b = Beckmann::isotropic(1.0).unwrap();
    let s = b.sample_p22_11(1.0, 0.0, 0.5, 0.0);
    eprintln!("Beckmann(1).sample_p22_11(1, 0, 0.5, 0) = {s}");
    r.tail(format!("sample_p22_11(1, 0, 0.5, 0) = {s}"), gaussian_tail(f64::from(s.y)));
    let b = Beckmann::new(1.0, 0.1).unwrap();
    let wm = b.sample_d_wi(Vec3::Z, 0.824_472_2, 0.0);
    let (d_wi, d_wi_peak) = (b.d_wi(Vec3::Z, wm), b.d_wi(Vec3::Z, Vec3::Z));
    eprintln!("Beckmann(1, 0.1).sample_d_wi(+z, 0.8244722, 0) = {wm}: D_ωi = {d_wi:e} (peak {d_wi_peak:e})");
    // D_ωi at the sample relative to its peak is e^{−ỹ²} ≥ 2 · 2⁻²⁶ · √π ỹ for a tail ≥ 2⁻²⁶
    assert!(f64::from(d_wi) > 1e-8 * f64::from(d_wi_peak), "D_ωi = {d_wi:e} at the u2 = 0 sample");
    beckmann_tails(&mut r, "Beckmann(1, 0.1).sample_d_wi(+z)", &b, Vec3::Z, wm, 0.824_472_2, 0.0);

    for (ax, ay) in roughnesses() {
        let b = Beckmann::new(ax, ay).unwrap();
        for theta in THETAS {
            let wi = direction(theta, 0.7);
            let (cos_t, sin_t) = (theta.cos() as f32, theta.sin() as f32);
            for &u1 in EXTREMES.iter().chain(&OTHERS) {
                for &u2 in OTHERS.iter() {
                    if !(EXTREMES.contains(&u1) || EXTREMES.contains(&u2)) {
                        continue;
                    }
                    let tag = format!("Beckmann({ax}, {ay}) θ = {theta}");
                    let wm = b.sample_d_wi(wi, u1, u2);
                    r.density(format!("{tag} sample_d_wi({u1:e}, {u2:e}) = {wm}"), b.d_wi(wi, wm));
                    beckmann_tails(&mut r, &format!("{tag} sample_d_wi"), &b, wi, wm, u1, u2);
                    let wm = SmithVndf(b).sample(wi, [u1, u2, 0.5]);
                    beckmann_tails(&mut r, &format!("{tag} SmithVndf"), &b, wi, wm, u1, u2);
                    if wi.z > 0.0 {
                        let wm = BeckmannNewton(b).sample(wi, [u1, u2, 0.5]);
                        r.density(format!("{tag} BeckmannNewton({u1:e}, {u2:e}) = {wm}"), b.d_wi(wi, wm));
                        beckmann_tails(&mut r, &format!("{tag} BeckmannNewton"), &b, wi, wm, u1, u2);
                    }
                    if ax == ay && ax == 1.0 {
                        // the α = 1 slopes themselves, seen from (sin θ, 0, cos θ)
                        let s = b.sample_p22_11(cos_t, sin_t, u1, u2);
                        let wm = Vec3::new(-s.x, -s.y, 1.0).normalize();
                        let w0 = Vec3::new(sin_t, 0.0, cos_t);
                        beckmann_tails(&mut r, &format!("{tag} sample_p22_11"), &b, w0, wm, u1, u2);
                    }
                }
            }
        }
    }
    r.finish("Beckmann slopes");
}

/// Below this v̂·m̂ the cap height of an f32 normal is not resolved: c.z + v̂.z = 2(v̂·m̂)m̂.z,
/// and rounding m̂ to f32 moves v̂·m̂ by up to ~1e-7 (at the bottom of the cap's far side,
/// c → −v̂, the exact tail 2⁻²⁴ has v̂·m̂ ~ 1e-8). There the sampled normals are only required
/// to be visible (and to have a positive density), not to show their tail.
const CAP_RESOLVED_FROM: f64 = 1e-5;

/// Checks the u1 tail of a cap sample: above (u1 = 0) always; below (u1 = 1⁻) where resolved.
fn check_cap(r: &mut Report, what: String, slope: &Ggx, wi: Vec3, wm: DVec3, u1: f32) {
    let (above, below, cos_vm) = cap_tails(slope, wi, wm);
    if u1 == 0.0 {
        r.tail(what, above);
    } else if cos_vm >= CAP_RESOLVED_FROM {
        r.tail(what, below);
    } else {
        r.checked += 1;
        if cos_vm.is_nan() || cos_vm <= -1e-7 {
            r.failures.push(format!("{what}: not visible, v̂·m̂ = {cos_vm:e}"));
        }
    }
}

/// The spherical-cap point c = reflect(−v̂, m̂) of a GGX normal, in the stretched frame, and the
/// cap's tails: the share of the cap above c.z (u1 = 0 end) and below it (u1 = 1⁻ end); and v̂·m̂.
fn cap_tails(slope: &Ggx, wi: Vec3, wm: DVec3) -> (f64, f64, f64) {
    let (ax, ay) = (f64::from(slope.alpha_x()), f64::from(slope.alpha_y()));
    let v = DVec3::new(ax * f64::from(wi.x), ay * f64::from(wi.y), f64::from(wi.z)).normalize();
    let m = DVec3::new(wm.x / ax, wm.y / ay, wm.z).normalize();
    let c = 2.0 * v.dot(m) * m - v;
    // 1 − c.z and c.z + v.z without cancellation
    let above = (c.x * c.x + c.y * c.y) / (1.0 + c.z);
    let below = 2.0 * v.dot(m) * m.z;
    (above / (1.0 + v.z), below / (1.0 + v.z), v.dot(m))
}

#[test]
fn ggx_spherical_cap_samplers_keep_their_tails() {
    let mut r = Report::new();
    for (ax, ay) in roughnesses() {
        let g = Ggx::new(ax, ay).unwrap();
        for theta in THETAS {
            let wi = direction(theta, 0.7);
            // the cap's far side c ≈ −v̂ (u1 → 1 at the azimuth opposite to the stretched ωi),
            // where normalize(v̂ + c) is ill-conditioned: that azimuth and its neighbours
            let phi = (f64::from(ay) * 0.7f64.sin()).atan2(f64::from(ax) * 0.7f64.cos());
            let opposite = (phi / std::f64::consts::TAU + 0.5) as f32;
            let step = 1.0 / 16_777_216.0;
            let azimuths =
                [opposite - 2.0 * step, opposite - step, opposite, opposite + step, opposite + 2.0 * step];
            for u1 in EXTREMES {
                for &u2 in OTHERS.iter().chain(&azimuths) {
                    let tag = format!("Ggx({ax}, {ay}) θ = {theta} u = ({u1:e}, {u2})");
                    let samples = [
                        ("sample_d_wi", g.sample_d_wi(wi, u1, u2)),
                        ("SmithVndf", SmithVndf(g).sample(wi, [u1, u2, 0.5])),
                        ("GgxSphericalCap", GgxSphericalCap(g).sample(wi, [u1, u2, 0.5])),
                    ];
                    for (name, wm) in samples {
                        r.density(format!("{tag} {name} = {wm}"), g.d_wi(wi, wm));
                        check_cap(&mut r, format!("{tag} {name} = {wm}"), &g, wi, wm.as_dvec3(), u1);
                    }
                    if ax == 1.0 && ay == 1.0 {
                        let (cos_t, sin_t) = (theta.cos() as f32, theta.sin() as f32);
                        let s = g.sample_p22_11(cos_t, sin_t, u1, u2);
                        // in f64: a grazing normal's slopes reach 1e38
                        let wm = DVec3::new(-f64::from(s.x), -f64::from(s.y), 1.0).normalize();
                        let w0 = Vec3::new(sin_t, 0.0, cos_t);
                        check_cap(&mut r, format!("{tag} sample_p22_11 = {s}"), &g, w0, wm, u1);
                    }
                }
            }
        }
    }
    r.finish("GGX spherical caps");
}

#[test]
fn ggx_disk_samplers_keep_their_tails() {
    // the disk point's radius r = √u1 drives the tail: P(r′ < r) = r² at u1 = 0; at the rim
    // (u1 = 1⁻) the sample must still have a positive density (the rim itself has none)
    let mut r = Report::new();
    for (ax, ay) in roughnesses() {
        let g = Ggx::new(ax, ay).unwrap();
        for theta in THETAS {
            let wi = direction(theta, 0.7);
            for u1 in EXTREMES {
                for u2 in OTHERS {
                    let tag = format!("Ggx({ax}, {ay}) θ = {theta} u = ({u1:e}, {u2})");
                    let wm = GgxDisk(g).sample(wi, [u1, u2, 0.5]);
                    r.density(format!("{tag} GgxDisk = {wm}"), g.d_wi(wi, wm));
                    for u3 in [0.0, 0.5, U_MAX] {
                        let wm = VCavity(g).sample(wi, [u1, u2, u3]);
                        r.density(format!("{tag} VCavity<Ggx>(u3 = {u3}) = {wm}"), VCavity(g).pdf(wi, wm));
                    }
                    if wi.z > 0.0 && u1 == 0.0 {
                        // front-facing V-cavity: D(m) m.z is uniform on the stretched unit disk,
                        // so the share of normals closer to the pole than the sample is r²
                        let wm = VCavity(g).sample(wi, [u1, u2, 0.0]);
                        let m = DVec3::new(
                            f64::from(wm.x) / f64::from(ax),
                            f64::from(wm.y) / f64::from(ay),
                            f64::from(wm.z),
                        )
                        .normalize();
                        r.tail(format!("{tag} VCavity<Ggx> = {wm}"), m.x * m.x + m.y * m.y);
                    }
                }
            }
        }
    }
    r.finish("GGX disks");
}

#[test]
fn beckmann_v_cavity_keeps_its_tails() {
    let mut r = Report::new();
    for (ax, ay) in roughnesses() {
        let b = Beckmann::new(ax, ay).unwrap();
        for theta in THETAS {
            let wi = direction(theta, 0.7);
            for u1 in EXTREMES.iter().chain(&OTHERS) {
                for u2 in OTHERS {
                    for u3 in [0.0, 0.5] {
                        let u = [*u1, u2, u3];
                        let wm = VCavity(b).sample(wi, u);
                        let tag = format!("Beckmann({ax}, {ay}) θ = {theta} u = {u:?}");
                        r.density(format!("{tag} VCavity = {wm}"), VCavity(b).pdf(wi, wm));
                        if wi.z > 0.0 {
                            // front-facing: both slopes Gaussian (D(m) m.z), up to a mirror image
                            let (x, y, _) = stretched_slopes(&b, Vec3::Z, wm);
                            if EXTREMES.contains(u1) {
                                r.tail(format!("{tag} x̃ = {x}"), gaussian_tail(x));
                            }
                            if EXTREMES.contains(&u2) {
                                r.tail(format!("{tag} ỹ = {y}"), gaussian_tail(y));
                            }
                        }
                    }
                }
            }
        }
    }
    r.finish("Beckmann V-cavity");
}

#[test]
fn cosine_and_disk_samplers_keep_their_tails() {
    let mut r = Report::new();
    for u1 in EXTREMES.iter().chain(&OTHERS) {
        for u2 in EXTREMES.iter().chain(&OTHERS) {
            if !(EXTREMES.contains(u1) || EXTREMES.contains(u2)) {
                continue;
            }
            // the concentric map sends the square's boundary to the rim: P(r′ > r) = 1 − r²
            let d = concentric_disk(*u1, *u2).as_dvec2();
            r.tail(format!("concentric_disk({u1:e}, {u2:e}) = {d}"), 1.0 - d.length_squared());
            // cosine-weighted: P(cos θ′ < cos θ) = cos²θ
            let w = sample_cosine_hemisphere(*u1, *u2);
            r.tail(
                format!("sample_cosine_hemisphere({u1:e}, {u2:e}) = {w}"),
                f64::from(w.z) * f64::from(w.z),
            );
        }
    }
    r.finish("cosine and disk");
}

#[test]
fn height_samplers_keep_their_tails() {
    // a ray from above the surface going down: its first hit has C¹ = (1 − u)^{1/|Λ|}, and the
    // share of hits above the sample is 1 − C¹(h)^{|Λ|}. `sample_height` returns heights, whose
    // C¹ is an f32: it resolves a tail of 2⁻²⁴ only for |Λ| < 2 (documented there; the walks
    // work in ln C¹, tested by the unit test of `next_ln_c1`), so straight down (|Λ| = 1) and
    // θ = 2 (|Λ| = 1.1 at α = 0.5)
    fn check<H: MicrosurfaceHeight>(r: &mut Report, name: &str, height: H, upper_tail: impl Fn(f32) -> f64) {
        let slope = Ggx::isotropic(0.5).unwrap();
        let g = MicrosurfaceGeometry::new(height, slope);
        for theta in [std::f64::consts::PI, 2.0] {
            let down = direction(theta, 0.3);
            let lambda = -f64::from(slope.lambda(down));
            assert!(lambda < 2.0, "|Λ| = {lambda}");
            for u in [0.0, 1.0 / 16_777_216.0] {
                match g.sample_height(down, f32::INFINITY, u) {
                    HeightSample::Hit(h) => {
                        let above = -(lambda * (-upper_tail(h)).ln_1p()).exp_m1();
                        r.tail(format!("{name} from above, θ = {theta}, u = {u:e}: h = {h}"), above)
                    }
                    HeightSample::Escape => r.failures.push(format!("{name}: a downward ray escaped")),
                }
            }
        }
    }
    let mut r = Report::new();
    // 1 − C¹(h) in double precision
    check(&mut r, "UniformHeight", UniformHeight, |h| 0.5 * (1.0 - f64::from(h)));
    check(&mut r, "GaussianHeight", GaussianHeight, |h| 0.5 * erfc(f64::from(h) / std::f64::consts::SQRT_2));
    eprintln!("heights: {} checks, smallest {:.3e}", r.checked, r.smallest);
    assert!(r.checked == 8 && r.failures.is_empty(), "{}", r.failures.join("\n"));
}
