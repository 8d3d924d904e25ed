#!/usr/bin/env bash
# G-code in and out (issue 28), end to end on the simulation: the cut exported as a program that
# LinuxCNC's interpreter rs274 reads with no error and that, cut again by the simulated mill with no
# stencil, leaves the job's stock; and a CAM program as the operator, guarded by the stencil, with
# the lines it refused named and measured. One ctest e2e.gcode_NAME per function case_NAME.
# usage: sim_gcode.sh CASE STENCIL_SIM WORK_DIR SOURCE_DIR
# Without rs274 (Debian's linuxcnc-uspace) the case is skipped (77) with a message, unless
# STENCIL_REQUIRE_LINUXCNC=1 (CI).
set -uo pipefail

case_name="$1"
sim="$2"
work="$3/gcode_$case_name"
source_dir="$4"
journal_tool="$(dirname "$sim")/stencil-journal"
failures=0

if ! command -v rs274 >/dev/null 2>&1; then
  if [ "${STENCIL_REQUIRE_LINUXCNC:-0}" = 1 ]; then
    echo "FAIL: rs274 (LinuxCNC's interpreter) is not installed, and STENCIL_REQUIRE_LINUXCNC=1 (bash toolchain/install-deps.sh installs linuxcnc-uspace)" >&2
    exit 1
  fi
  echo "skipped: rs274 is not installed (bash toolchain/install-deps.sh installs linuxcnc-uspace)"
  exit 77
fi

rm -rf "$work"
mkdir -p "$work"
cd "$work" || exit 1

fail() {
  echo "FAIL: $*" >&2
  failures=$((failures + 1))
}
json() { python3 -c "import json, sys; r = json.load(open(sys.argv[1])); print(eval(sys.argv[2]))" "$@"; }
at_most() {
  # A number at most l: empty, null or None (nothing measured) fails.
  awk -v v="$1" -v l="$2" 'BEGIN { exit !(v ~ /^-?[0-9.]+([eE][-+]?[0-9]+)?$/ && v + 0 <= l + 0) }' || fail "$3 is '$1'; expected at most $2"
}
run() {
  "$@" > stdout.txt 2> stderr.txt
  status=$?
  echo "$ $* -> exit $status"
  sed 's/^/  stdout: /' stdout.txt
  sed 's/^/  stderr: /' stderr.txt
}

# A CAM-like program over the hex prism (top face z = 6, centred at 25, 12.5): passes clear of the
# part, an arc, and three plunges planted 0.5 mm into its top at lines 11, 14 and 18. Every other
# move stays clear or only leaves the part (the retracts).
write_cam_program() {
  cat > cam.ngc <<'PROGRAM'
%
(a CAM-like program over the hex prism: three plunges planted 0.5 mm into its top, at lines 11, 14 and 18)
G21 G90 G94 G17 G40 G49 G54 G61
T1 M6
S2800 M3
G0 Z12
G0 X18 Y12.5
G1 Z6.5 F300
G1 X25 F300
G1 X27
G1 Z5.5 F60
G1 Z6.5
G1 X23 F300
G1 Z5.5 F60
G0 Z8
G0 X25 Y10
G1 Z6.5 F120
G1 Z5.5 F60
G1 Z6.5
G2 X25 Y15 I0 J2.5 F300
G1 X32 Y15
G0 Z12
M5
M2
%
PROGRAM
}

# The cut written as a program (stencil-sim --gcode, and stencil-journal gcode from the same journal:
# the same program), read by rs274 with no error, and cut again by the simulated mill with no stencil
# (its canonical moves driving the mill directly): the job's stock within 0.01 mm, no gouge. Ten
# simulated minutes of make demo's raster job (the whole demo, measured once: README).
case_export_runs_through_rs274_and_cuts_the_same_stock() {
  run "$sim" --fast --pattern raster --duration 600 --out-dir jobs --keep-jobs 0 --report job.json --stock-csv "$work/job.csv" \
    --gcode job.ngc
  [ "$status" = 0 ] || fail "the job: exit status $status; expected 0"
  grep -q '^gcode: job.ngc' stdout.txt || fail "the job did not say where its program went"
  grep -qx 'G21 G90 G94 G17 G40 G49 G54 G61' job.ngc || fail "no G21 G90 G94 G17 G40 G49 G54 G61 header"
  grep -q '^T1 M6 (ball end mill d 3.000 mm' job.ngc || fail "the program does not name its tool"
  [ "$(grep -c '^G1 ' job.ngc)" -gt 1000 ] || fail "only $(grep -c '^G1 ' job.ngc) feed moves"
  run "$journal_tool" gcode jobs/latest/job.journal -o journal.ngc
  [ "$status" = 0 ] || fail "stencil-journal gcode: exit status $status; expected 0"
  # The same program but for the journal's name in its first comment.
  diff <(sed 2d job.ngc) <(sed 2d journal.ngc) > /dev/null || fail "stencil-journal gcode and stencil-sim --gcode differ"
  rs274 -g job.ngc canon.txt > rs274.txt 2>&1
  echo "rs274: exit $?; $(wc -l < canon.txt) canonical calls"
  tail -n 2 rs274.txt | sed 's/^/  rs274: /'
  grep -q 'PROGRAM_END()' canon.txt || fail "rs274 did not reach the program's end: $(tail -n 1 rs274.txt)"
  grep -qiE 'error|unknown|bad ' rs274.txt && fail "rs274 reported: $(grep -iE 'error|unknown|bad ' rs274.txt | head -n 1)"
  run "$sim" --gcode-direct job.ngc --out-dir direct --keep-jobs 0 --report direct.json --stock-csv "$work/direct.csv"
  [ "$status" = 0 ] || fail "--gcode-direct: exit status $status; expected 0"
  local difference
  difference=$(python3 "$source_dir/tests/e2e/stock_difference.py" job.csv direct.csv) || fail "the stocks could not be compared"
  echo "the stock cut again differs from the job's by at most $difference mm"
  at_most "$difference" 0.01 "the largest height difference between the job's stock and the program's (mm)"
  at_most "$(json direct.json "r['gouge']['max_depth_mm']")" 0.005 "the program's deepest gouge cut directly (mm)"
  [ "$(json direct.json "r['gcode']['run']")" = direct ] || fail "the direct cut's report does not say so"
}

# A CAM program as the operator: the stencil refuses exactly the three planted lines, each measured
# at the planted 0.5 mm (within 0.01), and the cut has no gouge.
case_guard_names_the_three_planted_plunges() {
  write_cam_program
  run "$sim" --fast --gcode-operator cam.ngc --out-dir jobs --keep-jobs 0 --report report.json
  [ "$status" = 0 ] || fail "exit status $status; expected 0"
  local lines
  lines=$(json report.json "[x['line'] for x in r['gcode']['refused']]")
  [ "$lines" = "[11, 14, 18]" ] || fail "refused lines $lines; expected [11, 14, 18]"
  for depth in $(json report.json "' '.join('%.6f' % x['depth_mm'] for x in r['gcode']['refused'])"); do
    awk -v d="$depth" 'BEGIN { exit !(d >= 0.49 && d <= 0.51) }' || fail "a refused line's depth is $depth mm; expected 0.5 +- 0.01"
  done
  at_most "$(json report.json "r['gouge']['max_depth_mm']")" 0.005 "the guarded cut's deepest gouge (mm)"
  grep -q 'gcode: 3 lines of cam.ngc refused or shortened by the stencil: line 11 (0.500 mm deep) line 14' stdout.txt ||
    fail "the summary does not list the refused lines"
  # Unguarded, the same program gouges the part as deep as the guard said.
  run "$sim" --gcode-direct cam.ngc --out-dir direct --keep-jobs 0 --report direct.json
  local gouge
  gouge=$(json direct.json "r['gouge']['max_depth_mm']")
  awk -v d="$gouge" 'BEGIN { exit !(d >= 0.49 && d <= 0.51) }' || fail "cut directly, the program gouges $gouge mm; expected 0.5"
}

# What the guard cannot follow faithfully is refused before anything runs, naming the line.
case_guard_refuses_cutter_compensation_naming_its_line() {
  write_cam_program
  sed 's/^G1 X23 F300$/G41 D1 G1 X23 F300/' cam.ngc > g41.ngc
  run "$sim" --fast --gcode-operator g41.ngc --out-dir jobs --keep-jobs 0
  [ "$status" = 2 ] || fail "exit status $status; expected 2 (bad input)"
  grep -q 'g41.ngc: line 13: cutter radius compensation' stderr.txt || fail "the refusal does not name line 13 and G41"
  [ -z "$(ls jobs 2>/dev/null)" ] || fail "a refused program left a job folder: $(ls jobs)"
  printf 'G21 G90\nG0 X20 Y5 Z10\nG81 X20 Y5 Z1 R8 F100\nM2\n' > g81.ngc
  run "$sim" --fast --gcode-operator g81.ngc --out-dir jobs --keep-jobs 0
  [ "$status" = 2 ] || fail "G81: exit status $status; expected 2"
  grep -q 'g81.ngc: line 3: .*canned cycle' stderr.txt || fail "the canned cycle's refusal does not name line 3"
  printf 'G21 G90\nG0 X20\nG1 X22 Y2 Q\nM2\n' > bad.ngc
  run "$sim" --fast --gcode-operator bad.ngc --out-dir jobs --keep-jobs 0
  [ "$status" = 2 ] || fail "a syntax error: exit status $status; expected 2"
  grep -q 'bad.ngc: line 3: rs274: ' stderr.txt || fail "rs274's error does not name line 3"
}

"case_$case_name"
[ "$failures" -eq 0 ] || { echo "$failures failure(s)" >&2; exit 1; }
echo "ok"
