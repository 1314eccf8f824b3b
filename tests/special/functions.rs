//! Maximum errors of the public special functions over their whole domains, measured against
//! `statrs` (double precision) and checked against the bounds their doc comments state.
//!
//! Run with `cargo test --release --test special_functions -- --nocapture` to see the measured
//! figures.

use statrs::function::{beta as sbeta, erf as serf, gamma as sgamma};
use validation::check::ulp32;

/// 2/√π = erf'(0).
const TWO_OVER_SQRT_PI: f64 = std::f64::consts::FRAC_2_SQRT_PI;

/// A monotone integer key of an f32 (adjacent floats differ by 1, ±0 map to 0).
fn key(x: f32) -> i64 {
    let b = x.to_bits();
    if b & 0x8000_0000 != 0 { -i64::from(b & 0x7fff_ffff) } else { i64::from(b) }
}

/// The distance in f32 ulps between `x` and `reference` rounded to f32.
fn ulp_distance(x: f32, reference: f64) -> u64 {
    key(x).abs_diff(key(reference as f32))
}

/// |x − reference| in units of the f32 spacing at the reference (0.5 = correctly rounded).
fn frac_ulps(x: f32, reference: f64) -> f64 {
    (f64::from(x) - reference).abs() / ulp32(reference)
}

/// The running maximum of an error, with its argument.
#[derive(Debug, Clone, Copy)]
struct MaxErr {
    err: f64,
    at: f64,
}

impl MaxErr {
    fn new() -> Self {
        Self { err: 0.0, at: f64::NAN }
    }

    fn push(&mut self, err: f64, at: f64) {
        assert!(!err.is_nan(), "NaN error at {at:e}");
        if err > self.err {
            self.err = err;
            self.at = at;
        }
    }
}

/// Every f32 argument of erf/erfc under test: a dense uniform grid of [−10, 10], a log grid
/// of magnitudes from the smallest subnormal to 10, and the extremes.
fn erf_arguments() -> Vec<f32> {
    let mut xs = Vec::new();
    let n = 1 << 20;
    for k in 0..=n {
        xs.push((-10.0 + 20.0 * k as f64 / n as f64) as f32);
    }
    let m = 100_000;
    for k in 0..=m {
        // 1e-45 .. 10
        let mag = (10f64.ln() + (1e-45f64.ln() - 10f64.ln()) * k as f64 / m as f64).exp() as f32;
        xs.push(mag);
        xs.push(-mag);
    }
    // the f32 neighbours of a few breakpoints of musl's erf (0.84375, 1.25, 1/0.35, 6, 28)
    for b in [0.84375f32, 1.25, 2.857_142_8, 6.0, 10.05] {
        let mut x = b;
        for _ in 0..64 {
            x = x.next_down();
        }
        for _ in 0..128 {
            xs.push(x);
            xs.push(-x);
            x = x.next_up();
        }
    }
    xs.extend([0.0, -0.0, f32::MIN_POSITIVE, -f32::MIN_POSITIVE, 1e-45, -1e-45, 26.0, 100.0, f32::MAX]);
    xs.extend([-26.0, -100.0, -f32::MAX]);
    xs
}

#[test]
fn erf_is_within_one_ulp() {
    let (mut ulps, mut frac) = (0u64, MaxErr::new());
    let mut worst_at = 0.0f32;
    for x in erf_arguments() {
        let r = microsurface::special::erf(x);
        let reference = serf::erf(f64::from(x));
        assert!(r.is_finite() && (-1.0..=1.0).contains(&r), "erf({x:e}) = {r}");
        let d = ulp_distance(r, reference);
        if d > ulps {
            ulps = d;
            worst_at = x;
        }
        frac.push(frac_ulps(r, reference), f64::from(x));
    }
    println!(
        "erf: max {ulps} ulp (at x = {worst_at:e}) vs statrs rounded to f32; max {:.4} f32 ulps vs the f64 \
         reference (at x = {:e})",
        frac.err, frac.at
    );
    assert!(ulps <= 1, "erf: {ulps} ulp at x = {worst_at:e}: the doc states 1 ulp");
    // special values and symmetry
    assert_eq!(microsurface::special::erf(0.0), 0.0);
    assert_eq!(microsurface::special::erf(f32::INFINITY), 1.0);
    assert_eq!(microsurface::special::erf(f32::NEG_INFINITY), -1.0);
    assert!(microsurface::special::erf(f32::NAN).is_nan());
    for x in erf_arguments() {
        assert_eq!(microsurface::special::erf(-x), -microsurface::special::erf(x), "erf is odd at {x:e}");
    }
}

#[test]
fn erfc_has_one_ulp_relative_error_where_normal() {
    let (mut ulps, mut rel) = (0u64, MaxErr::new());
    let mut worst_at = 0.0f32;
    let (mut sub_ulps, mut sub_at) = (0u64, 0.0f32);
    for x in erf_arguments() {
        let r = microsurface::special::erfc(x);
        let reference = serf::erfc(f64::from(x));
        assert!(r.is_finite() && (0.0..=2.0).contains(&r), "erfc({x:e}) = {r}");
        let d = ulp_distance(r, reference);
        if (reference as f32).is_normal() {
            if d > ulps {
                ulps = d;
                worst_at = x;
            }
            rel.push((f64::from(r) - reference).abs() / reference, f64::from(x));
        } else if d > sub_ulps {
            sub_ulps = d;
            sub_at = x;
        }
    }
    println!(
        "erfc: max {ulps} ulp (at x = {worst_at:e}) and max relative error {:.3e} (at x = {:e}) where the \
         result is a normal f32; max {sub_ulps} ulp (at x = {sub_at:e}) in the subnormal range",
        rel.err, rel.at
    );
    assert!(ulps <= 1, "erfc: {ulps} ulp at x = {worst_at:e}: the doc states 1 ulp");
    assert!(rel.err <= f64::from(f32::EPSILON), "erfc: relative error {:.3e} at x = {:e}", rel.err, rel.at);
    assert!(sub_ulps <= 1, "erfc: {sub_ulps} subnormal ulp at x = {sub_at:e}");

    // the underflow threshold: the largest x with erfc(x) > 0
    let mut x = 10.0f32;
    while microsurface::special::erfc(x.next_up()) > 0.0 {
        x = x.next_up();
    }
    println!("erfc: last x with erfc(x) > 0 is {x:.9} (erfc = {:e})", microsurface::special::erfc(x));
    assert!(microsurface::special::erfc(x) > 0.0);
    for y in [x.next_up(), 10.1, 11.0, 27.0, 1e10, f32::MAX, f32::INFINITY] {
        assert_eq!(microsurface::special::erfc(y), 0.0, "erfc({y}) underflows");
    }
    // the documented threshold: erfc underflows to 0 for x > 10.05
    assert!(
        (10.05..10.06).contains(&x),
        "erfc underflows after x = {x}, the doc states 10.05 (to two decimals)"
    );
    assert_eq!(microsurface::special::erfc(f32::NEG_INFINITY), 2.0);
    assert_eq!(microsurface::special::erfc(0.0), 1.0);
    assert!(microsurface::special::erfc(f32::NAN).is_nan());
}

/// erf⁻¹(y) in double precision: statrs' erf_inv polished by one Newton step on a residual
/// formed from statrs' erfc in the tail (1 − |y| is exact for f32 inputs).
fn erfinv_reference(y: f32) -> f64 {
    let a = f64::from(y).abs();
    let mut x = serf::erf_inv(a);
    let residual = if a <= 0.5 { serf::erf(x) - a } else { (1.0 - a) - serf::erfc(x) };
    x -= residual / (TWO_OVER_SQRT_PI * (-x * x).exp());
    x.copysign(f64::from(y))
}

/// Every y of (−1, 1) under test: a dense uniform grid, every f32 within 2¹⁶ ulps of ±1, a log
/// grid of 1 − |y| down to 2⁻²⁴ and a log grid of |y| down to the smallest subnormal.
fn erfinv_arguments() -> Vec<f32> {
    let mut ys = Vec::new();
    let n = 1 << 20;
    for k in 1..n {
        ys.push((-1.0 + 2.0 * k as f64 / n as f64) as f32);
    }
    let mut y = 1.0f32;
    for _ in 0..(1 << 16) {
        y = y.next_down();
        ys.push(y);
        ys.push(-y);
    }
    let m = 50_000;
    for k in 0..=m {
        let t = k as f64 / m as f64;
        // 1 − |y| from 0.5 down to 2⁻²⁴ (f32 rounds y to the grid of spacing 2⁻²⁴ near 1)
        let y = (1.0 - (0.5f64.ln() + (2f64.powi(-24).ln() - 0.5f64.ln()) * t).exp()) as f32;
        // |y| from 0.5 down to 1e-45
        let small = (0.5f64.ln() + (1e-45f64.ln() - 0.5f64.ln()) * t).exp() as f32;
        ys.extend([y, -y, small, -small]);
    }
    ys.retain(|y| y.abs() < 1.0);
    ys
}

#[test]
fn erfinv_is_within_one_ulp() {
    let (mut ulps, mut frac, mut worst_at) = (0u64, MaxErr::new(), 0.0f32);
    let mut ys = erfinv_arguments();
    for &y in &ys {
        let r = microsurface::special::erfinv(y);
        let reference = erfinv_reference(y);
        assert!(r.is_finite(), "erfinv({y:e}) = {r}");
        let d = ulp_distance(r, reference);
        if d > ulps {
            ulps = d;
            worst_at = y;
        }
        frac.push(frac_ulps(r, reference), f64::from(y));
    }
    println!(
        "erfinv: max {ulps} ulp (at y = {worst_at:e}) vs the polished statrs reference rounded to f32; max \
         {:.4} f32 ulps vs the f64 reference (at y = {:e}); {} arguments",
        frac.err,
        frac.at,
        ys.len()
    );
    assert!(ulps <= 1, "erfinv: {ulps} ulp at y = {worst_at:e}: the doc states 1 ulp");

    // the largest finite results: the f32 neighbours of ±1
    let below_one = 1.0f32.next_down();
    println!(
        "erfinv(1 − 2⁻²⁴) = {} (reference {})",
        microsurface::special::erfinv(below_one),
        erfinv_reference(below_one)
    );
    // monotone and odd
    ys.sort_by(f32::total_cmp);
    for w in ys.windows(2) {
        assert!(
            microsurface::special::erfinv(w[0]) <= microsurface::special::erfinv(w[1]),
            "erfinv decreases at {:e}",
            w[1]
        );
    }
    for &y in &ys {
        assert_eq!(
            microsurface::special::erfinv(-y),
            -microsurface::special::erfinv(y),
            "erfinv is odd at {y:e}"
        );
    }
    // documented special values
    assert_eq!(microsurface::special::erfinv(0.0), 0.0);
    assert_eq!(microsurface::special::erfinv(1.0), f32::MAX);
    assert_eq!(microsurface::special::erfinv(-1.0), -f32::MAX);
    assert!(microsurface::special::erfinv(f32::NAN).is_nan());
}

/// ln Γ(x) at exactly representable x, from mpmath at 50 digits (the f64 literal is the correctly
/// rounded value): an independent reference for the points where statrs and libm disagree.
#[rustfmt::skip]
#[allow(clippy::excessive_precision)] // 22 digits, parsed to the correctly rounded f64
const LN_GAMMA_TABLE: [(f64, f64); 30] = [
    (0.001, 6.907178885383853661684),
    (0.003, 5.807418734725978203894),
    (0.01, 4.599479878042021701581),
    (0.1, 2.252712651734205902006),
    (0.5, 0.5723649429247000870717),
    (0.9, 0.06637623973474295442597),
    (0.999, 0.0005780385328913802381689),
    (1.001, -0.0005763935982833061515192),
    (1.2, -0.08537409000331583688375),
    (1.4616321449683622, -0.1214862905358496080955),
    (1.5, -0.1207822376352452223455),
    (1.999, -0.0004224618006921072841757),
    (2.001, 0.0004231067348001169911903),
    (2.5, 0.2846828704729191596325),
    (2.7961985102873155, 0.513510557897971087186),
    (3.5, 1.200973602347074224816),
    (7.3, 7.147892523022248692104),
    (10.0, 12.80182748008146961121),
    (33.3, 82.60372358165494300782),
    (100.5, 361.4355404677776215553),
    (171.6, 709.6573587630563212999),
    (1000.25, 5906.947268271117176996),
    (3651.7, 26299.82303330034247329),
    (8223.392130838512, 65904.74556269634281522),
    (9999.9, 82098.7964679052863047),
    (10000.0, 82099.71749644237727265),
    (33000.0, 310336.3905444426033771),
    (100000.3, 1051291.162850246418776),
    (440000.0, 5277587.624267274966936),
    (1000000.0, 12815504.56914761165998),
];

/// ln B(a, b) = ln Γ(a) + ln Γ(b) − ln Γ(a + b) from mpmath at 50 digits.
#[rustfmt::skip]
#[allow(clippy::excessive_precision)]
const LN_BETA_TABLE: [(f64, f64, f64); 17] = [
    (0.001, 0.001, 7.600900817008347378501),
    (0.001, 10000.0, 6.897968594962708313672),
    (0.5, 0.5, 1.144729885849400174143),
    (1.1091748152624015, 10000.0, -10.26958386242008243395),
    (1.5, 2.5, -1.627858836390381063526),
    (10.0, 20.0, -19.11532729988704536264),
    (100.0, 10000.0, -562.3931981971056768133),
    (1000.0, 1000.0, -1388.482601635902250296),
    (3651.7, 42.0, -230.7245005184431975208),
    (6683.439175686151, 9225.714271547642, -10826.59651678268293753),
    (10000.0, 10000.0, -13866.28325676140963952),
    (10000.0, 1.0, -9.210340371976182736072),
    (2.0, 9999.0, -18.42058073895203211381),
    (5000.0, 7.5, -56.34945742544610219168),
    (1.02, 1.37, -0.3388800550516340963936),
    (11.5, 1.0001, -2.442653268692977284098),
    (2500.5, 0.01, 4.521239397866819047258),
];

/// The spacing of the f64 numbers at |v|.
fn ulp64(v: f64) -> f64 {
    let v = v.abs();
    if v == 0.0 { f64::from_bits(1) } else { v.next_up() - v }
}

/// Arguments of ln Γ: a log grid of [1e-3, 1e6], the neighbourhoods of its zeros 1 and 2,
/// and the integers and half-integers up to 200.
fn ln_gamma_arguments() -> Vec<f64> {
    let mut xs = Vec::new();
    let n = 300_000;
    for k in 0..=n {
        xs.push((1e-3f64.ln() + (1e6f64.ln() - 1e-3f64.ln()) * k as f64 / n as f64).exp());
    }
    for k in -10_000..=10_000 {
        let d = k as f64 * 1e-5;
        xs.extend([1.0 + d, 2.0 + d]);
    }
    for k in 1..=400 {
        xs.push(0.5 * k as f64);
    }
    xs
}

#[test]
fn ln_gamma_matches_statrs_and_mpmath() {
    // against the 50-digit table: within 1 f64 ulp of the correctly rounded value everywhere
    let mut vs_table = MaxErr::new();
    for (x, reference) in LN_GAMMA_TABLE {
        let r = microsurface::special::ln_gamma(x);
        vs_table.push((r - reference).abs() / ulp64(reference), x);
    }
    println!("ln_gamma vs mpmath (50 digits): max {:.3} f64 ulps (at x = {:e})", vs_table.err, vs_table.at);
    assert!(vs_table.err <= 1.0, "ln_gamma: {:.3} ulps from mpmath at x = {:e}", vs_table.err, vs_table.at);

    // against statrs on the dense grid: statrs' Lanczos sum is itself only good to about 1e-14
    // absolute near its small arguments and a few ulps of |ln Γ| for large ones, so the bound
    // is on err / max(1, |ln Γ|) (measured: about 2e-14, from statrs)
    let (mut abs_below, mut rel_above, mut scaled) = (MaxErr::new(), MaxErr::new(), MaxErr::new());
    for x in ln_gamma_arguments() {
        let r = microsurface::special::ln_gamma(x);
        let reference = sgamma::ln_gamma(x);
        assert!(r.is_finite(), "ln_gamma({x:e}) = {r}");
        let err = (r - reference).abs();
        if x < 1e4 {
            abs_below.push(err, x);
        } else {
            rel_above.push(err / reference.abs(), x);
        }
        scaled.push(err / reference.abs().max(1.0), x);
    }
    println!(
        "ln_gamma vs statrs on [1e-3, 1e6]: max absolute error {:.3e} (at x = {:e}) for x < 1e4; max relative \
         error {:.3e} (at x = {:e}) for x ≥ 1e4; max err/max(1, |ln Γ|) = {:.3e} (at x = {:e})",
        abs_below.err, abs_below.at, rel_above.err, rel_above.at, scaled.err, scaled.at
    );
    assert!(
        rel_above.err < 1e-14,
        "ln_gamma: relative error {:.3e} at x = {:e}",
        rel_above.err,
        rel_above.at
    );
    assert!(scaled.err < 5e-14, "ln_gamma: scaled error {:.3e} at x = {:e}", scaled.err, scaled.at);
    // exact values
    assert_eq!(microsurface::special::ln_gamma(1.0), 0.0);
    assert_eq!(microsurface::special::ln_gamma(2.0), 0.0);
    assert!((microsurface::special::ln_gamma(0.5) - 0.5 * std::f64::consts::PI.ln()).abs() <= ulp64(0.57));
}

/// a, b on a log grid of [1e-3, 1e4].
fn beta_arguments() -> Vec<f64> {
    let n = 400;
    (0..=n).map(|k| (1e-3f64.ln() + (1e4f64.ln() - 1e-3f64.ln()) * k as f64 / n as f64).exp()).collect()
}

/// The rounding scale of ln B(a, b) = ln Γ(a) + ln Γ(b) − ln Γ(a + b): 2⁻⁵³ (|ln Γ(a)| +
/// |ln Γ(b)| + |ln Γ(a + b)| + 1). Each term carries about one rounding of its own size (and
/// ln Γ(a + b) also that of a + b), so the error of the sum is a small multiple of this.
fn ln_beta_scale(a: f64, b: f64) -> f64 {
    let g = |x: f64| sgamma::ln_gamma(x).abs();
    f64::EPSILON * 0.5 * (g(a) + g(b) + g(a + b) + 1.0)
}

#[test]
fn ln_beta_and_beta_match_statrs_and_mpmath() {
    // against the 50-digit table
    let (mut ln_table, mut rel_table) = (MaxErr::new(), MaxErr::new());
    for (a, b, reference) in LN_BETA_TABLE {
        let scale = ln_beta_scale(a, b);
        ln_table.push((microsurface::special::ln_beta(a, b) - reference).abs() / scale, a);
        let exact = reference.exp();
        if exact < f64::MIN_POSITIVE {
            continue;
        }
        // exp adds its own rounding and amplifies the ln B error into a relative one
        rel_table.push((microsurface::special::beta(a, b) - exact).abs() / exact / (scale + f64::EPSILON), a);
    }
    println!(
        "ln_beta vs mpmath: max {:.3} × 2⁻⁵³(|lnΓa|+|lnΓb|+|lnΓ(a+b)|+1) (a = {:e}); beta: max relative error \
         {:.3} × that scale",
        ln_table.err, ln_table.at, rel_table.err
    );
    assert!(
        ln_table.err <= 4.0,
        "ln_beta: {:.3} scale units from mpmath at a = {:e}",
        ln_table.err,
        ln_table.at
    );
    assert!(
        rel_table.err <= 4.0,
        "beta: {:.3} scale units from mpmath at a = {:e}",
        rel_table.err,
        rel_table.at
    );
    let (a, b, reference) = LN_BETA_TABLE[9];
    println!(
        "ln_beta({a}, {b}): absolute error {:.3e} vs mpmath (the doc states < 1e-11)",
        (microsurface::special::ln_beta(a, b) - reference).abs()
    );

    // against statrs, which forms the same three-term sum with its own ln Γ
    let grid = beta_arguments();
    let (mut ln_abs, mut rel, mut scaled) = (MaxErr::new(), MaxErr::new(), MaxErr::new());
    let (mut at_a, mut at_b) = (0.0, 0.0);
    for &a in &grid {
        for &b in &grid {
            let reference = sbeta::ln_beta(a, b);
            let l = microsurface::special::ln_beta(a, b);
            let bb = microsurface::special::beta(a, b);
            assert!(l.is_finite() && bb.is_finite() && bb >= 0.0, "ln_beta({a}, {b}) = {l}, beta = {bb}");
            let e = (l - reference).abs();
            if e > ln_abs.err {
                (at_a, at_b) = (a, b);
            }
            ln_abs.push(e, a);
            // libm's rounding (4 scale units, as against mpmath) plus statrs' own ln Γ error
            // (below 5e-14·max(1, |ln Γ|) per term, as measured in the ln Γ test)
            let g = |x: f64| sgamma::ln_gamma(x).abs().max(1.0);
            let allowance = 4.0 * ln_beta_scale(a, b) + 5e-14 * (g(a) + g(b) + g(a + b));
            scaled.push(e / allowance, a);
            // relative error of beta where exp(ln B) is a normal f64
            let expected = reference.exp();
            if expected > f64::MIN_POSITIVE {
                rel.push((bb - expected).abs() / expected, a);
            }
            assert_eq!(microsurface::special::beta(b, a), bb, "beta is symmetric");
        }
    }
    println!(
        "ln_beta vs statrs on a, b ∈ [1e-3, 1e4]: max absolute error {:.3e} at (a, b) = ({at_a:e}, {at_b:e}); \
         max {:.3} of the allowance; beta: max relative error {:.3e} (a = {:e})",
        ln_abs.err, scaled.err, rel.err, rel.at
    );
    assert!(
        scaled.err <= 1.0,
        "ln_beta: {:.3} × the allowance from statrs at a = {:e}",
        scaled.err,
        scaled.at
    );
    assert!(ln_abs.err < 1e-10, "ln_beta: absolute error {:.3e} at ({at_a:e}, {at_b:e})", ln_abs.err);
    assert!(rel.err < 1e-10, "beta: relative error {:.3e} at a = {:e}", rel.err, rel.at);

    // exact identities, independent of any reference: B(a, 1) = 1/a, B(½, ½) = π and
    // B(a + 1, b) = B(a, b)·a/(a + b) (where both are normal f64)
    let mut identity = MaxErr::new();
    for &a in &grid {
        let scale = ln_beta_scale(a, 1.0) + f64::EPSILON;
        identity.push((microsurface::special::beta(a, 1.0) * a - 1.0).abs() / scale, a);
        for &b in grid.iter().step_by(7) {
            let (hi, lo) = (microsurface::special::beta(a + 1.0, b), microsurface::special::beta(a, b));
            if hi > f64::MIN_POSITIVE && lo > f64::MIN_POSITIVE {
                let scale = ln_beta_scale(a + 1.0, b) + ln_beta_scale(a, b) + 2.0 * f64::EPSILON;
                identity.push((hi / lo * (a + b) / a - 1.0).abs() / scale, a);
            }
        }
    }
    identity.push(
        (microsurface::special::beta(0.5, 0.5) / std::f64::consts::PI - 1.0).abs() / ln_beta_scale(0.5, 0.5),
        0.5,
    );
    println!("beta identities: max relative error {:.3} scale units (a = {:e})", identity.err, identity.at);
    assert!(identity.err <= 8.0, "beta identities: {:.3} scale units at a = {:e}", identity.err, identity.at);
    // huge arguments underflow to 0 rather than forming ∞/∞
    assert_eq!(microsurface::special::beta(1e6, 1e6), 0.0);
    assert_eq!(microsurface::special::beta(1.0, 1.0), 1.0);
}

/// The documented bound of `sin_cos_turns`: absolute error over [0, 1].
const SIN_COS_TURNS_MAX_ERROR: f64 = 1.2e-7;

#[test]
fn sin_cos_turns_is_within_its_documented_bound_on_every_f32_in_the_unit_interval() {
    // every f32 in [0, 1]: the 2^24 multiples of 2^-24 (the crate's uniforms) and all the
    // finer floats below 2^-1 (exhaustive: about 1.07e9 values would take too long, so every
    // float with exponent ≥ −24 is visited and the rest, where sin ≈ 2πu, on a stride)
    let (mut worst, mut at) = (0.0f64, 0.0f32);
    let mut check = |u: f32| {
        let (s, c) = microsurface::special::sin_cos_turns(u);
        let angle = core::f64::consts::TAU * f64::from(u);
        let err = (f64::from(s) - angle.sin()).abs().max((f64::from(c) - angle.cos()).abs());
        if err > worst {
            (worst, at) = (err, u);
        }
    };
    for k in 0..=(1u32 << 24) {
        check(k as f32 / (1u32 << 24) as f32);
    }
    let mut bits = 0u32;
    while bits <= 1.0f32.to_bits() {
        check(f32::from_bits(bits));
        bits += 97;
    }
    eprintln!("sin_cos_turns: worst absolute error {worst:.3e} at u = {u:e}", u = at);
    assert!(
        worst <= SIN_COS_TURNS_MAX_ERROR,
        "sin_cos_turns errs by {worst:e} at u = {at:e} (bound {SIN_COS_TURNS_MAX_ERROR:e})"
    );
}
