#!/usr/bin/env python3
"""Regenerates `PIECES` of src/special/erfcx.rs: erfcx(u) = exp(u²) erfc(u) on u ∈ [0, 25] as
32 polynomials of degree 7 in y = 4/(4 + u) (the variable of S. G. Johnson's Faddeeva package).

Piece k covers y ∈ [Y_FROM + k h, Y_FROM + (k + 1) h], Y_FROM = 4/29, h = (1 − Y_FROM)/32, with
Y_FROM, h and the centre c_k = Y_FROM + (k + ½) h evaluated in f64 exactly as erfcx64 does (it
forms s = y − c_k in f64). Its polynomial, in s with coefficients lowest degree first,
interpolates erfcx(4/y − 4) at the 8 Chebyshev nodes (first kind) of the piece,
c_k + (h/2) cos((2j + 1)π/16), j = 0..7, solved with 40 significant digits; each coefficient
is rounded once to the nearest f64 and printed as the shortest decimal that round-trips (as
Rust prints an f64).

Usage (mpmath 1.3):
  python3 scripts/erfcx_pieces.py                 prints the Rust item, laid out as rustfmt does
  python3 scripts/erfcx_pieces.py --compare FILE  compares with the table in FILE (the .rs file)
"""
import re
import sys

import mpmath as mp

mp.mp.dps = 40
PIECE_COUNT = 32
DEGREE = 7


def erfcx_of_y(y):
    u = 4 / y - 4
    return mp.erfc(u) * mp.exp(u * u)


def piece(k):
    y_from = 4.0 / 29.0
    width = (1.0 - y_from) / PIECE_COUNT
    centre = mp.mpf(y_from + (k + 0.5) * width)
    half = mp.mpf(width) / 2
    n = DEGREE + 1
    nodes = [half * mp.cos((2 * j + 1) * mp.pi / (2 * n)) for j in range(n)]
    vandermonde = mp.matrix([[s**i for i in range(n)] for s in nodes])
    values = mp.matrix([erfcx_of_y(centre + s) for s in nodes])
    return [float(c) for c in mp.lu_solve(vandermonde, values)]


def table():
    return [piece(k) for k in range(PIECE_COUNT)]


def committed(path):
    source = open(path, encoding="utf-8").read()
    block = source[source.index("const PIECES: [[f64; 8]; 32] = [") :]
    block = block[: block.index("\n];")].split("=", 1)[1]
    values = [float(x) for x in re.findall(r"-?\d+\.\d+(?:e-?\d+)?", block)]
    return [values[8 * k : 8 * k + 8] for k in range(PIECE_COUNT)]


def main():
    if len(sys.argv) == 3 and sys.argv[1] == "--compare":
        ours, theirs = table(), committed(sys.argv[2])
        pairs = [(a, b) for row_a, row_b in zip(ours, theirs) for a, b in zip(row_a, row_b)]
        differing = [(a, b) for a, b in pairs if a != b]
        worst = max((abs(a - b) / abs(b) for a, b in differing), default=0.0)
        print(f"{len(pairs) - len(differing)} of {len(pairs)} coefficients identical; "
              f"largest relative difference {worst:.2e}")
        return
    print("const PIECES: [[f64; 8]; 32] = [")
    for row in table():
        print("    [")
        for c in row:
            print(f"        {c!r},")
        print("    ],")
    print("];")


if __name__ == "__main__":
    main()
