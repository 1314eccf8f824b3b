//! The linear convolution of two real 2D grids by the fast Fourier transform (radix 2), for
//! the downsampling operator's numerical convolution of slope densities.

use core::f64::consts::TAU;

/// A real grid of `nx × ny` values, row-major (x fastest).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Grid2 {
    pub(crate) nx: usize,
    pub(crate) ny: usize,
    pub(crate) values: Vec<f64>,
}

/// The twiddle factors e^{−2πi j/n}, j < n/2, of a transform of length n (a power of two).
fn twiddles(n: usize) -> Vec<(f64, f64)> {
    (0..n / 2)
        .map(|j| {
            let angle = -TAU * j as f64 / n as f64;
            (angle.cos(), angle.sin())
        })
        .collect()
}

/// The in-place radix-2 transform of the complex sequence (`re`, `im`) of length n (a power of
/// two, ≥ 1): X_k = Σ x_j e^{∓2πi jk/n} (− forward, + inverse, unnormalized). `table` holds
/// [`twiddles`]`(n)`.
fn fft(re: &mut [f64], im: &mut [f64], table: &[(f64, f64)], inverse: bool) {
    let n = re.len();
    // bit-reversal permutation
    let mut j = 0;
    for i in 1..n {
        let mut bit = n >> 1;
        while j & bit != 0 {
            j ^= bit;
            bit >>= 1;
        }
        j |= bit;
        if i < j {
            re.swap(i, j);
            im.swap(i, j);
        }
    }
    let sign = if inverse { -1.0 } else { 1.0 };
    let mut len = 2;
    while len <= n {
        let (half, stride) = (len / 2, n / len);
        for start in (0..n).step_by(len) {
            for k in 0..half {
                let (c, s) = table[k * stride];
                let s = sign * s;
                let (a, b) = (start + k, start + k + half);
                let (xr, xi) = (re[b] * c - im[b] * s, re[b] * s + im[b] * c);
                re[b] = re[a] - xr;
                im[b] = im[a] - xi;
                re[a] += xr;
                im[a] += xi;
            }
        }
        len <<= 1;
    }
}

/// The 2D transform of an `lx × ly` complex array (row-major), rows then columns.
fn fft2(re: &mut [f64], im: &mut [f64], lx: usize, ly: usize, inverse: bool) {
    let (tx, ty) = (twiddles(lx), twiddles(ly));
    for row in 0..ly {
        let r = row * lx..(row + 1) * lx;
        fft(&mut re[r.clone()], &mut im[r], &tx, inverse);
    }
    let (mut cr, mut ci) = (vec![0.0; ly], vec![0.0; ly]);
    for col in 0..lx {
        for row in 0..ly {
            cr[row] = re[row * lx + col];
            ci[row] = im[row * lx + col];
        }
        fft(&mut cr, &mut ci, &ty, inverse);
        for row in 0..ly {
            re[row * lx + col] = cr[row];
            im[row * lx + col] = ci[row];
        }
    }
}

/// The linear convolution c = a ∗ b, c[i + k] = Σ a[i] b[k], of two real grids: a grid of
/// (a.nx + b.nx − 1) × (a.ny + b.ny − 1) values. Both inputs go into one complex transform
/// (a the real part, b the imaginary part, separated by the Hermitian symmetry of real
/// transforms), multiplied and transformed back: two 2D transforms of the power-of-two size
/// that holds c. The rounding error is about 1e-16 × log₂(size) of the largest |c| (not of each
/// value: tiny values far from the peak carry that absolute noise).
pub(crate) fn convolve(a: &Grid2, b: &Grid2) -> Grid2 {
    let (nx, ny) = (a.nx + b.nx - 1, a.ny + b.ny - 1);
    let (lx, ly) = (nx.next_power_of_two(), ny.next_power_of_two());
    let (mut re, mut im) = (vec![0.0; lx * ly], vec![0.0; lx * ly]);
    for y in 0..a.ny {
        re[y * lx..y * lx + a.nx].copy_from_slice(&a.values[y * a.nx..(y + 1) * a.nx]);
    }
    for y in 0..b.ny {
        im[y * lx..y * lx + b.nx].copy_from_slice(&b.values[y * b.nx..(y + 1) * b.nx]);
    }
    fft2(&mut re, &mut im, lx, ly, false);
    // Z = A + iB with A, B the transforms of the real a, b: A_k = (Z_k + conj Z_−k)/2,
    // B_k = (Z_k − conj Z_−k)/(2i); the product A_k B_k for every k
    let (mut pr, mut pi) = (vec![0.0; lx * ly], vec![0.0; lx * ly]);
    for y in 0..ly {
        let my = (ly - y) % ly;
        for x in 0..lx {
            let mx = (lx - x) % lx;
            let (zr, zi) = (re[y * lx + x], im[y * lx + x]);
            let (wr, wi) = (re[my * lx + mx], -im[my * lx + mx]);
            let (ar, ai) = (0.5 * (zr + wr), 0.5 * (zi + wi));
            let (dr, di) = (zr - wr, zi - wi);
            let (br, bi) = (0.5 * di, -0.5 * dr);
            pr[y * lx + x] = ar * br - ai * bi;
            pi[y * lx + x] = ar * bi + ai * br;
        }
    }
    fft2(&mut pr, &mut pi, lx, ly, true);
    let scale = 1.0 / (lx * ly) as f64;
    let mut values = Vec::with_capacity(nx * ny);
    for y in 0..ny {
        values.extend(pr[y * lx..y * lx + nx].iter().map(|v| v * scale));
    }
    Grid2 { nx, ny, values }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The transform's convolution equals the direct sum to 1e-14 of the largest value, for
    /// grids of odd, even and unit sizes.
    #[test]
    fn convolution_matches_the_direct_sum() {
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        for ((anx, any), (bnx, bny)) in
            [((5, 3), (4, 7)), ((1, 1), (6, 2)), ((8, 8), (1, 9)), ((13, 2), (3, 3))]
        {
            let a = Grid2 { nx: anx, ny: any, values: (0..anx * any).map(|_| next() - 0.3).collect() };
            let b = Grid2 { nx: bnx, ny: bny, values: (0..bnx * bny).map(|_| next()).collect() };
            let c = convolve(&a, &b);
            assert_eq!((c.nx, c.ny), (anx + bnx - 1, any + bny - 1));
            let mut direct = vec![0.0; c.nx * c.ny];
            for (ia, va) in a.values.iter().enumerate() {
                for (ib, vb) in b.values.iter().enumerate() {
                    let (x, y) = (ia % anx + ib % bnx, ia / anx + ib / bnx);
                    direct[y * c.nx + x] += va * vb;
                }
            }
            let scale = direct.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            for (got, want) in c.values.iter().zip(&direct) {
                assert!((got - want).abs() <= 1e-14 * scale, "{got} vs {want}");
            }
        }
    }
}
