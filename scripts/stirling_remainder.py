"""STIRLING in src/special/stirling.rs: the remainder of Stirling's series,
x mu(x) = x (ln Gamma(x) - (x - 1/2) ln x + x - ln(2 pi)/2), as a degree-7 polynomial
in t = 1/x on [0, 1] (x >= 1), the Chebyshev interpolant of mpmath, highest degree first.

--error prints the largest absolute error of mu(x) = t P(t) over x in [1, 1e6] with the
coefficients rounded to f32 (f64 Horner evaluation)."""
import sys
from mpmath import mp, mpf, loggamma, log, pi, chebyfit

mp.dps = 40


def mu(x):
    return loggamma(x) - ((x - mpf(1) / 2) * log(x) - x + log(2 * pi) / 2)


def g(t):
    if t == 0:
        return mpf(1) / 12
    return mu(1 / t) / t


def fit():
    coeffs = chebyfit(g, [0, 1], 8)
    return [float(c) for c in coeffs]


def item(coeffs):
    import struct

    f32 = [struct.unpack("f", struct.pack("f", c))[0] for c in coeffs]
    lines = ["const STIRLING: [f32; 8] = ["]
    lines += [f"    {repr(c)}," for c in f32]
    lines.append("];")
    return "\n".join(lines), f32


if __name__ == "__main__":
    text, f32 = item(fit())
    if "--error" in sys.argv:
        worst = 0.0
        for k in range(20001):
            x = mpf(10) ** (6 * mpf(k) / 20000)
            t = float(1 / x)
            p = 0.0
            for c in f32:
                p = p * t + c
            worst = max(worst, abs(float(t * p - mu(x))))
        print(f"largest absolute error of mu: {worst:.3e}")
    elif "--compare" in sys.argv:
        src = open(sys.argv[sys.argv.index("--compare") + 1]).read()
        start = src.index("const STIRLING:")
        committed = src[src.index("[", src.index("=", start)) + 1 : src.index("];", start)]
        import struct

        values = [
            struct.unpack("f", struct.pack("f", float(v.replace("_", ""))))[0]
            for v in committed.split(",")
            if v.strip()
        ]
        print("bit for bit" if values == f32 else "differs:\n" + text)
    else:
        print(text)
