//! Mathematical constants shared by the special functions, the slope distributions and the
//! samplers, in the precision they are used in.

/// √π, rounded to f64 (`core` has no such constant).
pub(crate) const SQRT_PI: f64 = 1.772_453_850_905_516;

/// 1/√π, rounded to f64 (`core` has 2/√π only; halving that is exact, so this equals
/// `FRAC_2_SQRT_PI / 2` bit for bit).
pub(crate) const INV_SQRT_PI: f64 = 0.564_189_583_547_756_3;

#[cfg(test)]
mod tests {
    use super::*;

    /// Both constants are the correctly rounded values (1/√π is 2/√π halved, an exact
    /// operation; √π squared is π to within the rounding of one product).
    #[test]
    fn constants_are_correctly_rounded() {
        assert_eq!(INV_SQRT_PI, 0.5 * core::f64::consts::FRAC_2_SQRT_PI);
        assert!(
            (SQRT_PI * SQRT_PI - core::f64::consts::PI).abs() <= 2.0 * f64::EPSILON * core::f64::consts::PI
        );
        assert!((SQRT_PI * INV_SQRT_PI - 1.0).abs() <= f64::EPSILON);
    }
}
