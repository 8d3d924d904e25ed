#!/usr/bin/env python3
"""How far apart two cuts of one stock are, in 3-D: for every Z-map cell where the two stocks'
heights differ by more than --vertical mm, the distance from the lower surface's point (the cell's
centre at its lower height) to the tool envelope the other path swept (a ball-end tool: its ball and
the shank's cylinder above it). Prints the largest such distance in mm (0 when no cell differs by
more than --vertical), then the count of such cells; exit 1 on unreadable input, named.

Why not the height difference alone: on a wall the cutter's rim makes the height jump. Over a cell
whose centre sits within a micron of the ball's equator, a lateral shift of half a micron either
cuts the cell's whole column or leaves it standing, so two paths 0.0005 mm apart can leave heights
4 mm apart. The distance between the surfaces is what a part's dimension is.

usage: stock_surface_distance.py A.csv B.csv A.ngc B.ngc --stock X0,Y0,Z0,X1,Y1,Z1 --tool-radius R
  A.csv, B.csv: stencil-sim --stock-csv files of one stock (cells of at most 0.05 mm);
  A.ngc, B.ngc: the paths that cut them, as straight G0/G1 moves in the stock's (work) coordinates.
"""
import argparse
import math
import sys

from stock_difference import grids

parser = argparse.ArgumentParser()
parser.add_argument("a_csv")
parser.add_argument("b_csv")
parser.add_argument("a_ngc")
parser.add_argument("b_ngc")
parser.add_argument("--stock", required=True, help="X0,Y0,Z0,X1,Y1,Z1 (mm), as given to stencil-sim")
parser.add_argument("--tool-radius", type=float, required=True, help="the ball's radius (mm)")
parser.add_argument("--vertical", type=float, default=0.01, help="cells differing by more than this are measured (mm)")
parser.add_argument("--max-cell", type=float, default=0.05, help="the Z-map's largest cell (mm), as stencil-sim's")
args = parser.parse_args()


def fail(message):
    print(message, file=sys.stderr)
    sys.exit(1)


# Words that change what X/Y/Z mean, or moves that are not straight: this measure follows none of
# them (our exported programs and samples_to_gcode.py's use none), so a program with one is refused.
UNFOLLOWED = {"G2", "G02", "G3", "G03", "G20", "G91", "G53", "G92", "G10", "G28", "G30", "G38.2", "G43", "G55", "G56",
              "G57", "G58", "G59"}


def path_points(path):
    """The tip's positions through the program's straight moves (G0/G1, absolute mm, modal X/Y/Z)."""
    at, points = [None, None, None], []
    try:
        with open(path) as program:
            for number, line in enumerate(program, 1):
                code = line
                while "(" in code:  # a comment first: a ';' inside one is its text
                    start = code.index("(")
                    end = code.find(")", start)
                    code = code[:start] + " " + ("" if end < 0 else code[end + 1:])
                words = code.split(";")[0].upper().split()
                refused = [w for w in words if w in UNFOLLOWED]
                if refused:
                    fail(f"{path}: line {number}: {refused[0]}; this measure follows straight moves in absolute mm only")
                moved = False
                for word in words:
                    if word[:1] in "XYZ" and len(word) > 1:
                        at["XYZ".index(word[0])] = float(word[1:])
                        moved = True
                if moved and None not in at:
                    points.append(tuple(at))
    except (OSError, ValueError) as error:
        fail(f"{path}: {error}")
    if len(points) < 2:
        fail(f"{path}: fewer than two positions: no path")
    return points


try:
    stock = [float(v) for v in args.stock.split(",")]
except ValueError:
    stock = []
if len(stock) != 6:
    fail(f"--stock '{args.stock}': six numbers X0,Y0,Z0,X1,Y1,Z1 expected")
a, b = grids(args.a_csv, args.b_csv)
rows, columns = len(a), len(a[0])
width, depth = stock[3] - stock[0], stock[4] - stock[1]
if columns != max(1, math.ceil(width / args.max_cell)) or rows != max(1, math.ceil(depth / args.max_cell)):
    fail(f"{args.a_csv}: {columns} x {rows} cells is not the grid of stock {args.stock} at {args.max_cell} mm")
cell = max(width / columns, depth / rows)
radius = args.tool_radius

differing = []
for row in range(rows):
    for column in range(columns):
        ha, hb = a[row][column], b[row][column]
        if abs(ha - hb) > args.vertical:
            x, y = stock[0] + (column + 0.5) * cell, stock[1] + (row + 0.5) * cell
            # The lower surface's point, measured against the other path's envelope.
            differing.append(((x, y, min(ha, hb)), "b" if ha < hb else "a"))
paths = {"a": path_points(args.a_ngc), "b": path_points(args.b_ngc)}  # read whatever the stocks say
if not differing:
    print("0.000000 0")
    sys.exit(0)

# Segments indexed by the 1 mm squares of the plane their tool may reach, only where a measured point
# looks: its own square and the eight around it, so every segment whose tool comes within 1 mm of the
# point in the plane is seen. Farther than that is reported as such, not guessed.
BUCKET = 1.0
wanted = {(math.floor(p[0] / BUCKET) + i, math.floor(p[1] / BUCKET) + j)
          for p, _ in differing for i in (-1, 0, 1) for j in (-1, 0, 1)}


def bucketed(points):
    index = {}
    for i in range(len(points) - 1):
        p, q = points[i], points[i + 1]
        x0, x1 = min(p[0], q[0]) - radius, max(p[0], q[0]) + radius
        y0, y1 = min(p[1], q[1]) - radius, max(p[1], q[1]) + radius
        for bx in range(math.floor(x0 / BUCKET), math.floor(x1 / BUCKET) + 1):
            for by in range(math.floor(y0 / BUCKET), math.floor(y1 / BUCKET) + 1):
                if (bx, by) in wanted:
                    index.setdefault((bx, by), []).append(i)
    return index


def point_segment(p, s, e, dims):
    d = [e[k] - s[k] for k in range(dims)]
    length_squared = sum(v * v for v in d)
    t = 0.0 if length_squared == 0.0 else max(0.0, min(1.0, sum((p[k] - s[k]) * d[k] for k in range(dims)) / length_squared))
    return math.sqrt(sum((p[k] - s[k] - t * d[k]) ** 2 for k in range(dims)))


def envelope_distance(p, s, e):
    """Distance from p to the tool swept along s->e (ball of `radius` at the centre, tip + radius,
    with the shank's cylinder above it); 0 inside."""
    cs, ce = (s[0], s[1], s[2] + radius), (e[0], e[1], e[2] + radius)
    # Split where the centre passes p's height: below p, the shank's cylinder is nearest (distance in
    # the plane); above p, the ball (distance in space).
    if (cs[2] - p[2]) * (ce[2] - p[2]) < 0.0:
        t = (p[2] - cs[2]) / (ce[2] - cs[2])
        mid = tuple(cs[k] + t * (ce[k] - cs[k]) for k in range(3))
        pieces = [(cs, mid), (mid, ce)]
    else:
        pieces = [(cs, ce)]
    best = math.inf
    for u, v in pieces:
        if max(u[2], v[2]) <= p[2] + 1e-12:
            best = min(best, point_segment(p, u, v, 2) - radius)
        else:
            best = min(best, point_segment(p, u, v, 3) - radius)
    return max(0.0, best)


indexes = {name: bucketed(points) for name, points in paths.items()}
largest = 0.0
for p, other in differing:
    points = paths[other]
    candidates = set()
    for i in (-1, 0, 1):
        for j in (-1, 0, 1):
            candidates.update(indexes[other].get((math.floor(p[0] / BUCKET) + i, math.floor(p[1] / BUCKET) + j), []))
    nearest = min((envelope_distance(p, points[i], points[i + 1]) for i in candidates), default=math.inf)
    if nearest == math.inf:
        print(f"cell at ({p[0]:.3f}, {p[1]:.3f}) mm, height {p[2]:.4f}: the other path's tool never comes within 1 mm of it",
              file=sys.stderr)
    largest = max(largest, nearest)
print(f"{largest:.6f} {len(differing)}")
