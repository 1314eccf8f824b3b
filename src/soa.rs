//! Structure-of-arrays slices of the batch calls: directions and three-channel outputs as
//! three `f32` slices each (the layout of SIMD lanes, see [`BatchBsdf`](crate::BatchBsdf)).

use crate::error::Error;
use glam::Vec3;

/// Directions in structure-of-arrays layout: the x, y and z coordinates of query i are
/// `x[i]`, `y[i]` and `z[i]`.
///
/// # Examples
/// ```
/// use microsurface::Directions;
///
/// let (x, y, z) = ([0.0, 0.6], [0.0, 0.0], [1.0, 0.8]);
/// let w = Directions::new(&x, &y, &z)?;
/// assert_eq!(w.len(), 2);
/// assert!(Directions::new(&x, &y, &z[..1]).is_err());
/// # Ok::<(), microsurface::Error>(())
/// ```
#[derive(Debug, Clone, Copy)]
pub struct Directions<'a> {
    x: &'a [f32],
    y: &'a [f32],
    z: &'a [f32],
}

impl<'a> Directions<'a> {
    /// The directions of three coordinate slices of equal length.
    ///
    /// # Errors
    /// [`Error::LengthMismatch`] if `y` or `z` is not as long as `x`.
    pub fn new(x: &'a [f32], y: &'a [f32], z: &'a [f32]) -> Result<Self, Error> {
        check_len("y", x.len(), y.len())?;
        check_len("z", x.len(), z.len())?;
        Ok(Self { x, y, z })
    }

    /// The number of directions.
    #[must_use]
    pub fn len(&self) -> usize {
        self.x.len()
    }

    /// Whether there is none.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.x.is_empty()
    }

    /// Direction `i`.
    #[inline(always)]
    pub(crate) fn get(&self, i: usize) -> Vec3 {
        Vec3::new(self.x[i], self.y[i], self.z[i])
    }

    /// The three coordinate slices.
    #[inline(always)]
    pub(crate) fn slices(&self) -> (&'a [f32], &'a [f32], &'a [f32]) {
        let n = self.x.len();
        (self.x, &self.y[..n], &self.z[..n])
    }
}

/// Mutable RGB or xyz outputs in structure-of-arrays layout (three slices of equal length).
#[derive(Debug)]
pub struct Channels<'a> {
    /// The first channel (red, or x).
    pub a: &'a mut [f32],
    /// The second channel (green, or y).
    pub b: &'a mut [f32],
    /// The third channel (blue, or z).
    pub c: &'a mut [f32],
}

impl<'a> Channels<'a> {
    /// The outputs of three slices.
    pub fn new(a: &'a mut [f32], b: &'a mut [f32], c: &'a mut [f32]) -> Self {
        Self { a, b, c }
    }

    /// The three slices, of equal length.
    #[inline(always)]
    pub(crate) fn slices(&mut self) -> (&mut [f32], &mut [f32], &mut [f32]) {
        let n = self.a.len();
        (&mut *self.a, &mut self.b[..n], &mut self.c[..n])
    }

    /// Checks that every slice has `n` elements.
    pub(crate) fn check(&self, name: &'static str, n: usize) -> Result<(), Error> {
        check_len(name, n, self.a.len())?;
        check_len(name, n, self.b.len())?;
        check_len(name, n, self.c.len())
    }

    /// Element `i` of the three channels.
    #[inline(always)]
    pub(crate) fn get(&self, i: usize) -> Vec3 {
        Vec3::new(self.a[i], self.b[i], self.c[i])
    }

    #[inline(always)]
    pub(crate) fn set(&mut self, i: usize, v: Vec3) {
        self.a[i] = v.x;
        self.b[i] = v.y;
        self.c[i] = v.z;
    }
}

/// `Ok` if a slice has the batch's length, [`Error::LengthMismatch`] naming it otherwise.
pub(crate) fn check_len(name: &'static str, expected: usize, found: usize) -> Result<(), Error> {
    if expected == found { Ok(()) } else { Err(Error::LengthMismatch { name, expected, found }) }
}

/// The first index i ≥ `from` whose value is NaN (the mark of a query left to a scalar call),
/// if any: blocks of eight values tested at once (vectorized), the marked block searched.
#[inline(always)]
pub(crate) fn next_marked(values: &[f32], from: usize) -> Option<usize> {
    let rest = values.get(from..)?;
    let blocks = rest.chunks_exact(8);
    let tail = blocks.remainder();
    for (b, block) in blocks.enumerate() {
        if block.iter().fold(false, |any, x| any | x.is_nan()) {
            return block.iter().position(|x| x.is_nan()).map(|k| from + 8 * b + k);
        }
    }
    tail.iter().position(|x| x.is_nan()).map(|k| values.len() - tail.len() + k)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `next_marked` finds every NaN in order, from every start, in and across blocks of eight
    /// and in the remainder (lengths 0 to 27, marks at every third, fifth or ninth index).
    #[test]
    fn next_marked_finds_every_mark_in_order() {
        for n in 0..28 {
            for every in [3, 5, 9] {
                let values: Vec<f32> =
                    (0..n).map(|i| if i % every == 1 { f32::NAN } else { i as f32 }).collect();
                let expected: Vec<usize> = (0..n).filter(|i| i % every == 1).collect();
                let mut found = Vec::new();
                let mut from = 0;
                while let Some(i) = next_marked(&values, from) {
                    found.push(i);
                    from = i + 1;
                }
                assert_eq!(found, expected, "n = {n}, every {every}");
                for from in 0..=n + 3 {
                    let first = expected.iter().copied().find(|&i| i >= from);
                    assert_eq!(next_marked(&values, from), first, "n = {n}, every {every}, from {from}");
                }
            }
        }
    }
}
