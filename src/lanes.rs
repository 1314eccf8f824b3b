//! Lanes: the number types the crate's formula kernels are written over, so that one formula
//! serves the scalar f32 calls, the f64 forms of the scalar paths (one lane each) and the three
//! colour channels of a Fresnel term (`glam::Vec3A`, one SSE register).
//!
//! Every operation of a lane type is the same IEEE operation applied to each lane, in the same
//! order (no fused multiply-add, no reassociation). The batch calls run the f32 instances in
//! loops over their queries, which LLVM vectorizes (sixteen queries per AVX-512 instruction or
//! eight per AVX2 instruction inside [`dispatch`]'s builds for them, four per SSE2 instruction
//! otherwise), so a batch answer is, query by query, the very bits of the f32 kernel. Branches
//! of a formula are [`Lanes::choose`] (a branch for one lane, both sides blended for several)
//! or [`Lanes::select`] (both sides computed: what a vectorized loop does with a branch
//! anyway).

use core::ops::{Add, BitAnd, BitOr, Div, Mul, Neg, Not, Sub};
use glam::{BVec3A, Vec3, Vec3A};

/// The lane masks of a lane type: one boolean per lane.
pub(crate) trait Mask:
    Copy + BitAnd<Output = Self> + BitOr<Output = Self> + Not<Output = Self>
{
    /// Whether every lane is set.
    fn all(self) -> bool;
    /// Whether some lane is set.
    fn any(self) -> bool;
}

/// A number type of one or several lanes, each lane an IEEE float.
pub(crate) trait Lanes:
    Copy + Add<Output = Self> + Sub<Output = Self> + Mul<Output = Self> + Div<Output = Self> + Neg<Output = Self>
{
    /// One boolean per lane.
    type Mask: Mask;
    /// The value `x` in every lane (exact: every lane type holds every f32).
    fn lit(x: f32) -> Self;
    /// The square root of each lane.
    fn sqrt(self) -> Self;
    /// |x| of each lane.
    fn abs(self) -> Self;
    /// The lane-wise `min` of the float type (the other operand where one is NaN).
    fn min(self, other: Self) -> Self;
    /// The lane-wise `max` of the float type (the other operand where one is NaN).
    fn max(self, other: Self) -> Self;
    /// The lane-wise `clamp` of the float type (NaN stays NaN).
    fn clamp(self, lo: Self, hi: Self) -> Self;
    /// self < other.
    fn lt(self, other: Self) -> Self::Mask;
    /// self ≤ other.
    fn le(self, other: Self) -> Self::Mask;
    /// self > other.
    fn gt(self, other: Self) -> Self::Mask;
    /// self ≥ other.
    fn ge(self, other: Self) -> Self::Mask;
    /// self == other.
    fn eq(self, other: Self) -> Self::Mask;
    /// `a` where `mask` is set, `b` elsewhere.
    fn select(mask: Self::Mask, a: Self, b: Self) -> Self;
    /// The branch `if mask { a() } else { b() }` of a formula: for one lane the branch itself
    /// (only the side taken is computed), for several both sides blended, each skipped where no
    /// lane takes it.
    #[inline(always)]
    fn choose(mask: Self::Mask, a: impl FnOnce() -> Self, b: impl FnOnce() -> Self) -> Self {
        if mask.all() {
            a()
        } else if !mask.any() {
            b()
        } else {
            Self::select(mask, a(), b())
        }
    }
    /// The nearest integer q = ⌊x + ½⌋ of each lane x ∈ [0, 4.5) (a quadrant), as a float, with
    /// masks of its bits 0 and 1.
    fn quadrant(self) -> (Self, Self::Mask, Self::Mask);
    /// The nearest integer of each lane x with |x| < 2²² (ties to even), as a float: x plus and
    /// minus 1.5·2ᵖ⁻¹ (p the significand's bits), exact in the lane type's arithmetic.
    fn nearest_int(self) -> Self;
    /// (k, m) with x = 2ᵏ m and m ∈ [√½, √2) for each lane x, a positive normal float: k (a
    /// float) from the exponent field, m with that field replaced, both exact.
    fn exponent_and_mantissa(self) -> (Self, Self);
    /// 2ᵏ of each lane k, an integer in [−126, 127] (a float; a normal f32), built in the
    /// exponent field: exact.
    fn exp2_int(self) -> Self;
}

impl Mask for bool {
    #[inline(always)]
    fn all(self) -> bool {
        self
    }
    #[inline(always)]
    fn any(self) -> bool {
        self
    }
}

/// The scalar float types: one lane.
macro_rules! scalar_lanes {
    ($t:ty, $i:ty, $u:ty, $sqrt_half:expr, $shift:expr, $bias:expr, $magic:expr) => {
        impl Lanes for $t {
            type Mask = bool;
            #[inline(always)]
            fn lit(x: f32) -> Self {
                x.into()
            }
            #[inline(always)]
            fn sqrt(self) -> Self {
                <$t>::sqrt(self)
            }
            #[inline(always)]
            fn abs(self) -> Self {
                <$t>::abs(self)
            }
            #[inline(always)]
            fn min(self, other: Self) -> Self {
                <$t>::min(self, other)
            }
            #[inline(always)]
            fn max(self, other: Self) -> Self {
                <$t>::max(self, other)
            }
            #[inline(always)]
            fn clamp(self, lo: Self, hi: Self) -> Self {
                <$t>::clamp(self, lo, hi)
            }
            #[inline(always)]
            fn lt(self, other: Self) -> bool {
                self < other
            }
            #[inline(always)]
            fn le(self, other: Self) -> bool {
                self <= other
            }
            #[inline(always)]
            fn gt(self, other: Self) -> bool {
                self > other
            }
            #[inline(always)]
            fn ge(self, other: Self) -> bool {
                self >= other
            }
            #[inline(always)]
            fn eq(self, other: Self) -> bool {
                self == other
            }
            #[inline(always)]
            fn select(mask: bool, a: Self, b: Self) -> Self {
                if mask { a } else { b }
            }
            #[inline(always)]
            fn choose(mask: bool, a: impl FnOnce() -> Self, b: impl FnOnce() -> Self) -> Self {
                if mask { a() } else { b() }
            }
            #[inline(always)]
            fn quadrant(self) -> (Self, bool, bool) {
                // ⌊y⌋ of y = x + ½ ≥ 0: its nearest integer, less one where that rounded up; the
                // low bits of q are those of the significand of q + 1.5·2ᵖ⁻¹ (exact). Float
                // instructions only: a loop of them vectorizes, where the saturating `as i32`
                // is a scalar conversion per lane.
                let y = self + 0.5;
                let r = y.nearest_int();
                let q = if r > y { r - 1.0 } else { r };
                let bits = (q + $magic).to_bits();
                (q, bits & 1 != 0, bits & 2 != 0)
            }
            #[inline(always)]
            fn nearest_int(self) -> Self {
                (self + $magic) - $magic
            }
            #[inline(always)]
            fn exponent_and_mantissa(self) -> (Self, Self) {
                let bits = self.to_bits();
                let k = (bits.wrapping_sub($sqrt_half) as $i) >> $shift;
                (k as $t, <$t>::from_bits(bits.wrapping_sub((k << $shift) as $u)))
            }
            #[inline(always)]
            fn exp2_int(self) -> Self {
                <$t>::from_bits(((self as $i + $bias) as $u) << $shift)
            }
        }
    };
}

// the bits of √½, the significand's width and the exponent's bias of each float type
scalar_lanes!(f32, i32, u32, 0x3f35_04f3, 23, 127, 12_582_912.0);
scalar_lanes!(f64, i64, u64, 0x3fe6_a09e_667f_3bcd, 52, 1023, 6_755_399_441_055_744.0);

impl Mask for BVec3A {
    #[inline(always)]
    fn all(self) -> bool {
        BVec3A::all(self)
    }
    #[inline(always)]
    fn any(self) -> bool {
        BVec3A::any(self)
    }
}

/// Three f32 lanes in one SSE register: the RGB channels of a Fresnel term.
impl Lanes for Vec3A {
    type Mask = BVec3A;
    #[inline(always)]
    fn lit(x: f32) -> Self {
        Vec3A::splat(x)
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        Vec3A::sqrt(self)
    }
    #[inline(always)]
    fn abs(self) -> Self {
        Vec3A::abs(self)
    }
    #[inline(always)]
    fn min(self, other: Self) -> Self {
        Vec3A::min(self, other)
    }
    #[inline(always)]
    fn max(self, other: Self) -> Self {
        Vec3A::max(self, other)
    }
    #[inline(always)]
    fn clamp(self, lo: Self, hi: Self) -> Self {
        Vec3A::clamp(self, lo, hi)
    }
    #[inline(always)]
    fn lt(self, other: Self) -> BVec3A {
        self.cmplt(other)
    }
    #[inline(always)]
    fn le(self, other: Self) -> BVec3A {
        self.cmple(other)
    }
    #[inline(always)]
    fn gt(self, other: Self) -> BVec3A {
        self.cmpgt(other)
    }
    #[inline(always)]
    fn ge(self, other: Self) -> BVec3A {
        self.cmpge(other)
    }
    #[inline(always)]
    fn eq(self, other: Self) -> BVec3A {
        self.cmpeq(other)
    }
    #[inline(always)]
    fn select(mask: BVec3A, a: Self, b: Self) -> Self {
        Vec3A::select(mask, a, b)
    }
    #[inline(always)]
    fn quadrant(self) -> (Self, BVec3A, BVec3A) {
        let q = self.to_array().map(|x| (x + 0.5) as i32);
        let bit = |b: i32| BVec3A::new(q[0] & b != 0, q[1] & b != 0, q[2] & b != 0);
        (Vec3A::new(q[0] as f32, q[1] as f32, q[2] as f32), bit(1), bit(2))
    }
    #[inline(always)]
    fn nearest_int(self) -> Self {
        Vec3A::from_array(self.to_array().map(Lanes::nearest_int))
    }
    #[inline(always)]
    fn exponent_and_mantissa(self) -> (Self, Self) {
        let [a, b, c] = self.to_array().map(Lanes::exponent_and_mantissa);
        (Vec3A::new(a.0, b.0, c.0), Vec3A::new(a.1, b.1, c.1))
    }
    #[inline(always)]
    fn exp2_int(self) -> Self {
        Vec3A::from_array(self.to_array().map(Lanes::exp2_int))
    }
}

/// A direction or vector of lanes: three coordinates, each a lane type.
#[derive(Debug, Clone, Copy)]
pub(crate) struct V3<L> {
    pub(crate) x: L,
    pub(crate) y: L,
    pub(crate) z: L,
}

impl<L: Lanes> V3<L> {
    /// The vector (x, y, z).
    #[inline(always)]
    pub(crate) fn new(x: L, y: L, z: L) -> Self {
        Self { x, y, z }
    }

    /// The dot product, summed as glam sums it: (x x′ + y y′) + z z′.
    #[inline(always)]
    pub(crate) fn dot(self, o: Self) -> L {
        self.x * o.x + self.y * o.y + self.z * o.z
    }

    /// The squared length (as glam's `length_squared`).
    #[inline(always)]
    pub(crate) fn length_squared(self) -> L {
        self.dot(self)
    }

    /// The lane-wise sum.
    #[inline(always)]
    pub(crate) fn add(self, o: Self) -> Self {
        Self::new(self.x + o.x, self.y + o.y, self.z + o.z)
    }

    /// Each coordinate times `s`.
    #[inline(always)]
    pub(crate) fn scale(self, s: L) -> Self {
        Self::new(self.x * s, self.y * s, self.z * s)
    }

    /// `a` where `mask` is set, `b` elsewhere.
    #[inline(always)]
    pub(crate) fn select(mask: L::Mask, a: Self, b: Self) -> Self {
        Self::new(L::select(mask, a.x, b.x), L::select(mask, a.y, b.y), L::select(mask, a.z, b.z))
    }
}

impl V3<f32> {
    /// The glam vector.
    #[inline(always)]
    pub(crate) fn of(v: Vec3) -> Self {
        Self::new(v.x, v.y, v.z)
    }

    /// As a glam vector.
    #[inline(always)]
    pub(crate) fn vec3(self) -> Vec3 {
        Vec3::new(self.x, self.y, self.z)
    }
}

/// The instruction sets [`dispatch`] compiles the batch loops for, best first.
#[cfg(target_arch = "x86_64")]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum InstructionSet {
    /// AVX-512 (F, VL, DQ, BW) with AVX2 and FMA: sixteen f32 lanes per instruction.
    Avx512,
    /// AVX2 and FMA: eight f32 lanes per instruction.
    Avx2,
    /// The build's baseline (SSE2 on x86-64): four lanes.
    Baseline,
}

/// The best instruction set of this CPU for the batch loops (checked once per process).
#[cfg(target_arch = "x86_64")]
#[inline]
fn instruction_set() -> InstructionSet {
    use std::sync::atomic::{AtomicU8, Ordering};
    const SETS: [InstructionSet; 3] =
        [InstructionSet::Avx512, InstructionSet::Avx2, InstructionSet::Baseline];
    // 0: not checked yet; k + 1: SETS[k]
    static STATE: AtomicU8 = AtomicU8::new(0);
    match STATE.load(Ordering::Relaxed) {
        0 => {
            let avx2 = std::is_x86_feature_detected!("avx2") && std::is_x86_feature_detected!("fma");
            let avx512 = avx2
                && std::is_x86_feature_detected!("avx512f")
                && std::is_x86_feature_detected!("avx512vl")
                && std::is_x86_feature_detected!("avx512dq")
                && std::is_x86_feature_detected!("avx512bw");
            let k = if avx512 {
                0
            } else if avx2 {
                1
            } else {
                2
            };
            STATE.store(k as u8 + 1, Ordering::Relaxed);
            SETS[k]
        }
        k => SETS[usize::from(k - 1).min(2)],
    }
}

/// A loop over lanes that [`dispatch`] compiles for the best instruction set of the CPU.
pub(crate) trait LaneLoop {
    /// The loop (inlined into the instruction-set-specific copies of [`dispatch`]).
    fn run(&mut self);
}

/// Runs `op` compiled for the CPU's best instruction set (checked once per process): AVX-512
/// (sixteen lanes), AVX2 with FMA (eight), or the build's baseline (SSE2 on x86-64: four). The
/// arithmetic is the same IEEE operations in every build (no fused multiply-adds are formed),
/// so all give the same bits.
#[inline]
#[allow(unsafe_code)]
pub(crate) fn dispatch<Op: LaneLoop>(op: &mut Op) {
    #[cfg(target_arch = "x86_64")]
    match instruction_set() {
        // SAFETY: the CPU supports AVX-512 F, VL, DQ and BW, AVX2 and FMA (checked above).
        InstructionSet::Avx512 => return unsafe { run_avx512(op) },
        // SAFETY: the CPU supports AVX2 and FMA (checked above).
        InstructionSet::Avx2 => return unsafe { run_avx2(op) },
        InstructionSet::Baseline => {}
    }
    op.run();
}

/// [`LaneLoop::run`] compiled with AVX-512 (F, VL, DQ, BW), AVX2 and FMA enabled.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512vl,avx512dq,avx512bw,avx2,fma")]
fn run_avx512<Op: LaneLoop>(op: &mut Op) {
    op.run();
}

/// [`LaneLoop::run`] compiled with AVX2 and FMA enabled.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn run_avx2<Op: LaneLoop>(op: &mut Op) {
    op.run();
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each lane of the three-channel type is the f32 operation, NaN and signed zeros included
    /// (min and max on non-NaN operands, as the kernels use them), and the quadrant is the
    /// scalar one.
    #[test]
    fn channel_lanes_are_the_scalar_operations() {
        let xs = [0.0f32, -0.0, 1.5, -2.25, f32::NAN, f32::INFINITY, 1e-40, 3.0];
        let ys = [-0.0f32, 0.0, f32::NAN, 7.0, 1.0, -1.0, 1e-40, 3.0];
        for k in 0..xs.len() - 2 {
            let (a, b) = (Vec3A::from_slice(&xs[k..]), Vec3A::from_slice(&ys[k..]));
            let same = |l: Vec3A, f: &dyn Fn(f32, f32) -> f32| {
                for i in 0..3 {
                    assert_eq!(l[i].to_bits(), f(xs[k + i], ys[k + i]).to_bits(), "lane {i} of {k}");
                }
            };
            same(a + b, &|x, y| x + y);
            same(a - b, &|x, y| x - y);
            same(a * b, &|x, y| x * y);
            same(a / b, &|x, y| x / y);
            same(Lanes::sqrt(a), &|x, _| x.sqrt());
            same(-a, &|x, _| -x);
            let m = Lanes::lt(a, b);
            same(<Vec3A as Lanes>::select(m, a, b), &|x, y| if x < y { x } else { y });
        }
        for x in [0.0f32, 0.3, 0.6, 1.2, 2.0, 2.7, 3.4, 4.2] {
            let (q, odd, high) = Lanes::quadrant(x);
            let (q3, odd3, high3) = Lanes::quadrant(Vec3A::splat(x));
            assert_eq!((q3.x, odd3.all(), high3.all()), (q, odd, high), "{x}");
        }
    }

    /// The exponent primitives: x = 2ᵏ m with m ∈ [√½, √2) for normal x of both float types
    /// (at the boundaries of m's range too), 2ᵏ over the whole normal f32 range, the nearest
    /// integer with ties to even.
    #[test]
    fn exponent_primitives_are_exact() {
        let sqrt_half = core::f32::consts::FRAC_1_SQRT_2;
        for x in
            [f32::MIN_POSITIVE, 1e-30, 0.3, sqrt_half, sqrt_half.next_down(), 1.0, 1.414, 1.5, 7.0, f32::MAX]
        {
            let (k, m) = Lanes::exponent_and_mantissa(x);
            assert!((sqrt_half..core::f32::consts::SQRT_2).contains(&m), "{x}: m = {m}");
            assert_eq!(f64::from(m) * f64::exp2(f64::from(k)), f64::from(x), "{x}");
            let (k64, m64) = Lanes::exponent_and_mantissa(f64::from(x));
            assert!((0.5f64.sqrt()..2f64.sqrt()).contains(&m64), "{x}: m = {m64}");
            assert_eq!(m64 * f64::exp2(k64), f64::from(x), "{x}");
            let (k3, m3) = Lanes::exponent_and_mantissa(Vec3A::splat(x));
            assert_eq!((k3.x, m3.z), (k, m), "{x}");
        }
        for k in -126..=127 {
            assert_eq!(Lanes::exp2_int(k as f32), f32::exp2(k as f32), "2^{k}");
            assert_eq!(Lanes::exp2_int(f64::from(k)), f64::exp2(f64::from(k)), "2^{k}");
        }
        for (x, n) in [(0.5f32, 0.0f32), (1.5, 2.0), (-2.5, -2.0), (3.49, 3.0), (-125.7, -126.0), (4e6, 4e6)]
        {
            assert_eq!(Lanes::nearest_int(x), n, "{x}");
            assert_eq!(Lanes::nearest_int(f64::from(x)), f64::from(n), "{x}");
        }
    }
}
