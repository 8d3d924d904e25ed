#!/usr/bin/env python3
"""The largest difference between two stocks' heights (stencil-sim --stock-csv files of one grid),
mm, on stdout; exit 1 when a file cannot be read or the grids differ in size (named).
stock_surface_distance.py reads its stocks with grids() from here."""
import sys


def heights(path):
    try:
        with open(path) as rows:
            return [[float(v) for v in row.split(",")] for row in rows if row.strip()]
    except (OSError, ValueError) as error:
        print(f"{path}: {error}", file=sys.stderr)
        sys.exit(1)


def grids(a_path, b_path):
    """Both files' heights, rows of columns; exits naming them when the grids differ in size."""
    a, b = heights(a_path), heights(b_path)
    if not a or len(a) != len(b) or any(len(x) != len(y) for x, y in zip(a, b)):
        print(f"{a_path} and {b_path}: grids of different sizes", file=sys.stderr)
        sys.exit(1)
    return a, b


if __name__ == "__main__":
    a, b = grids(sys.argv[1], sys.argv[2])
    print(f"{max(abs(x - y) for ra, rb in zip(a, b) for x, y in zip(ra, rb)):.6f}")
