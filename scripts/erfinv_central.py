#!/usr/bin/env python3
"""Regenerates `NO_LOG` of src/special/erfinv.rs: erfinv(y)/y as a polynomial of degree 9 in
v = y² for v ∈ [0, 0.64] (|y| ≤ 0.8, tail probabilities t = (1 − y)/2 ≥ 0.1: 80 % of the
uniforms), which lets `erfc_inv_f32` skip its logarithm there.

The polynomial is the least-squares fit of erfinv(y)/y in the relative sense (residuals divided
by the function) on 400 Chebyshev-distributed v in [0, 0.64], solved with 30 significant digits;
each coefficient is rounded once to f32 and printed with 10 significant digits.
`--error` prints the largest relative error of y·P(y²) against 30-digit erfinv(y) on 3001
equally spaced y ∈ [0, 0.8], with P evaluated by Horner's rule in f32 arithmetic (as
`erfc_inv_f32` does).

Usage (mpmath 1.3; a few seconds):
  python3 scripts/erfinv_central.py                 prints the Rust item
  python3 scripts/erfinv_central.py --error         the f32 evaluation's largest relative error
  python3 scripts/erfinv_central.py --compare FILE  compares with the table in FILE (the .rs file)
"""
import re
import struct
import sys

import mpmath as mp

mp.mp.dps = 30
V_MAX = 0.64
DEGREE = 9
FIT_POINTS = 400
CHECK_POINTS = 3000


def f32(x):
    return struct.unpack("f", struct.pack("f", float(x)))[0]


def ratio(v):
    """erfinv(y)/y for v = y²; its limit √π/2 at v = 0."""
    if v == 0:
        return mp.sqrt(mp.pi) / 2
    y = mp.sqrt(v)
    return mp.erfinv(y) / y


def fit():
    rows, rhs = [], []
    for i in range(FIT_POINTS):
        v = mp.mpf(V_MAX) * (1 - mp.cos(mp.pi * (i + mp.mpf(0.5)) / FIT_POINTS)) / 2
        r = ratio(v)
        rows.append([v**j / r for j in range(DEGREE + 1)])
        rhs.append(1)
    solution = mp.qr_solve(mp.matrix(rows), mp.matrix(rhs))[0]
    return [f32(float(f"{f32(solution[j]):.9e}")) for j in range(DEGREE + 1)]


def error(coefficients):
    worst = 0.0
    for i in range(CHECK_POINTS + 1):
        y = f32(mp.sqrt(V_MAX) * i / CHECK_POINTS)
        v = f32(y * y)
        acc = 0.0
        for c in reversed(coefficients):
            acc = f32(f32(acc * v) + c)
        got, exact = (f32(y * acc), mp.erfinv(y)) if y > 0 else (acc, mp.sqrt(mp.pi) / 2)
        worst = max(worst, float(abs(got / exact - 1)))
    return worst


def committed(path):
    source = open(path, encoding="utf-8").read()
    block = source[source.index(f"const NO_LOG: [f32; {DEGREE + 1}] = [") :]
    block = block[: block.index("\n];")].split("=", 1)[1]
    return [f32(float(x)) for x in re.findall(r"-?\d+\.\d+e[+-]\d+", block)]


def main():
    if len(sys.argv) == 3 and sys.argv[1] == "--compare":
        ours, theirs = fit(), committed(sys.argv[2])
        same = sum(a == b for a, b in zip(ours, theirs))
        print(f"{same} of {len(ours)} coefficients identical; relative error in f32 evaluation, "
              f"committed {error(theirs):.3e}, regenerated {error(ours):.3e}")
        return
    if len(sys.argv) == 2 and sys.argv[1] == "--error":
        print(f"largest relative error in f32 evaluation: {error(fit()):.3e}")
        return
    print(f"const NO_LOG: [f32; {DEGREE + 1}] = [")
    for c in fit():
        print(f"    {c:.9e},")
    print("];")


if __name__ == "__main__":
    main()
