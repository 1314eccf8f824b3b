#!/usr/bin/env python3
"""Regenerates `PIECES` of src/special/gaussian.rs: the Gaussian integral
A(x) = ∫₋∞ˣ e^{−t²} dt = (√π/2) erfc(−x) and half the Gaussian B(x) = e^{−x²}/2 on
x ∈ [X_FROM, X_FROM + PIECE_COUNT·WIDTH] = [−4.5, 6], as PIECE_COUNT polynomials of degree
DEGREE per function (the two functions of the Beckmann visible-slope CDF above the horizon,
S(x) = κ A(x) + B(x), S′(x) = 2(κ − x) B(x)).

Piece k covers [X_FROM + k·WIDTH, X_FROM + (k + 1)·WIDTH]; its centre c_k = X_FROM + (k + ½)·WIDTH
is exact in f64 (WIDTH is a power of two). Each polynomial, in s = x − c_k with coefficients
lowest degree first, interpolates its function at the DEGREE + 1 Chebyshev nodes (first kind)
of the piece, c_k + (WIDTH/2) cos((2j + 1)π/(2(DEGREE + 1))), solved with 40 significant digits;
each coefficient is rounded once to the nearest f64 and printed as the shortest decimal that
round-trips (as Rust prints an f64). A row holds A's coefficients, then B's.

Usage (mpmath 1.3):
  python3 scripts/gaussian_pieces.py                 prints the Rust item, laid out as rustfmt does
  python3 scripts/gaussian_pieces.py --error         the largest absolute error of the f64 Horner
                                                     evaluation over a fine grid, per function
  python3 scripts/gaussian_pieces.py --compare FILE  compares with the table in FILE (the .rs file)
"""
import re
import sys

import mpmath as mp

mp.mp.dps = 40
X_FROM = -4.5
WIDTH = 0.25
PIECE_COUNT = 42
DEGREE = 7


def integral(x):
    return mp.sqrt(mp.pi) / 2 * mp.erfc(-x)


def half_gaussian(x):
    return mp.exp(-x * x) / 2


def interpolant(f, centre):
    n = DEGREE + 1
    half = mp.mpf(WIDTH) / 2
    nodes = [half * mp.cos((2 * j + 1) * mp.pi / (2 * n)) for j in range(n)]
    vandermonde = mp.matrix([[s**i for i in range(n)] for s in nodes])
    values = mp.matrix([f(centre + s) for s in nodes])
    return [float(c) for c in mp.lu_solve(vandermonde, values)]


def table():
    rows = []
    for k in range(PIECE_COUNT):
        centre = mp.mpf(X_FROM + (k + 0.5) * WIDTH)
        rows.append(interpolant(integral, centre) + interpolant(half_gaussian, centre))
    return rows


def horner(coefficients, s):
    value = 0.0
    for c in reversed(coefficients):
        value = value * s + c
    return value


def errors(rows, samples_per_piece=200):
    worst = [0.0, 0.0]
    for k, row in enumerate(rows):
        centre = X_FROM + (k + 0.5) * WIDTH
        for i in range(samples_per_piece + 1):
            x = X_FROM + k * WIDTH + WIDTH * i / samples_per_piece
            s = x - centre
            for f, (j, coefficients) in zip((integral, half_gaussian), enumerate((row[:8], row[8:]))):
                err = abs(horner(coefficients, s) - f(mp.mpf(x)))
                worst[j] = max(worst[j], float(err))
    return worst


def committed(path):
    source = open(path, encoding="utf-8").read()
    block = source[source.index(f"const PIECES: [[f64; {2 * (DEGREE + 1)}]; {PIECE_COUNT}] = [") :]
    block = block[: block.index("\n];")].split("=", 1)[1]
    values = [float(x) for x in re.findall(r"-?\d+\.\d+(?:e-?\d+)?", block)]
    n = 2 * (DEGREE + 1)
    return [values[n * k : n * k + n] for k in range(PIECE_COUNT)]


def main():
    if len(sys.argv) == 3 and sys.argv[1] == "--compare":
        ours, theirs = table(), committed(sys.argv[2])
        pairs = [(a, b) for row_a, row_b in zip(ours, theirs) for a, b in zip(row_a, row_b)]
        differing = [(a, b) for a, b in pairs if a != b]
        worst = max((abs(a - b) / abs(b) for a, b in differing), default=0.0)
        print(f"{len(pairs) - len(differing)} of {len(pairs)} coefficients identical; "
              f"largest relative difference {worst:.2e}")
        return
    if len(sys.argv) == 2 and sys.argv[1] == "--error":
        a, b = errors(table())
        print(f"largest absolute error: A {a:.3e}, B {b:.3e}")
        return
    print(f"const PIECES: [[f64; {2 * (DEGREE + 1)}]; {PIECE_COUNT}] = [")
    for row in table():
        print("    [")
        for c in row:
            print(f"        {c!r},")
        print("    ],")
    print("];")


if __name__ == "__main__":
    main()
