#!/usr/bin/env python3
"""The largest difference between two stocks' heights (stencil-sim --stock-csv files of one grid),
mm, on stdout; exit 1 when the grids differ in size (named)."""
import sys


def heights(path):
    with open(path) as rows:
        return [[float(v) for v in row.split(",")] for row in rows if row.strip()]


a, b = heights(sys.argv[1]), heights(sys.argv[2])
if len(a) != len(b) or any(len(x) != len(y) for x, y in zip(a, b)):
    print(f"{sys.argv[1]} and {sys.argv[2]}: grids of different sizes", file=sys.stderr)
    sys.exit(1)
print(f"{max(abs(x - y) for ra, rb in zip(a, b) for x, y in zip(ra, rb)):.6f}")
