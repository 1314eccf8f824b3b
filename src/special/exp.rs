//! The exponential of a non-positive argument without a library call, for the Beckmann kernels
//! that need e^{−a²} to a relative accuracy near double precision but not to the last ulp.

/// Below this argument [`exp_nonpositive`] returns 0 (e^x < 3.3e-308 there, near the end of the
/// normal f64 range).
pub(crate) const EXP_NONPOSITIVE_FROM: f64 = -708.0;

/// 1.5·2⁵²: adding it rounds an f64 of magnitude below 2⁵¹ to the nearest integer, which the low
/// 32 bits of the sum then hold in two's complement.
pub(crate) const ROUNDING_MAGIC: f64 = 6_755_399_441_055_744.0;

// 32/ln 2, ln 2/32 split in Cody and Waite's manner and 2^{j/32}, from 50-digit mpmath
// (`scripts/exp_table.py`)
const INV_LN2_32: f64 = 46.16624130844683;
const LN2_32_HI: f64 = 0.021660849392446835;
const LN2_32_LO: f64 = 5.145609244655338e-14;
#[allow(clippy::approx_constant)] // 2^{16/32} = √2, from the generator
const TWO_TO_J_32: [f64; 32] = [
    1.0,
    1.0218971486541166,
    1.0442737824274138,
    1.0671404006768237,
    1.0905077326652577,
    1.1143867425958924,
    1.1387886347566916,
    1.1637248587775775,
    1.189207115002721,
    1.215247359980469,
    1.241857812073484,
    1.2690509571917332,
    1.2968395546510096,
    1.3252366431597413,
    1.3542555469368927,
    1.383909881963832,
    1.4142135623730951,
    1.4451808069770467,
    1.4768261459394993,
    1.5091644275934228,
    1.5422108254079407,
    1.5759808451078865,
    1.6104903319492543,
    1.645755478153965,
    1.681792830507429,
    1.718619298122478,
    1.7562521603732995,
    1.7947090750031072,
    1.8340080864093424,
    1.8741676341103,
    1.9152065613971474,
    1.9571441241754002,
];

/// e^x for x ∈ [−708, 0] (0 below −708, NaN for NaN): x = (k/32) ln 2 + r with k the nearest
/// integer of 32x/ln 2 (|r| ≤ ln 2/64), e^x = 2^{⌊k/32⌋}·2^{(k mod 32)/32}·e^r with the table
/// `TWO_TO_J_32` and e^r by its Taylor polynomial of degree 5 (Estrin's scheme).
///
/// Relative error below 4e-15 (the polynomial's truncation r⁶/720 ≤ 2.3e-15 plus a few
/// roundings; measured against the standard library's exp by the unit test). Also correct for
/// small positive x (up to 700), which the callers do not pass.
#[must_use]
#[inline(always)]
pub(crate) fn exp_nonpositive(x: f64) -> f64 {
    if x < EXP_NONPOSITIVE_FROM {
        return 0.0;
    }
    let shifted = x * INV_LN2_32 + ROUNDING_MAGIC;
    // the low 32 bits: k in two's complement (|k| < 2¹⁵)
    let k = shifted.to_bits() as u32 as i32;
    let kf = shifted - ROUNDING_MAGIC;
    let r = (x - kf * LN2_32_HI) - kf * LN2_32_LO;
    let r2 = r * r;
    let poly = (1.0 + r) + r2 * ((0.5 + r * (1.0 / 6.0)) + r2 * ((1.0 / 24.0) + r * (1.0 / 120.0)));
    // 2^{⌊k/32⌋} added to the table entry's exponent (an arithmetic shift is the floor); the
    // result stays normal for x ≥ −708
    let table = TWO_TO_J_32[(k & 31) as usize];
    let scale = f64::from_bits(table.to_bits().wrapping_add(((i64::from(k >> 5)) << 52) as u64));
    scale * poly
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The documented relative error.
    const MAX_RELATIVE_ERROR: f64 = 4e-15;

    /// Against the standard library's exp (correctly rounded to within an ulp) on 10⁶ points
    /// of [−708, 0] and near 0, and the limits.
    #[test]
    fn exp_nonpositive_meets_its_error_bound() {
        let mut worst = 0.0f64;
        let n = 1_000_000;
        for i in 0..=n {
            for x in [EXP_NONPOSITIVE_FROM * i as f64 / n as f64, -1e-3 * i as f64 / n as f64] {
                let exact = x.exp();
                worst = worst.max((exp_nonpositive(x) / exact - 1.0).abs());
            }
        }
        eprintln!("exp_nonpositive: worst relative error {worst:.3e}");
        assert!(worst <= MAX_RELATIVE_ERROR, "relative error {worst:e} > {MAX_RELATIVE_ERROR:e}");
        assert_eq!(exp_nonpositive(0.0), 1.0);
        assert_eq!(exp_nonpositive(-0.0), 1.0);
        assert_eq!(exp_nonpositive(-708.5), 0.0);
        assert_eq!(exp_nonpositive(f64::NEG_INFINITY), 0.0);
        assert!(exp_nonpositive(f64::NAN).is_nan());
        // the split is exact: k·HI has at most 53 significant bits for |k| < 2¹⁵
        assert_eq!(LN2_32_HI.to_bits() & ((1 << 15) - 1), 0);
    }
}
