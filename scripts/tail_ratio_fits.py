#!/usr/bin/env python3
"""Regenerates `PIECES` and `FAR` of src/special/tail_ratio.rs: the ratio of the Gaussian tail's
two terms r(v) = 1 − √π v erfcx(v) (r(0) = 1, r(v) ≈ 1/(2v²) for large v), the factor that
Beckmann's Λ and the visible-slope CDF below the horizon have besides a Gaussian:
Λ(a) = e^{−a²} r(a)/(2√π a), and S(x̃)/e^{−x̃²} = (t + m r(v))/(2v) for v = −x̃, t = v − m.

- `PIECES`: on v ∈ [0, V_SPLIT) = [0, 8), PIECE_COUNT = 32 polynomials of degree 7 in
  s = v − c_k, c_k = (k + ½)·WIDTH, WIDTH = ¼, each interpolating r at the 8 Chebyshev nodes
  (first kind) of its piece, c_k + (WIDTH/2) cos((2j + 1)π/16).
- `FAR`: from V_SPLIT on, r(v) = (w/2) P(w) with w = 1/v² ∈ (0, 1/64]; P (P(0) = 1, the
  asymptotic series 1 − 3w/2 + 15w²/4 − …) as the polynomial of degree 7 in w interpolating it
  at the 8 Chebyshev nodes of [0, 1/64].

Values with 40 significant digits (erfcx from mpmath's erfc and exp at that precision), each
coefficient rounded once to the nearest f64 and printed as the shortest decimal that round-trips
(as Rust prints an f64), lowest degree first.

Usage (mpmath 1.3; about ten seconds):
  python3 scripts/tail_ratio_fits.py                 prints the Rust items, laid out as rustfmt does
  python3 scripts/tail_ratio_fits.py --error         the largest relative error of the f64 Horner
                                                     evaluation, on a fine grid of each part
  python3 scripts/tail_ratio_fits.py --compare FILE  compares with the tables in FILE (the .rs file)
"""
import re
import sys

import mpmath as mp

mp.mp.dps = 40
V_SPLIT = 8
WIDTH = mp.mpf(1) / 4
PIECE_COUNT = 32
DEGREE = 7
W_MAX = mp.mpf(1) / V_SPLIT**2


def ratio(v):
    v = mp.mpf(v)
    return 1 - mp.sqrt(mp.pi) * v * mp.exp(v * v) * mp.erfc(v)


def far(w):
    """P(w) = 2 r(v)/w at v = 1/√w; P(0) = 1."""
    if w == 0:
        return mp.mpf(1)
    return 2 * ratio(1 / mp.sqrt(w)) / w


def interpolant(f, centre, half):
    n = DEGREE + 1
    nodes = [half * mp.cos((2 * j + 1) * mp.pi / (2 * n)) for j in range(n)]
    vandermonde = mp.matrix([[s**i for i in range(n)] for s in nodes])
    values = mp.matrix([f(centre + s) for s in nodes])
    return [float(c) for c in mp.lu_solve(vandermonde, values)]


def pieces():
    return [interpolant(ratio, (k + mp.mpf(1) / 2) * WIDTH, WIDTH / 2) for k in range(PIECE_COUNT)]


def far_polynomial():
    # in w itself (centre 0): interpolate P(w) at the nodes of [0, W_MAX]
    n = DEGREE + 1
    nodes = [W_MAX / 2 + W_MAX / 2 * mp.cos((2 * j + 1) * mp.pi / (2 * n)) for j in range(n)]
    vandermonde = mp.matrix([[w**i for i in range(n)] for w in nodes])
    values = mp.matrix([far(w) for w in nodes])
    return [float(c) for c in mp.lu_solve(vandermonde, values)]


def horner(coefficients, s):
    value = 0.0
    for c in reversed(coefficients):
        value = value * s + c
    return value


def errors(rows, tail, samples_per_piece=100):
    worst_pieces = 0.0
    for k, row in enumerate(rows):
        centre = (k + 0.5) * float(WIDTH)
        for i in range(samples_per_piece + 1):
            v = k * float(WIDTH) + float(WIDTH) * i / samples_per_piece
            err = abs(horner(row, v - centre) / ratio(v) - 1)
            worst_pieces = max(worst_pieces, float(err))
    worst_far = 0.0
    for i in range(1, 2001):
        # v from 8 to 8000, geometrically
        v = V_SPLIT * 10 ** (3 * (i - 1) / 1999)
        w = 1.0 / (v * v)
        err = abs(0.5 * w * horner(tail, w) / ratio(v) - 1)
        worst_far = max(worst_far, float(err))
    return worst_pieces, worst_far


def committed(path):
    source = open(path, encoding="utf-8").read()
    number = r"-?\d+\.\d+(?:e-?\d+)?"
    block = source[source.index(f"const PIECES: [[f64; {DEGREE + 1}]; {PIECE_COUNT}] = [") :]
    block = block[: block.index("\n];")].split("=", 1)[1]
    values = [float(x) for x in re.findall(number, block)]
    n = DEGREE + 1
    rows = [values[n * k : n * k + n] for k in range(PIECE_COUNT)]
    block = source[source.index(f"const FAR: [f64; {DEGREE + 1}] = [") :]
    block = block[: block.index("];")].split("=", 1)[1]
    return rows, [float(x) for x in re.findall(number, block)]


def main():
    if len(sys.argv) == 3 and sys.argv[1] == "--compare":
        ours = [c for row in pieces() for c in row] + far_polynomial()
        rows, tail = committed(sys.argv[2])
        theirs = [c for row in rows for c in row] + tail
        differing = [(a, b) for a, b in zip(ours, theirs) if a != b]
        worst = max((abs(a - b) / abs(b) for a, b in differing), default=0.0)
        print(f"{len(ours) - len(differing)} of {len(ours)} coefficients identical "
              f"({len(theirs)} committed); largest relative difference {worst:.2e}")
        return
    if len(sys.argv) == 2 and sys.argv[1] == "--error":
        p, f = errors(pieces(), far_polynomial())
        print(f"largest relative error: pieces {p:.3e}, far {f:.3e}")
        return
    print(f"const PIECES: [[f64; {DEGREE + 1}]; {PIECE_COUNT}] = [")
    for row in pieces():
        print("    [")
        for c in row:
            print(f"        {c!r},")
        print("    ],")
    print("];")
    print()
    print(f"const FAR: [f64; {DEGREE + 1}] = [")
    for c in far_polynomial():
        print(f"    {c!r},")
    print("];")


if __name__ == "__main__":
    main()
