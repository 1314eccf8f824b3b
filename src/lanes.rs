//! Lanes: the number types the crate's formula kernels are written over, so that one formula
//! serves the scalar f32 calls, the f64 forms of the scalar paths (one lane each) and the three
//! colour channels of a Fresnel term (`glam::Vec3A`, one SSE register).
//!
//! Every operation of a lane type is the same IEEE operation applied to each lane, in the same
//! order (no fused multiply-add, no reassociation). The batch calls run the f32 instances in
//! loops over their queries, which LLVM vectorizes (eight queries per AVX2 instruction inside
//! [`dispatch`]'s AVX2 build, four per SSE2 instruction otherwise), so a batch answer is, query
//! by query, the very bits of the f32 kernel. Branches of a formula are [`Lanes::choose`] (a
//! branch for one lane, both sides blended for several) or [`Lanes::select`] (both sides
//! computed: what a vectorized loop does with a branch anyway).

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
}
