#!/usr/bin/env python3
"""Regenerates `CENTRAL`, `TAIL` and `FAR_TAIL` of src/special/erfinv.rs: the single-precision
Gaussian quantile erfc⁻¹(2t) = erfinv(y), y = 1 − 2t, written (after Giles 2010, “Approximating
the erfinv function”) as y · P(x) with w = −ln(1 − y²) and

  CENTRAL   degree 9, x = w − 3.125,  w ∈ [0, 6.25]
  TAIL      degree 8, x = √w − 3.75,  w ∈ [6.25, 25]
  FAR_TAIL  degree 8, x = √w − 6.6,   w ∈ [25, 72]   (t down to about 1e-30)

Each P is the least-squares fit of erfinv(y)/y in the relative sense (residuals divided by the
function) on 1000 equally spaced w of its range, computed with 30 significant digits and
printed with 10 significant digits, as in the source.

The committed tables came from an unrecorded least-squares fit of the same form; they are not
reproduced digit for digit (its grid and weights are unknown). `--compare` prints, for the
committed and the regenerated coefficients, the largest relative error of P against 30-digit
erfinv(y)/y on 4000 points per range, with P evaluated by Horner's rule in f32 arithmetic (as
`erfc_inv_f32` does), and the largest relative difference between the coefficient sets.

Usage (mpmath 1.3; about a minute):
  python3 scripts/erfinv_fits.py                 prints the three Rust items
  python3 scripts/erfinv_fits.py --compare FILE  compares with the tables in FILE (the .rs file)
"""
import re
import struct
import sys

import mpmath as mp

mp.mp.dps = 30
FIT_POINTS = 1000
CHECK_POINTS = 4000
# (name, degree, variable, centre, w range, doc line)
RANGES = [
    ("CENTRAL", 9, "w", "3.125", (0.0, 6.25), "/// erfinv(y)/y as a polynomial in w − 3.125, for w = −ln(1 − y²) ∈ [0, 6.25]."),
    ("TAIL", 8, "sqrt", "3.75", (6.25, 25.0), "/// erfinv(y)/y as a polynomial in √w − 3.75, for w ∈ [6.25, 25]."),
    ("FAR_TAIL", 8, "sqrt", "6.6", (25.0, 72.0), "/// erfinv(y)/y as a polynomial in √w − 6.6, for w ∈ [25, 72]."),
]


def ratio(w):
    """erfinv(y)/y for w = −ln(1 − y²) > 0; its limit √π/2 at w = 0."""
    if w == 0:
        return mp.sqrt(mp.pi) / 2
    # 1 − y reaches 1e-32 at w = 72: 30 digits beyond it
    with mp.workdps(mp.mp.dps + 35):
        y = mp.sqrt(-mp.expm1(-w))
        return +(mp.erfinv(y) / y)


def variable(w, kind, centre):
    return (w if kind == "w" else mp.sqrt(w)) - mp.mpf(centre)


def fit(degree, kind, centre, lo, hi):
    rows, rhs = [], []
    for i in range(FIT_POINTS):
        w = mp.mpf(lo) + (mp.mpf(hi) - lo) * i / (FIT_POINTS - 1)
        x, r = variable(w, kind, centre), ratio(w)
        rows.append([x**j / r for j in range(degree + 1)])
        rhs.append(mp.mpf(1))
    return [float(c) for c in mp.qr_solve(mp.matrix(rows), mp.matrix(rhs))[0]]


def f32(x):
    return struct.unpack("f", struct.pack("f", x))[0]


def worst_error_f32(coefficients, kind, centre, lo, hi):
    cs = [f32(c) for c in coefficients]
    worst = 0.0
    for i in range(CHECK_POINTS):
        w = lo + (hi - lo) * (i + 0.5) / CHECK_POINTS
        w32 = f32(w)
        x = f32(f32(w32 if kind == "w" else f32(w32**0.5)) - f32(float(centre)))
        acc = 0.0
        for c in reversed(cs):
            acc = f32(c + f32(acc * x))
        exact = ratio(mp.mpf(w32))
        worst = max(worst, float(abs(acc / exact - 1)))
    return worst


def committed(path, name):
    source = open(path, encoding="utf-8").read()
    block = source[source.index(f"const {name}: [f32;") :]
    block = block[: block.index("];")].split("=", 1)[1]
    return [float(x) for x in re.findall(r"-?\d+\.\d+e[+-]\d+", block)]


def main():
    compare = len(sys.argv) == 3 and sys.argv[1] == "--compare"
    for name, degree, kind, centre, (lo, hi), doc in RANGES:
        ours = fit(degree, kind, centre, lo, hi)
        if compare:
            theirs = committed(sys.argv[2], name)
            diff = max(abs(a - b) / abs(b) for a, b in zip(ours, theirs))
            print(f"{name}: committed fit error {worst_error_f32(theirs, kind, centre, lo, hi):.2e}, "
                  f"regenerated {worst_error_f32(ours, kind, centre, lo, hi):.2e} (relative, f32 Horner); "
                  f"largest relative coefficient difference {diff:.2e}")
            continue
        print(doc)
        print(f"const {name}: [f32; {degree + 1}] = [")
        for c in ours:
            print(f"    {c:.9e},")
        print("];")


if __name__ == "__main__":
    main()
