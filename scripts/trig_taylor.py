#!/usr/bin/env python3
"""Regenerates `SIN` and `COS` of src/special/trig.rs: the Taylor coefficients of sin(πf/2)
(odd powers f, f³, …, f⁹) and of cos(πf/2) (even powers f⁰, …, f¹⁰), (−1)ᵏ (π/2)ⁿ / n! with
n = 2k + 1 and n = 2k, each rounded once to the nearest f32 and printed as the shortest
decimal that rounds back to it (Rust's `{:e}` of an f32). The truncation errors of the
polynomials on |f| ≤ ½ (the doc comments' bounds) are printed as comments.

The committed literals are the correctly rounded coefficients for 6 of the 9 non-trivial
entries; SIN[2], COS[1] and COS[4] are one f32 step away (relative 9.3e-8, 9.7e-8, 6.3e-8:
literals rounded to 7–8 decimal digits), well inside sin_cos_turns' stated 1.2e-7 absolute
error. `--compare FILE` lists every entry's difference in f32 steps.

Usage (mpmath 1.3):
  python3 scripts/trig_taylor.py                 prints the Rust items
  python3 scripts/trig_taylor.py --compare FILE  compares with the tables in FILE (the .rs file)
"""
import math
import re
import struct
import sys

import mpmath as mp

mp.mp.dps = 40


def f32(x):
    return struct.unpack("f", struct.pack("f", float(x)))[0]


def shortest(x):
    for digits in range(1, 10):
        text = f"{x:.{digits - 1}e}"
        if f32(float(text)) == x:
            mantissa, exponent = text.split("e")
            return f"{mantissa}e{int(exponent)}"
    raise ValueError(x)


def coefficient(n):
    return f32((-1) ** (n // 2) * (mp.pi / 2) ** n / mp.factorial(n))


SIN = [coefficient(2 * k + 1) for k in range(5)]
COS = [coefficient(2 * k) for k in range(6)]


def truncation(first_omitted):
    return float((mp.pi / 2) ** first_omitted / mp.factorial(first_omitted) * mp.mpf(0.5) ** first_omitted)


def steps(a, b):
    """Signed distance from b to a in f32 steps (same sign, finite)."""
    bits = lambda v: struct.unpack("i", struct.pack("f", v))[0]
    return bits(a) - bits(b)


def committed(path, name):
    source = open(path, encoding="utf-8").read()
    block = source[source.index(f"const {name}: [f32;") :]
    block = block[: block.index("];")].split("=", 1)[1]
    block = block.replace("core::f32::consts::FRAC_PI_2", repr(f32(math.pi / 2))).replace("_", "")
    return [f32(float(x)) for x in re.findall(r"-?\d+\.\d+(?:e-?\d+)?", block)]


def main():
    if len(sys.argv) == 3 and sys.argv[1] == "--compare":
        for name, ours in (("SIN", SIN), ("COS", COS)):
            theirs = committed(sys.argv[2], name)
            for k, (a, b) in enumerate(zip(ours, theirs)):
                print(f"{name}[{k}]: regenerated {shortest(a)}, committed {shortest(b)}, "
                      f"{steps(b, a):+d} f32 steps, relative {abs(b - a) / abs(a):.2e}")
        return
    print(f"// truncation error on |f| ≤ ½: sin {truncation(11):.1e}, cos {truncation(12):.1e}")
    print("const SIN: [f32; 5] = [core::f32::consts::FRAC_PI_2, " + ", ".join(shortest(c) for c in SIN[1:]) + "];")
    print("const COS: [f32; 6] = [" + ", ".join(shortest(c) for c in COS) + "];")


if __name__ == "__main__":
    main()
