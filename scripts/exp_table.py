#!/usr/bin/env python3
"""Regenerates the constants of src/special/exp.rs (`exp_nonpositive`, e^x by 2^{k/32}·e^r):

- `TWO_TO_J_32`: 2^{j/32} for j = 0 … 31, each correctly rounded to f64;
- `LN2_32_HI` + `LN2_32_LO` = ln 2/32 (Cody and Waite's split): HI is ln 2/32 rounded to 38
  significant bits, so that k·HI is exact in f64 for |k| < 2¹⁵ (x ≥ −708 gives
  |k| ≤ 32 690), and LO is the rest, rounded to f64;
- `INV_LN2_32` = 32/ln 2 rounded to f64 (it only selects k: any rounding of it is exact in r).

Values from 50-digit mpmath, printed as the shortest decimal that round-trips.

Usage (mpmath 1.3):
  python3 scripts/exp_table.py                 prints the Rust items
  python3 scripts/exp_table.py --compare FILE  compares with the items in FILE (the .rs file)
"""
import re
import sys

import mpmath as mp

mp.mp.dps = 50
HI_BITS = 38


def items():
    ln2_32 = mp.log(2) / 32
    exponent = mp.floor(mp.log(ln2_32, 2))
    quantum = mp.mpf(2) ** (exponent - HI_BITS + 1)
    hi = mp.nint(ln2_32 / quantum) * quantum
    return {
        "INV_LN2_32": [float(32 / mp.log(2))],
        "LN2_32_HI": [float(hi)],
        "LN2_32_LO": [float(ln2_32 - hi)],
        "TWO_TO_J_32": [float(mp.mpf(2) ** (mp.mpf(j) / 32)) for j in range(32)],
    }


def committed(path):
    source = open(path, encoding="utf-8").read()
    number = r"-?\d+\.\d+(?:e-?\d+)?"
    found = {}
    for name in items():
        start = source.index(f"const {name}: ")
        end = source.index(";\n", start)
        found[name] = [float(x) for x in re.findall(number, source[start:end].split("=", 1)[1])]
    return found


def main():
    if len(sys.argv) == 3 and sys.argv[1] == "--compare":
        ours, theirs = items(), committed(sys.argv[2])
        same = all(ours[k] == theirs[k] for k in ours)
        print("identical" if same else f"differ: ours {ours}, committed {theirs}")
        return
    for name, values in items().items():
        if name == "TWO_TO_J_32":
            print(f"const {name}: [f64; 32] = [")
            for v in values:
                print(f"    {v!r},")
            print("];")
        else:
            print(f"const {name}: f64 = {values[0]!r};")


if __name__ == "__main__":
    main()
