#!/usr/bin/env python3
"""halsampler's file of sim/linuxcnc_mill (N Xmotor Ymotor Zmotor ...: every servo period's joint
positions, LinuxCNC's machine coordinates) as a G-code program of straight moves in the part's
coordinates (world = home + sign x machine, per axis), so that stencil-sim --gcode-direct cuts the
mill's true path into a stock as the simulation cuts it (board/sim/linuxcnc_wiring: a leg between
consecutive samples). An `overrun` line or a gap in N is lost samples: refused, named.

usage: samples_to_gcode.py SAMPLES OUT.ngc [--home 50,25,25] [--sign -1,-1,-1]
"""
import argparse
import sys

parser = argparse.ArgumentParser()
parser.add_argument("samples")
parser.add_argument("out")
parser.add_argument("--home", default="50,25,25")
parser.add_argument("--sign", default="-1,-1,-1")
args = parser.parse_args()
home = [float(v) for v in args.home.split(",")]
sign = [int(v) for v in args.sign.split(",")]
last, expected, points = None, None, 0
with open(args.samples) as samples, open(args.out, "w") as out:
    out.write("%\n(the mill's true path: halsampler's every servo period)\nG21 G90 G94 G17 G40 G49 G54 G61\nF1000\n")
    for number, line in enumerate(samples, 1):
        fields = line.split()
        if not fields:
            continue
        if fields[0] == "overrun" or (expected is not None and int(fields[0]) != expected):
            print(f"{args.samples}: line {number}: samples were lost ({fields[0]})", file=sys.stderr)
            sys.exit(1)
        expected = int(fields[0]) + 1
        point = tuple(round(home[i] + sign[i] * float(fields[1 + i]), 6) for i in range(3))
        if point != last:
            out.write("G1 X%.6f Y%.6f Z%.6f\n" % point)
            last, points = point, points + 1
    out.write("M2\n%\n")
print(f"{points} points")
