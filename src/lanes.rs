//! Lanes: the number types the crate's formula kernels are written over, so that one formula
//! serves the scalar calls (one lane: `f32` or `f64`), the three colour channels of a Fresnel
//! term (`glam::Vec3A`) and the batch calls (eight f32 lanes, [`F32x8`]).
//!
//! Every operation of a lane type is the same IEEE operation applied to each lane, in the same
//! order (no fused multiply-add, no reassociation): a kernel instantiated with [`F32x8`] returns,
//! lane by lane, the very bits it returns when instantiated with `f32`. [`F32x8`] is a plain
//! `[f32; 8]` whose operations are loops over the eight lanes; LLVM turns each loop into one
//! 256-bit instruction inside a function compiled for AVX2 ([`dispatch`]), and into two 128-bit
//! ones elsewhere. Branches of a formula become [`Lanes::choose`]: a branch for one lane, both
//! sides blended for several (each side skipped when no lane needs it).

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
    ($t:ty) => {
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
                // x + ½ ≥ 0, so truncation is the floor
                let q = (self + 0.5) as i32;
                (q as $t, q & 1 != 0, q & 2 != 0)
            }
        }
    };
}

scalar_lanes!(f32);
scalar_lanes!(f64);

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
}

/// The number of lanes of [`F32x8`].
pub(crate) const WIDTH: usize = 8;

/// Eight f32 lanes (one AVX register), each operation a loop over the lanes.
#[derive(Debug, Clone, Copy, PartialEq)]
#[repr(C, align(32))]
pub(crate) struct F32x8(pub(crate) [f32; WIDTH]);

/// Eight lane masks, all bits set or clear (the layout of an AVX compare's result).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(C, align(32))]
pub(crate) struct M32x8(pub(crate) [i32; WIDTH]);

impl F32x8 {
    /// The lanes of a slice of exactly [`WIDTH`] values.
    #[inline(always)]
    pub(crate) fn load(s: &[f32]) -> Self {
        let mut out = [0.0; WIDTH];
        out.copy_from_slice(&s[..WIDTH]);
        Self(out)
    }

    /// Writes the lanes to a slice of at least [`WIDTH`] values.
    #[inline(always)]
    pub(crate) fn store(self, s: &mut [f32]) {
        s[..WIDTH].copy_from_slice(&self.0);
    }

    /// Lane-wise map (for the integer steps of a kernel).
    #[inline(always)]
    fn map(self, f: impl Fn(f32) -> f32) -> Self {
        Self(self.0.map(f))
    }

    /// Lane-wise combination of two operands.
    #[inline(always)]
    fn zip(self, other: Self, f: impl Fn(f32, f32) -> f32) -> Self {
        let mut out = [0.0; WIDTH];
        for i in 0..WIDTH {
            out[i] = f(self.0[i], other.0[i]);
        }
        Self(out)
    }

    /// Lane-wise comparison.
    #[inline(always)]
    fn cmp(self, other: Self, f: impl Fn(f32, f32) -> bool) -> M32x8 {
        let mut out = [0; WIDTH];
        for i in 0..WIDTH {
            out[i] = -i32::from(f(self.0[i], other.0[i]));
        }
        M32x8(out)
    }
}

impl M32x8 {
    /// The lanes as bits of an integer (lane i at bit i).
    #[inline(always)]
    pub(crate) fn bits(self) -> u32 {
        let mut b = 0;
        for i in 0..WIDTH {
            b |= u32::from(self.0[i] != 0) << i;
        }
        b
    }
}

impl Mask for M32x8 {
    #[inline(always)]
    fn all(self) -> bool {
        self.0.iter().fold(-1, |a, &m| a & m) != 0
    }
    #[inline(always)]
    fn any(self) -> bool {
        self.0.iter().fold(0, |a, &m| a | m) != 0
    }
}

impl BitAnd for M32x8 {
    type Output = Self;
    #[inline(always)]
    fn bitand(self, o: Self) -> Self {
        let mut out = self.0;
        for i in 0..WIDTH {
            out[i] &= o.0[i];
        }
        Self(out)
    }
}

impl BitOr for M32x8 {
    type Output = Self;
    #[inline(always)]
    fn bitor(self, o: Self) -> Self {
        let mut out = self.0;
        for i in 0..WIDTH {
            out[i] |= o.0[i];
        }
        Self(out)
    }
}

impl Not for M32x8 {
    type Output = Self;
    #[inline(always)]
    fn not(self) -> Self {
        Self(self.0.map(|m| !m))
    }
}

macro_rules! lane_op {
    ($tr:ident, $f:ident, $op:tt) => {
        impl $tr for F32x8 {
            type Output = Self;
            #[inline(always)]
            fn $f(self, o: Self) -> Self {
                self.zip(o, |a, b| a $op b)
            }
        }
    };
}

lane_op!(Add, add, +);
lane_op!(Sub, sub, -);
lane_op!(Mul, mul, *);
lane_op!(Div, div, /);

impl Neg for F32x8 {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        self.map(|a| -a)
    }
}

impl Lanes for F32x8 {
    type Mask = M32x8;
    #[inline(always)]
    fn lit(x: f32) -> Self {
        Self([x; WIDTH])
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        self.map(f32::sqrt)
    }
    #[inline(always)]
    fn abs(self) -> Self {
        self.map(f32::abs)
    }
    #[inline(always)]
    fn min(self, other: Self) -> Self {
        self.zip(other, f32::min)
    }
    #[inline(always)]
    fn max(self, other: Self) -> Self {
        self.zip(other, f32::max)
    }
    #[inline(always)]
    fn clamp(self, lo: Self, hi: Self) -> Self {
        let mut out = [0.0; WIDTH];
        for i in 0..WIDTH {
            // f32::clamp without its assertion lo ≤ hi (the kernels pass ordered bounds)
            let mut x = self.0[i];
            if x < lo.0[i] {
                x = lo.0[i];
            }
            if x > hi.0[i] {
                x = hi.0[i];
            }
            out[i] = x;
        }
        Self(out)
    }
    #[inline(always)]
    fn lt(self, other: Self) -> M32x8 {
        self.cmp(other, |a, b| a < b)
    }
    #[inline(always)]
    fn le(self, other: Self) -> M32x8 {
        self.cmp(other, |a, b| a <= b)
    }
    #[inline(always)]
    fn gt(self, other: Self) -> M32x8 {
        self.cmp(other, |a, b| a > b)
    }
    #[inline(always)]
    fn ge(self, other: Self) -> M32x8 {
        self.cmp(other, |a, b| a >= b)
    }
    #[inline(always)]
    fn eq(self, other: Self) -> M32x8 {
        self.cmp(other, |a, b| a == b)
    }
    #[inline(always)]
    fn select(mask: M32x8, a: Self, b: Self) -> Self {
        let mut out = [0.0; WIDTH];
        for i in 0..WIDTH {
            let bits = (a.0[i].to_bits() & mask.0[i] as u32) | (b.0[i].to_bits() & !mask.0[i] as u32);
            out[i] = f32::from_bits(bits);
        }
        Self(out)
    }
    #[inline(always)]
    fn quadrant(self) -> (Self, M32x8, M32x8) {
        // x + ½ ∈ [0, 5): its floor is the truncation of the scalar form, and the bits of the
        // small integer q come from the floors of q/2 and q/4 (all exact), in float
        // instructions that vectorize (a float-to-int conversion with Rust's saturation does
        // not)
        let q = (self + Self::lit(0.5)).map(f32::floor);
        let half = q * Self::lit(0.5);
        let odd = half.ne_floor();
        let quarter = q * Self::lit(0.25);
        let high = (quarter - quarter.map(f32::floor)).ge(Self::lit(0.5));
        (q, odd, high)
    }
}

impl F32x8 {
    /// The lanes whose value is not an integer.
    #[inline(always)]
    fn ne_floor(self) -> M32x8 {
        self.cmp(self.map(f32::floor), |a, b| a != b)
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

/// Whether this CPU runs the AVX2 + FMA build of the batch loops (checked once).
#[cfg(target_arch = "x86_64")]
#[inline]
pub(crate) fn has_avx2() -> bool {
    use std::sync::atomic::{AtomicU8, Ordering};
    static STATE: AtomicU8 = AtomicU8::new(0);
    match STATE.load(Ordering::Relaxed) {
        1 => true,
        2 => false,
        _ => {
            let yes = std::is_x86_feature_detected!("avx2") && std::is_x86_feature_detected!("fma");
            STATE.store(if yes { 1 } else { 2 }, Ordering::Relaxed);
            yes
        }
    }
}

/// A loop over lanes that [`dispatch`] compiles for the best instruction set of the CPU.
pub(crate) trait LaneLoop {
    /// The loop (inlined into the instruction-set-specific copies of [`dispatch`]).
    fn run(&mut self);
}

/// Runs `op` compiled with AVX2 and FMA where the CPU has them (checked once per process), and
/// compiled for the build's baseline (SSE2 on x86-64) otherwise. The arithmetic is the same
/// IEEE operations either way (no fused multiply-adds are formed), so both give the same bits.
#[inline]
#[allow(unsafe_code)]
pub(crate) fn dispatch<Op: LaneLoop>(op: &mut Op) {
    #[cfg(target_arch = "x86_64")]
    {
        if has_avx2() {
            // SAFETY: the CPU supports AVX2 and FMA (checked above).
            unsafe { run_avx2(op) };
            return;
        }
    }
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

    /// Each lane of every F32x8 operation is the f32 operation, NaN and signed zeros included.
    #[test]
    fn lanes_are_the_scalar_operations() {
        let xs = [0.0f32, -0.0, 1.5, -2.25, f32::NAN, f32::INFINITY, 1e-40, 3.0];
        let ys = [-0.0f32, 0.0, f32::NAN, 7.0, 1.0, -1.0, 1e-40, 3.0];
        let (a, b) = (F32x8(xs), F32x8(ys));
        let same = |l: F32x8, f: &dyn Fn(f32, f32) -> f32| {
            for i in 0..WIDTH {
                assert_eq!(l.0[i].to_bits(), f(xs[i], ys[i]).to_bits(), "lane {i}");
            }
        };
        same(a + b, &|x, y| x + y);
        same(a - b, &|x, y| x - y);
        same(a * b, &|x, y| x * y);
        same(a / b, &|x, y| x / y);
        same(a.min(b), &f32::min);
        same(a.max(b), &f32::max);
        same(a.sqrt(), &|x, _| x.sqrt());
        same(-a, &|x, _| -x);
        let m = a.lt(b);
        for i in 0..WIDTH {
            assert_eq!(m.bits() >> i & 1 == 1, xs[i] < ys[i]);
        }
        same(F32x8::select(m, a, b), &|x, y| if x < y { x } else { y });
        let (q, b0, b1) = F32x8([0.0, 0.3, 0.6, 1.2, 2.0, 2.7, 3.4, 4.2]).quadrant();
        assert_eq!(q.0, [0.0, 0.0, 1.0, 1.0, 2.0, 3.0, 3.0, 4.0]);
        assert_eq!(b0.bits(), 0b0110_0110);
        assert_eq!(b1.bits(), 0b0111_0000);
    }
}
