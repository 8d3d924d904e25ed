#!/usr/bin/env bash
# End-to-end cases for stencil-sim (fast mode) and stencil-rig's start-up checks, one function
# case_NAME per ctest e2e.sim_NAME.
#
# usage: sim_cli.sh CASE STENCIL_SIM WORK_ROOT
# Each case runs in a fresh directory under WORK_ROOT, removed when it passes and kept, with its path
# printed, when it fails (SIM_CLI_KEEP=1 keeps it when it passes too: toolchain/same-behaviour.sh
# compares what two builds left there). Exit 0 pass, 1 fail. Only bash, coreutils, grep, sed and awk.
set -uo pipefail

if [ "$#" -ne 3 ]; then
  echo "usage: $0 CASE STENCIL_SIM WORK_ROOT" >&2
  exit 2
fi
case_name=$1 sim=$2 work_root=$3
rig="$(dirname "$sim")/stencil-rig"
journal_tool="$(dirname "$sim")/stencil-journal"
repo="$(cd "$(dirname "$0")/../.." && pwd)"

failures=0
status=0

fail() {
  echo "FAIL: $*" >&2
  failures=$((failures + 1))
}

# run PROGRAM ARGS...: runs it in the case's folder; sets status, and keeps stdout/stderr in files.
run() {
  echo "\$ $(basename "$1") ${*:2}"
  "$@" >stdout.txt 2>stderr.txt
  status=$?
  sed 's/^/  stdout: /' stdout.txt
  sed 's/^/  stderr: /' stderr.txt
  echo "  exit status $status"
}

# STENCIL_SIM_FEEL: options every stencil-sim run here also gets (make feel-check runs the job cases
# and the fault suite with the wall's feel and a dynamic hand this way); empty in CI.
read -r -a sim_feel <<<"${STENCIL_SIM_FEEL:-}"
run_sim() { run "$sim" "$@" "${sim_feel[@]}"; }
run_rig() { run "$rig" "$@"; }

expect_status() {
  [ "$status" -eq "$1" ] || fail "exit status $status; expected $1"
}

expect_stderr() {
  grep -Eq -- "$1" stderr.txt || fail "stderr does not say $2 (expected /$1/)"
}

# json_number FILE KEY: the first number after "KEY": in the report (nested keys are unique here).
json_number() {
  grep -E "\"$2\": " "$1" | head -n 1 | sed -E 's/.*": ([-0-9.eE+]+|null).*/\1/'
}

# at_most VALUE LIMIT WHAT
at_most() {
  # A number at most l: empty or null (nothing measured) fails.
  awk -v v="$1" -v l="$2" 'BEGIN { exit !(v ~ /^-?[0-9.]+([eE][-+]?[0-9]+)?$/ && v + 0 <= l + 0) }' || fail "$3 is '$1'; expected at most $2"
}

# journal_holds_everything JOURNAL REPORT EVENTS WHAT: read back with stencil-journal (the
# controllers' own reader), the journal holds one run, ended in order: its start's provenance, every
# cycle, machine command and command the cycle took as the report counts them, the homing, EVENTS
# safe-state events and no torn tail; and at most 14.3 bytes a cycle (version 4 took 115: the
# compact journal must be at least 8 times smaller).
journal_holds_everything() {
  local journal=$1 report=$2 events=$3 what=$4 summary field want got
  summary=$("$journal_tool" summary "$journal") || fail "$what: stencil-journal cannot read $journal"
  for field in cycles:cycles machine_commands:machine_records commands:command_records; do
    want=$(json_number "$report" "${field#*:}")
    got=$(echo "$summary" | sed -n "s/^${field%%:*}: \([0-9]*\).*/\1/p")
    [ "$got" = "$want" ] || fail "$what: $journal holds $got ${field%%:*}; the report counts $want"
  done
  for field in safe_states:"$events" homings:1 ends:1 provenance:1 runs:1; do
    got=$(echo "$summary" | sed -n "s/^${field%%:*}: \([0-9]*\).*/\1/p")
    [ "$got" = "${field#*:}" ] || fail "$what: $journal holds $got ${field%%:*}; expected ${field#*:}"
  done
  echo "$summary" | grep -q "^bytes: [0-9]* whole, 0 torn tail$" || fail "$what: $journal has a torn tail: $summary"
  [ "$(json_number "$report" machine_records)" -gt 0 ] || fail "$what: no machine command in the journal"
  at_most "$(echo "$summary" | sed -n 's/^bytes_per_cycle: //p')" 14.3 "$what: the journal's bytes per cycle"
}

# journal_cycles JOURNAL: how many cycles the journal holds so far (0 before it is there).
journal_cycles() {
  "$journal_tool" summary "$1" 2>/dev/null | sed -n 's/^cycles: \([0-9]*\).*/\1/p' | grep . || echo 0
}

# strip_wall_clock REPORT: the report without what differs between two runs of the same job: the
# wall clock's figures and the provenance (the command line, which names each run's own outputs).
strip_wall_clock() {
  awk '/"provenance": \{/ { prov = 1; depth = 0 }
    prov { depth += gsub(/[{[]/, "&"); depth -= gsub(/[]}]/, "&"); if (depth <= 0) prov = 0; next }
    /"(compute_us|memory_kb)": \{/ { skip = 1 } skip && /\}/ { skip = 0; next } !skip && !/"wall_s":/' "$1"
}

# stock_within CSV REFERENCE LIMIT WHAT: every cell of the two stocks within LIMIT mm.
stock_within() {
  local worst
  worst=$(awk -F, 'NR == FNR { for (i = 1; i <= NF; i++) a[FNR "," i] = $i; rows = FNR; next }
    { for (i = 1; i <= NF; i++) { d = $i - a[FNR "," i]; if (d < 0) d = -d; if (d > m) m = d } n = FNR }
    END { if (n != rows) print "rows"; else printf "%.6f", m + 0 }' "$2" "$1")
  [ "$worst" != "rows" ] || fail "$4: $1 and $2 have different sizes"
  at_most "$worst" "$3" "$4: the largest difference of any stock cell from the uninterrupted run's (mm)"
}

# is_png FILE: the picture beside the report is there and starts with PNG's signature.
is_png() {
  [ -s "$1" ] || fail "no picture was written beside the report ($1)"
  [ "$(head -c 8 "$1" | od -An -tx1 | tr -d ' \n')" = 89504e470d0a1a0a ] || fail "$1 is not a PNG picture"
}

no_gouge() {
  at_most "$(json_number report.json max_depth_mm)" 0.005 "the deepest gouge (mm)"
  grep -q '"safe_state": null' report.json || fail "the run ended in a safe state: $(grep safe_state report.json)"
}

# The issue's bar: raster over the whole hex prism until done leaves no gouge over 0.005 mm and at
# most 1 % of the stock this tool can reach (the demo's job; about two minutes, so the sanitizer
# build runs the corner case below instead).
case_raster_whole_part() {
  run_sim --fast --pattern raster --until-complete --report report.json
  expect_status 0
  no_gouge
  at_most "$(json_number report.json fraction)" 0.01 "the unmachined fraction"
  grep -q '"complete": true' report.json || fail "the job did not complete"
  is_png report.png
}

# A corner of the hex prism's stock, raster until done: the same bar on a quarter of the job,
# where the part runs out of the stock on two sides (the finishing pass breaks into arcs there).
case_raster_corner() {
  run_sim --fast --pattern raster --until-complete --stock 15,3.6,0,25,12.5,7 --report report.json
  expect_status 0
  no_gouge
  at_most "$(json_number report.json fraction)" 0.01 "the unmachined fraction"
  # The controller's own model of the stock (from what it commanded) agrees with the mill's.
  at_most "$(json_number report.json max_difference_mm)" 0.01 "the model's largest difference from the mill's stock (mm)"
  is_png report.png
}

# The corner job stopped by a fault half-way (its tool in contact with the part by then), resumed
# from the journal and carried on to completion: the touched set is rebuilt to what the journal
# recorded, and the whole job meets the corner job's bars. (Cell by cell it is not the uninterrupted
# run: after the way back the tool's contact with the walls differs by micrometres, and a Z-map
# cell on a wall's edge can hold a sliver either way.)
case_resume_after_a_fault_completes_the_corner_job() {
  local corner=(--fast --pattern raster --until-complete --stock 15,3.6,0,25,12.5,7)
  run_sim "${corner[@]}" --inject pose-jump@700 --journal job.journal --report first.json
  expect_status 3
  run_sim "${corner[@]}" --resume job.journal --report report.json
  expect_status 0
  no_gouge
  at_most "$(json_number report.json fraction)" 0.01 "the unmachined fraction"
  local recorded rebuilt
  recorded=$(json_number report.json touched_recorded)
  rebuilt=$(json_number report.json touched_rebuilt)
  [ "$recorded" -gt 0 ] || fail "nothing was touched before the fault; the case does not test the rebuild"
  [ "$recorded" = "$rebuilt" ] || fail "the touched set rebuilt has $rebuilt triangles; the journal recorded $recorded"
}

# --replay: the recorded job again on the virtual clock, every cycle reading what the recorded one
# read: the faulted and resumed job (two runs, the second from the state the first left), and a
# random walk into the part over CAN; every virtual tool bit for bit as recorded, the same stock.
case_replay_gives_the_recorded_job_back() {
  run_sim "${fault_job[@]}" --inject pose-jump@40 --journal job.journal --report first.json
  expect_status 3
  run_sim "${fault_job[@]}" --resume job.journal --report resumed.json --stock-csv resumed.csv
  expect_status 0
  run_sim --replay job.journal --report replay.json --stock-csv replayed.csv
  expect_status 0
  grep -q "replay run 0: 40021 of 40021 recorded cycles, 0 recorded commands (0 taken otherwise), 0 cycles with a different virtual tool; recorded ending pose_jump, replayed pose_jump: the same" stdout.txt ||
    fail "the faulted run did not replay as recorded"
  grep -Eq "replay run 1: ([0-9]+) of \1 recorded cycles, 0 recorded commands \(0 taken otherwise\), 0 cycles with a different virtual tool; recorded ending none, replayed none: the same" stdout.txt ||
    fail "the resumed run did not replay as recorded"
  cmp -s resumed.csv replayed.csv || fail "the replayed stock is not the recorded job's"
  run_sim --fast --pattern random --seed 7 --duration 60 --haptic-transport can --journal walk.journal --report walk.json
  expect_status 0
  run_sim --replay walk.journal --report walk_replay.json
  expect_status 0
  grep -q "replay: every run replayed as recorded" stdout.txt || fail "the random walk over CAN did not replay as recorded"
  [ "$(json_number walk.json max_force_n)" = "$(json_number walk_replay.json max_force_n)" ] ||
    fail "the replay's largest force $(json_number walk_replay.json max_force_n) N is not the recorded $(json_number walk.json max_force_n) N"
}

# What --replay refuses: a journal that is not one, and options that have no place in a replay.
case_replay_refuses_what_it_cannot_replay() {
  printf 'not a journal' >junk.journal
  run_sim --replay junk.journal
  expect_status 2
  expect_stderr "--replay: junk.journal: journal offset 0: not a journal" "the file and what is wrong with it"
  run_sim --replay junk.journal --inject pose-nan@3
  expect_status 2
  expect_stderr "--replay runs the recorded job on the virtual clock by itself" "what cannot go with it"
  run_sim --fast --resume junk.journal
  expect_status 2
  expect_stderr "--resume: junk.journal: journal offset 0: not a journal" "the file and what is wrong with it"
}

case_plunge() {
  run_sim --fast --pattern plunge --duration 150 --report report.json
  expect_status 0
  no_gouge
}

# Issue 29: the wall's feel on (damping, friction, the penalty speed limiting) with a dynamic hand
# pulling the handle: the engine still decides every move, so no gouge; the report lists the three
# opening commands, applied at the first cycle, and the limits they set.
case_plunge_with_the_walls_feel_and_a_dynamic_hand() {
  run_sim --fast --pattern plunge --duration 150 --hand medium --damping 30 --friction 0.5 --speed-limiting penalty \
    --report report.json
  expect_status 0
  no_gouge
  python3 - report.json <<'PY' || fail "the report does not show the wall's feel in force"
import json, sys
r = json.load(open(sys.argv[1]))
sets = [(c["parameter"], c["applied"], c["source"], c["cycle"]) for c in r["commands"]["list"] if c.get("parameter")]
assert sets == [("damping", 30.0, "program", 1), ("friction", 0.5, "program", 1), ("speed_limiting", 1.0, "program", 1)], sets
last = r["limits"][-1]
assert (last["damping_n_s_per_m"], last["friction"], last["speed_limiting"]) == (30.0, 0.5, "penalty"), last
PY
}

case_thinwall() {
  run_sim --fast --pattern thinwall --duration 150 --report report.json
  expect_status 0
  no_gouge
}

case_random() {
  run_sim --fast --pattern random --seed 7 --duration 150 --report report.json
  expect_status 0
  no_gouge
}

# A random job that used to end in a stall (the mill found no legal staircase for 3 s, 1,400 s in:
# the virtual tool rode the prism's top edge a micrometre off it, the hand pressed deep below) runs
# past that point: the standoff keeps a legal way open for the mill. About a minute.
case_random_job_that_stalled_runs_past_its_stall() {
  run_sim --fast --pattern random --seed 3 --moves 600 --duration 1410 --no-journal --report report.json
  expect_status 0
  no_gouge
  grep -q stalled stdout.txt stderr.txt report.json && fail "the mill stalled"
  return 0
}

# Two more random jobs that stalled (seeds 6 and 13 of make stall-seeds, 412 and 380 simulated s in,
# before the standoff) run past where they stalled. Half a minute.
case_random_jobs_that_stalled_early_run_past_their_stalls() {
  local seed duration
  for seed in 6 13; do
    duration=$([ "$seed" -eq 6 ] && echo 430 || echo 400)
    run_sim --fast --pattern random --seed "$seed" --moves 600 --duration "$duration" --no-journal --report report.json
    expect_status 0
    no_gouge
    grep -q stalled stdout.txt stderr.txt report.json && fail "seed $seed: the mill stalled"
  done
  return 0
}

# A hand pressed hard into the concave corner where the prism's walls meet the floor, from several
# directions in turn (each point is inside the prism and 1.5-2 mm under the floor, as low as the device reaches), and over the top's edge:
# the mill follows all the way: no stall, no other safe state, no gouge.
case_pressed_into_the_floor_corner_from_several_directions() {
  cat >pressed.csv <<'CSV'
t_s,x_mm,y_mm,z_mm
0,500,250,250
25,345,95,250
45,345,95,20
60,310,125,-20
75,345,100,10
90,320,165,-20
105,345,100,10
120,300,175,-20
135,330,140,-15
150,345,95,10
165,300,100,90
180,200,120,30
195,180,200,40
210,340,95,80
CSV
  run_sim --fast --operator pressed.csv --no-journal --report report.json
  expect_status 0
  no_gouge
  grep -q stalled stdout.txt stderr.txt report.json && fail "the mill stalled"
  return 0
}

# --script-csv to a file that cannot be written: refused before the job runs, naming the file.
case_script_csv_that_cannot_be_written_is_refused() {
  run_sim --fast --pattern raster --duration 1 --no-journal --script-csv no-such-folder/script.csv --report report.json
  expect_status 2
  expect_stderr "no-such-folder/script.csv: cannot be written" "which file could not be written"
  [ ! -e report.json ] || fail "a report was written for a job that did not run"
  return 0
}

# The same inputs give the same report, apart from the wall-clock fields.
case_same_report_twice() {
  run_sim --fast --pattern random --seed 3 --duration 60 --no-journal --report first.json
  expect_status 0
  run_sim --fast --pattern random --seed 3 --duration 60 --no-journal --report second.json
  expect_status 0
  if ! diff <(strip_wall_clock first.json) <(strip_wall_clock second.json); then
    fail "two runs of the same job gave different reports"
  fi
  cmp -s first.png second.png || fail "two runs of the same job gave different pictures"
}

# A display killed part way through a job changes nothing in it: the controller neither waits for
# nor depends on its displays, so the report is the same as without one (apart from wall clock).
case_killing_the_display_changes_nothing() {
  local display socket display_pid sim_pid
  display="$(dirname "$sim")/stencil-display"
  socket="$PWD/display.sock"
  "$display" --controller "$socket" --listen 127.0.0.1:0 >display.log 2>&1 &
  display_pid=$!
  "$sim" --fast --pattern random --seed 3 --duration 600 --no-journal --display-socket "$socket" \
    --report with.json >with.log 2>&1 &
  sim_pid=$!
  for _ in $(seq 1 200); do grep -q "controller connected" display.log && break; sleep 0.02; done
  sleep 0.3
  if kill -0 "$sim_pid" 2>/dev/null; then
    kill -9 "$display_pid"
    echo "display killed while the job ran"
  else
    fail "the job ended before the display could be killed"
  fi
  wait "$display_pid" 2>/dev/null
  wait "$sim_pid"
  status=$?
  sed 's/^/  display: /' display.log
  sed 's/^/  stdout: /' with.log
  expect_status 0
  grep -q "display link: 1 display(s) connected" with.log || fail "the display never connected"
  run_sim --fast --pattern random --seed 3 --duration 600 --no-journal --report without.json
  expect_status 0
  if ! diff <(strip_wall_clock with.json) <(strip_wall_clock without.json); then
    fail "killing the display changed the job's report"
  fi
}

# A service has no terminal: `stencil-rig status|pause|start|stop` reach a running controller over
# its socket, and a stop sent so ends its job in the safe state, recorded with the source `control`.
# The job runs on the paced virtual clock (--speed 2), not the real-time threads of --speed 1: the
# socket and its commands are the same, and a host too loaded to keep real time (the sanitized
# suites beside a build) cannot starve the machine side into the fault it would rightly raise there
# (a ring of 512 cycles falling behind: machine_fault instead of the stop this case checks).
case_control_commands_reach_a_running_controller() {
  local socket="$PWD/control.sock" sim_pid
  "$sim" --speed 2 --pattern raster --duration 60 --display-socket "$socket" --journal job.journal \
    --report report.json >sim.log 2>&1 &
  sim_pid=$!
  for _ in $(seq 1 300); do [ -S "$socket" ] && break; sleep 0.02; done
  # Homing first: the job runs once the cycle has made records and told its state (the force line).
  for _ in $(seq 1 100); do
    "$rig" status --socket "$socket" 2>/dev/null | grep -q "^force:" && break
    sleep 0.1
  done
  run_rig status --socket "$socket"
  expect_status 0
  grep -q "controller: stencil-sim (pid $sim_pid)" stdout.txt || fail "status does not name the controller"
  grep -q "^job: running, cycle" stdout.txt || fail "status does not say the job runs"
  grep -q "^safe state: none" stdout.txt || fail "status does not say there is no safe state"
  run_rig pause --socket "$socket"
  expect_status 0
  # Accepted is queued: the cycle takes it at its next period, however late a loaded host runs it.
  for _ in $(seq 1 100); do
    "$rig" status --socket "$socket" 2>/dev/null | grep -q "PAUSED" && break
    sleep 0.1
  done
  run_rig status --socket "$socket"
  grep -q "PAUSED" stdout.txt || fail "status does not show the pause"
  grep -q ", held$" stdout.txt || fail "status does not show the mill held"
  run_rig start --socket "$socket"
  expect_status 1
  expect_stderr "refused: not waiting for a start" "why a start is refused mid-cut"
  run_rig stop --socket "$socket"
  expect_status 0
  wait "$sim_pid"
  status=$?
  sed 's/^/  stencil-sim: /' sim.log
  grep -q '"safe_state": "stopped"' report.json || fail "the job did not end in the safe state 'stopped'"
  grep -q '"source": "control"' report.json || fail "the report does not record the stop's source (control)"
  run_rig status --socket "$socket" --timeout 0.5
  expect_status 3
  expect_stderr "no controller at .*control.sock" "that no controller is there"
}

# Installed (cmake --install, what the package holds), the programs find what ships beside them under
# <prefix>/share/stencil, not in the build tree: the page, the sample parts; the units, the example
# configuration and the man pages are there too.
case_installed_programs_find_their_page_and_parts() {
  local build prefix="$PWD/prefix" display_pid
  build=$(cd "$(dirname "$sim")/.." && pwd)
  run cmake --install "$build" --prefix "$prefix"
  expect_status 0
  if [ ! -x "$prefix/bin/stencil-sim" ]; then
    echo "this build installs nothing (the sanitizers' build has no install rules): skipped"
    exit 77
  fi
  for file in share/stencil/parts/hex_prism.stl share/stencil/examples/rig.toml lib/systemd/system/stencil-rig.service \
              lib/systemd/system/stencil-display.service lib/udev/rules.d/60-stencil-uio.rules bin/stencil-rig \
              bin/stencil-display bin/stencil-tablegen share/doc/stencil/README.md; do
    [ -e "$prefix/$file" ] || fail "$file is not installed"
  done
  if [ -d "$build/hmi" ]; then
    [ -e "$prefix/share/stencil/page/index.html" ] || fail "the page is not installed"
  fi
  if [ -d "$build/man" ]; then
    [ -e "$prefix/share/man/man1/stencil-rig.1.gz" ] || fail "stencil-rig's man page is not installed"
  fi
  run "$prefix/bin/stencil-tablegen" sample:hex_prism --tool ball:d=3 -o hex.stbl --quiet
  expect_status 0
  [ -s hex.stbl ] || fail "no table from the installed sample part"
  run "$prefix/bin/stencil-tablegen" sample:no_such_part --tool ball:d=3
  expect_status 2
  expect_stderr "no such sample part in $prefix/share/stencil/parts \\(expected sample:NAME with NAME one of" \
    "where the installed parts are and which there are"
  "$prefix/bin/stencil-display" --controller "$PWD/none.sock" --listen 127.0.0.1:0 >display.log 2>&1 &
  display_pid=$!
  for _ in $(seq 1 100); do grep -q "the page from" display.log && break; sleep 0.05; done
  kill "$display_pid" 2>/dev/null
  wait "$display_pid" 2>/dev/null
  sed 's/^/  display: /' display.log
  grep -q "display: the page from $prefix/share/stencil/page$" display.log || fail "the installed display does not serve the installed page"
  run "$prefix/bin/stencil-sim" --fast --pattern raster --duration 1 --no-journal --report report.json --tables hex.stbl
  expect_status 0
  grep -q "\"$prefix/bin/stencil-sim\"" report.json || fail "the report's provenance does not name the installed program"
}

# The simulated device reached through the real PIO shared-memory and SocketCAN code: both wires
# carry positions to the micrometre, so the two give the same report, and neither gouges.
case_pio_and_can_give_the_same_result() {
  run_sim --fast --pattern plunge --duration 90 --haptic-transport pio --no-journal --report pio.json
  expect_status 0
  cp pio.json report.json && no_gouge
  run_sim --fast --pattern plunge --duration 90 --haptic-transport can --no-journal --report can.json
  expect_status 0
  cp can.json report.json && no_gouge
  if ! diff <(strip_wall_clock pio.json) <(strip_wall_clock can.json); then
    fail "the same job through pio and can gave different reports"
  fi
}

case_trace_is_written() {
  run_sim --fast --pattern plunge --duration 30 --trace ./trace.csv --report report.json
  expect_status 0
  head -n 1 trace.csv | grep -qx 't_s,x_mm,y_mm,z_mm' || fail "trace.csv has no header t_s,x_mm,y_mm,z_mm"
  [ "$(wc -l <trace.csv)" -gt 10 ] || fail "trace.csv has fewer than 10 corners"
  awk -F, 'NR > 1 && (NF != 4 || $1 + 0 < prev) { bad = 1 } NR > 1 { prev = $1 + 0 } END { exit bad }' trace.csv ||
    fail "trace.csv rows are not t_s,x_mm,y_mm,z_mm with t_s increasing"
}

# Neither --fast nor --speed: it asks for one; the two together are refused, and so are the
# real-time thread's options where there is no real-time thread.
case_refuses_to_run_without_a_clock() {
  run_sim --pattern raster
  expect_status 2
  expect_stderr "pass --fast \(virtual time\) or --speed N \(N x real time\)" "the two ways to run"
  run_sim --fast --speed 1 --pattern raster
  expect_status 2
  expect_stderr "--fast and --speed: choose one" "that the two exclude each other"
  run_sim --speed 5 --cpu 1 --pattern raster
  expect_status 2
  expect_stderr "--priority, --cpu and --require-rt are for the real-time threads of --speed 1 only" "where --cpu applies"
}

# --speed N (N other than 1) is the virtual clock held to N x the wall clock: the same report as
# --fast, timing aside, and no faster than N allows.
case_speed_n_is_fast_mode_paced() {
  run_sim --fast --pattern plunge --duration 12 --no-journal --report fast.json
  expect_status 0
  run_sim --speed 20 --pattern plunge --duration 12 --no-journal --report paced.json
  expect_status 0
  if ! diff <(strip_wall_clock fast.json) <(strip_wall_clock paced.json); then
    fail "--speed 20 and --fast gave different reports"
  fi
  # 12 simulated seconds and the 30 s the mill may take to catch up, at 20 x: at least 0.6 s.
  local wall
  wall=$(json_number paced.json wall_s)
  awk -v w="$wall" 'BEGIN { exit !(w + 0 >= 0.6) }' || fail "12 simulated s at --speed 20 took $wall s; expected at least 0.6 s"
}

# --journal: every cycle's record and every machine command reach the file; a journal that cannot
# be created is refused before the run. Without --journal the journal is job.journal in the job's own
# folder, named after the start time, under $XDG_STATE_HOME/stencil/jobs.
case_journal_holds_every_cycle() {
  run_sim --fast --pattern plunge --duration 5 --journal job.journal --report report.json
  expect_status 0
  grep -q '"cycle_records"' report.json || fail "the report does not describe the journal"
  local cycles records
  cycles=$(json_number report.json cycles)
  records=$(json_number report.json cycle_records)
  [ "$records" = "$cycles" ] || fail "the journal holds $records cycle records; the run had $cycles cycles"
  journal_holds_everything job.journal report.json 0 "plunge"
  head -c 8 job.journal | grep -q STENCILJ || fail "job.journal does not start with the magic STENCILJ"
  run_sim --fast --pattern plunge --duration 5 --journal /nonexistent/job.journal --report report2.json
  expect_status 2
  expect_stderr "/nonexistent/job.journal: cannot be created: No such file or directory" "which journal and why"
  [ ! -e report2.json ] || fail "a refused run left a report behind"
  run_sim --fast --pattern plunge --duration 1 --report report3.json
  expect_status 0
  local named
  named=$(sed -n 's/^journal: //p' stdout.txt)
  echo "$named" | grep -Eq "^$XDG_STATE_HOME/stencil/jobs/stencil-sim-[0-9]{8}-[0-9]{6}/job[.]journal\$" ||
    fail "the default journal is '$named'; expected \$XDG_STATE_HOME/stencil/jobs/stencil-sim-YYYYMMDD-HHMMSS/job.journal"
  [ -s "$named" ] || fail "the default journal $named was not written"
  run_sim --fast --pattern plunge --duration 1 --no-journal --report report4.json
  expect_status 0
  grep -q '"journal": null' report4.json || fail "--no-journal still wrote a journal"
}

# mill_off_at_end REPORT WHAT [relay]: the simulated mill's spindle and drivers (its power as the
# board's latches leave it, not what the driver believes) are off once the machine side stopped it.
# With "relay" (a link fault: the driver may not reach the controller to turn them off) they may stay
# on until the rig's watchdog relay drops them a second later, and must be off then.
mill_off_at_end() {
  local report=$1 what=$2 mode=${3:-}
  grep -q '"on_after_watchdog_relay": false' "$report" ||
    fail "$what: the spindle or the drivers are on even after the watchdog relay's second"
  if [ "$mode" = relay ]; then
    if ! grep -q '"stop_confirmed": true' "$report"; then
      grep -q '"spindle_on_after_stop": false' "$report" && grep -q '"drivers_on_after_stop": false' "$report" ||
        grep -q '"watchdog_relay_dropped_power": true' "$report" ||
        fail "$what: the stop was not confirmed and the watchdog relay did not drop the power"
    fi
    return
  fi
  grep -q '"spindle_on_after_stop": false' "$report" || fail "$what: the spindle is on after the stop"
  grep -q '"drivers_on_after_stop": false' "$report" || fail "$what: the drivers are on after the stop"
  grep -q '"stop_confirmed": true' "$report" || fail "$what: the link did not confirm the stop"
}

# SIGNAL mid-cut (SIGTERM; SIGHUP, a closed terminal; SIGQUIT, Ctrl-\): the run ends in the safe state
# "stopped" (exit 3) with its report and journal written, the safe-state event in the journal, and
# the mill's spindle and drivers off, the link having confirmed it (issue 18, item 1: before, a
# SIGHUP killed the run with the spindle latched on).
signal_mid_cut() {
  local signal=$1
  echo "\$ stencil-sim --speed 10 --pattern raster --journal job.journal --report report.json  (SIG$signal once cutting)"
  "$sim" --speed 10 --pattern raster --journal job.journal --report report.json >stdout.txt 2>stderr.txt &
  local pid=$! waited=0
  # Mid-cut: once the journal holds a simulated second of cycles (slow builds take a while).
  while [ "$(journal_cycles job.journal)" -lt 1000 ] && [ "$waited" -lt 600 ]; do
    sleep 0.1
    waited=$((waited + 1))
  done
  kill -"$signal" "$pid"
  wait "$pid"
  status=$?
  sed 's/^/  stdout: /' stdout.txt
  echo "  exit status $status"
  expect_status 3
  grep -q '"safe_state": "stopped"' report.json || fail "the report does not give the safe state stopped: $(grep safe_state report.json)"
  grep -q "safe state: stopped" stdout.txt || fail "the summary does not say the run was stopped"
  mill_off_at_end report.json "SIG$signal"
  grep -q '"safe_state_source": "signal"' report.json ||
    fail "the report does not say the stop came from a signal: $(grep safe_state_source report.json)"
  journal_holds_everything job.journal report.json 1 "SIG$signal"
}
case_sigterm_mid_cut_ends_in_the_safe_state_with_the_record_kept() { signal_mid_cut TERM; }
case_sighup_mid_cut_leaves_the_mill_off() { signal_mid_cut HUP; }
case_sigquit_mid_cut_leaves_the_mill_off() { signal_mid_cut QUIT; }

# The fault suite's job, shared by every case: a raster over a tall block beside home, so that the
# cut is under way 25 s in; 60 simulated seconds. The uninterrupted run is the reference_job case,
# which the fault cases need first (a ctest fixture); its stock is kept in the shared folder.
fault_job=(--fast --pattern raster --stock 40,17,0,48,23,20 --duration 60)
shared="$work_root/shared"

case_reference_job() {
  mkdir -p "$shared"
  rm -f "$shared/reference.csv"
  run_sim "${fault_job[@]}" --no-journal --report report.json --stock-csv ./reference.csv
  expect_status 0
  no_gouge
  local removed
  removed=$(grep -A1 '"removed"' report.json | json_number /dev/stdin volume_mm3)
  awk -v r="$removed" 'BEGIN { exit !(r + 0 > 10) }' || fail "the reference job removed $removed mm3; expected a cut under way (over 10 mm3)"
  [ "$failures" -eq 0 ] && cp reference.csv "$shared/reference.csv"
}

# resume_matches_reference REASON WHAT: carries the journal's job on to its end; it must end well,
# cover both runs (the first ended in the safe state REASON; -: it has none, it was killed), rebuild the touched set the journal recorded, and leave every cell of the stock
# within 0.01 mm of the uninterrupted run's.
resume_matches_reference() {
  local reason=$1 what=$2
  [ -s "$shared/reference.csv" ] || { fail "$what: no reference stock (the reference_job case runs first)"; return; }
  run_sim "${fault_job[@]}" --resume job.journal --report resumed.json --stock-csv resumed.csv
  expect_status 0
  grep -q "resume: job.journal: 1 run(s)" stdout.txt || fail "$what: the resume did not say what it found in the journal"
  cp resumed.json report.json && no_gouge
  [ "$(json_number resumed.json runs)" = 2 ] || fail "$what: the resumed report covers $(json_number resumed.json runs) runs; expected 2"
  if [ "$reason" != - ]; then
    grep -A4 '"safe_states"' resumed.json | grep -q "\"reason\": \"$reason\"" ||
      fail "$what: the resumed report does not account for the first run's $reason"
  else
    grep -q '"safe_states": \[\]' resumed.json || fail "$what: the resumed report gives safe states nobody entered"
  fi
  [ "$(json_number resumed.json touched_recorded)" = "$(json_number resumed.json touched_rebuilt)" ] ||
    fail "$what: the touched set rebuilt has $(json_number resumed.json touched_rebuilt) triangles; the journal recorded $(json_number resumed.json touched_recorded)"
  if [ ${#sim_feel[@]} -eq 0 ]; then
    stock_within resumed.csv "$shared/reference.csv" 0.01 "$what"
  else
    # A dynamic hand does not take up the cut exactly where it stopped (it comes back with an arm's
    # lag and momentum the placed hand has not): said, not failed (make feel-check measures gouges).
    echo "note: with STENCIL_SIM_FEEL the resumed stock is not compared with the reference cell by cell"
  fi
}

# The fault-injection cases: the shared job, one fault 40 simulated seconds in (mid-cut). Each must
# end in the named safe state (exit 3), within DETECT seconds of the fault; the device must drive no
# force within one period of the safe state, the mill be held and stopped by the machine update
# after the one under way (two updates: 67 ms), the journal hold every cycle, command and the event,
# and nothing be gouged. Then the job is resumed from its journal (resume_matches_reference).
# expect_fault KIND REASON DETECT [TRANSPORT]
expect_fault() {
  local kind=$1 reason=$2 detect=$3 transport=${4:-direct}
  run_sim "${fault_job[@]}" --haptic-transport "$transport" --inject "$kind@40" --journal job.journal --report report.json
  expect_status 3
  grep -q "\"safe_state\": \"$reason\"" report.json || fail "$kind ended in $(grep '"safe_state"' report.json); expected $reason"
  at_most "$(json_number report.json max_depth_mm)" 0.005 "the deepest gouge (mm)"
  local injected safe force stopped
  injected=$(json_number report.json injected_s)
  safe=$(json_number report.json safe_state_s)
  force=$(json_number report.json force_zero_s)
  stopped=$(json_number report.json machine_stopped_s)
  awk -v i="$injected" -v s="$safe" -v d="$detect" 'BEGIN { exit !(s >= i && s - i <= d + 1e-9) }' ||
    fail "$kind: the safe state came at $safe s for a fault at $injected s; expected within $detect s"
  if [ "$kind" = device-frozen ] && [ "$transport" != direct ] && [ ${#sim_feel[@]} -gt 0 ]; then
    # A hung device reads no command: it keeps the force it last took. The placed hand's was zero in
    # free air; the speed penalty's is not. Nothing the controller sends can change that.
    echo "note: device-frozen over $transport with STENCIL_SIM_FEEL: the hung device's force went to zero at $force s (-1: never)"
  else
    awk -v s="$safe" -v f="$force" 'BEGIN { exit !(f >= s && f - s <= 0.001 + 1e-9) }' ||
      fail "$kind: no force at $force s, the safe state at $safe s; expected within one period"
  fi
  awk -v s="$safe" -v m="$stopped" 'BEGIN { exit !(m >= 0 && m - s <= 0.067) }' ||
    fail "$kind: the mill stopped at $stopped s, the safe state at $safe s; expected by the next machine update"
  journal_holds_everything job.journal report.json 1 "$kind"
  mill_off_at_end report.json "$kind" "$([ "$reason" = machine_fault ] && echo relay)"
  resume_matches_reference "$reason" "$kind"
}

case_fault_device_frozen() { expect_fault device-frozen device_stale 0.007; }
case_fault_device_frozen_over_pio() { expect_fault device-frozen device_stale 0.007 pio; }
case_fault_device_frozen_over_can() { expect_fault device-frozen device_stale 0.007 can; }
case_fault_pose_nan() { expect_fault pose-nan pose_not_finite 0.001; }
case_fault_pose_jump() { expect_fault pose-jump pose_jump 0.001; }
case_fault_pose_jump_over_can() { expect_fault pose-jump pose_jump 0.001 can; }
case_fault_device_fault_over_pio() { expect_fault device-fault device_fault 0.001 pio; }
case_fault_cy545_silent() { expect_fault cy545-silent machine_fault 0.2; }
case_fault_cy545_garbled() { expect_fault cy545-garbled machine_fault 0.2; }
case_fault_serial_closed() { expect_fault serial-closed machine_fault 0.2; }
case_fault_position_mismatch() { expect_fault position-mismatch machine_fault 0.2; }
# 20 ms of bad CAN frames (a wrong DLC, pose halves whose counters disagree) and no good pose: refused
# and counted, and after 5 periods without a fresh sample the cycle is in its safe state.
case_fault_can_bad_frames() { expect_fault can-bad-frames device_stale 0.007 can; }
# Every cycle 1.5 periods late from the fault on: the fourth overrun in a row is the safe state.
case_fault_overrun_storm() { expect_fault overrun-storm overrun_storm 0.004; }

# SIGKILL mid-cut (no handler runs, nothing is flushed on the way out), with the simulated device in
# a process of its own over the PIO window: the device's own host watchdog zeroes the force (its
# 20 ms, and a few on this host). Then --resume from the journal: a torn tail, if the kill left one,
# is ignored, and the job carries on to the same stock as the uninterrupted run.
case_kill_mid_cut_then_resume() {
  local paced=(--speed 10 "${fault_job[@]:1}" --haptic-transport pio --device-process ./device.log)
  echo "\$ stencil-sim ${paced[*]} --journal job.journal --report report.json  (SIGKILL once cutting)"
  "$sim" "${paced[@]}" --journal job.journal --report report.json >stdout.txt 2>stderr.txt &
  local pid=$! waited=0 zero_ms
  # Mid-cut: 35 simulated seconds in (3.5 s at 10 x; the cut starts at about 25 s).
  while [ "$(journal_cycles job.journal)" -lt 35000 ] && [ "$waited" -lt 1200 ]; do
    sleep 0.05
    waited=$((waited + 1))
  done
  kill -KILL "$pid"
  wait "$pid"
  status=$?
  echo "  exit status $status"
  expect_status 137
  [ ! -e report.json ] || fail "a killed run wrote a report"
  waited=0
  while ! grep -q "^device: force zero\|a second after the controller" device.log 2>/dev/null && [ "$waited" -lt 100 ]; do
    sleep 0.05
    waited=$((waited + 1))
  done
  sed 's/^/  device.log: /' device.log
  grep -q "the controller's process is gone" device.log || fail "the device did not notice its controller was gone"
  zero_ms=$(sed -n 's/^device: force zero \([0-9.]*\) ms after.*/\1/p' device.log)
  [ -n "$zero_ms" ] || fail "the device did not zero the force after the kill"
  [ -n "$zero_ms" ] && at_most "$zero_ms" 40 "the time from the kill to zero force at the device (ms)"
  resume_matches_reference - "SIGKILL"
}

# Garbage on the serial line between exchanges: the driver flushes its input before each query,
# so the bytes are dropped and the job goes on, ungouged.
case_fault_serial_garbage_is_flushed() {
  run_sim "${fault_job[@]}" --inject serial-garbage@40 --report report.json --stock-csv ./stock.csv
  expect_status 0
  no_gouge
  grep -q '"kind": "serial-garbage"' report.json || fail "the report does not name the injected fault"
  if [ -s "$shared/reference.csv" ]; then
    stock_within stock.csv "$shared/reference.csv" 0.01 "serial-garbage"
  else
    fail "no reference stock (the reference_job case runs first)"
  fi
}

# The journal's disk fills mid-cut (a 60 kB tmpfs: about five seconds of journal): the cut stops
# in the safe state journal_failed and the report says why. Needs mount (root); skipped otherwise.
case_fault_disk_full_for_the_journal() {
  mkdir -p tiny
  if ! mount -t tmpfs -o size=60k tmpfs tiny 2>/dev/null; then
    echo "cannot mount a tmpfs here: skipped"
    exit 77
  fi
  run_sim --fast --pattern raster --duration 20 --journal tiny/job.journal --report report.json
  umount tiny
  expect_status 3
  grep -q '"safe_state": "journal_failed"' report.json || fail "the run ended in $(grep '"safe_state"' report.json); expected journal_failed"
  grep -q 'tiny/job.journal: write failed: No space left on device' report.json ||
    fail "the report does not say the journal's disk is full"
  grep -q 'journal: tiny/job.journal: write failed: No space left on device' stdout.txt ||
    fail "the summary does not say the journal's disk is full"
  at_most "$(json_number report.json max_depth_mm)" 0.005 "the deepest gouge (mm)"
}

case_refuses_a_bad_inject() {
  run_sim --fast --pattern raster --inject lightning@3
  expect_status 2
  expect_stderr "--inject lightning@3: expected KIND@SECONDS, KIND one of device-frozen" "the option and its kinds"
  run_sim --speed 1 --pattern raster --inject pose-nan@3
  expect_status 2
  expect_stderr "--inject: faults are injected on the virtual clock" "where faults can be injected"
}

case_refuses_a_bad_display_option() {
  run_sim --fast --pattern raster --duration 1 --hmi 0.0.0.0:8080
  expect_status 2
  expect_stderr "--hmi 0.0.0.0: listening beyond loopback needs --hmi-token-file FILE" "that a token is needed"
  run_sim --fast --pattern raster --duration 1 --hmi 127.0.0.1
  expect_status 2
  expect_stderr "expected HOST:PORT" "the form expected"
  run_sim --fast --pattern raster --duration 1 --hmi-token-file token
  expect_status 2
  expect_stderr "--hmi-token-file and --hmi-assets go with --hmi" "the option it needs"
  run_sim --fast --pattern raster --duration 1 --hmi 127.0.0.1:0 --display-socket "$PWD/display.sock"
  expect_status 2
  expect_stderr "--hmi makes a socket of its own" "that the two do not go together"
  # A token others may read is refused by the display, and the job does not start.
  echo "s3cret-token" >token
  chmod 644 token
  run_sim --fast --pattern raster --duration 1 --no-journal --hmi 127.0.0.1:0 --hmi-token-file "$PWD/token"
  expect_status 2
  expect_stderr "mode 0644 lets others read it; chmod 600" "why the token file is refused"
  expect_stderr "stencil-display did not start" "that the display did not start"
  chmod 600 token
  echo "short" >token
  run_sim --fast --pattern raster --duration 1 --no-journal --hmi 127.0.0.1:0 --hmi-token-file "$PWD/token"
  expect_status 2
  expect_stderr "the token: at least 8 characters" "the token's rule"
  run_sim --fast --pattern raster --duration 1 --no-journal --hmi 127.0.0.1:0 --hmi-assets "$PWD/no-page"
  expect_status 2
  expect_stderr "the display's page is not built: no .*no-page/index.html" "that the page is missing"
  : >part.stbl
  run_rig --tables part.stbl --serial /dev/ttyS0 --haptic pio:/dev/uio0 --hmi 0.0.0.0:8080
  expect_status 2
  expect_stderr "listening beyond loopback needs --hmi-token-file" "that a token is needed (the rig, before it opens anything)"
}

case_refuses_a_bad_operator_csv() {
  printf 't_s,x_mm,y_mm,z_mm\n0,250,125,200\n0.5,250,abc,200\n' >operator.csv
  run_sim --fast --operator operator.csv --report report.json
  expect_status 2
  expect_stderr "operator.csv: line 3: field 3 'abc' is not a finite number" "the file, line and field"
  [ ! -e report.json ] || fail "a report was written for bad input"
}

case_refuses_a_row_of_the_wrong_length_an_empty_file_and_a_missing_one() {
  printf '0,250,125,200\n1,250,125\n' >operator.csv
  run_sim --fast --operator operator.csv
  expect_status 2
  expect_stderr "operator.csv: line 2: 3 fields; expected t_s,x_mm,y_mm,z_mm\[,a_rad,b_rad\]" "the line and the fields expected"
  : >empty.csv
  run_sim --fast --operator empty.csv
  expect_status 2
  expect_stderr "empty.csv: no rows; expected t_s,x_mm,y_mm,z_mm" "that the file has no rows"
  run_sim --fast --operator missing.csv
  expect_status 2
  expect_stderr "missing.csv: cannot be read" "the missing file"
}

case_refuses_outputs_it_cannot_write_before_running() {
  run_sim --fast --report no-such-folder/report.json
  expect_status 2
  expect_stderr "no-such-folder/report.json: cannot be written" "the report path"
  run_sim --fast --trace no-such-folder/trace.csv
  expect_status 2
  expect_stderr "no-such-folder/trace.csv: cannot be written" "the trace path"
}

case_refuses_times_that_do_not_increase() {
  printf '0,250,125,200\n1,250,125,190\n1,250,125,180\n' >operator.csv
  run_sim --fast --operator operator.csv
  expect_status 2
  expect_stderr "operator.csv: line 3: t_s 1.0+ does not increase" "the line whose time goes back"
}

case_refuses_a_bad_stock() {
  run_sim --fast --stock 1,2,3
  expect_status 2
  expect_stderr "--stock 1,2,3: 3 numbers; expected X0,Y0,Z0,X1,Y1,Z1" "the option and what it expects"
  run_sim --fast --stock 10,10,0,5,20,x7
  expect_status 2
  expect_stderr "--stock 10,10,0,5,20,x7: 'x7' is not a number" "the field that is not a number"
  run_sim --fast --stock 10,10,0,5,20,7
  expect_status 2
  expect_stderr "--stock 10,10,0,5,20,7: axis x must have 0 <= low < high" "the axis at fault"
}

case_refuses_a_file_that_is_not_a_table() {
  printf 'not a table\n' >junk.stbl
  run_sim --fast --tables junk.stbl
  expect_status 2
  expect_stderr "junk.stbl: not a valid table" "the file and that it is not a table"
  run_sim --fast --tables missing.stbl
  expect_status 2
  expect_stderr "missing.stbl: cannot be read" "the missing file"
  # A folder given as the table: an error naming it (the program once aborted on an uncaught
  # exception from reading it).
  mkdir -p a_folder
  run_sim --fast --tables a_folder
  expect_status 2
  expect_stderr "a_folder: cannot be read" "the folder"
}

case_refuses_an_unknown_pattern() {
  run_sim --fast --pattern spiral
  expect_status 2
  expect_stderr "spiral" "the pattern it does not know"
}

# The rig's configuration file: each bad file refused with the file, the line and the key (or both
# numbers), exit status 2, before anything is opened (nothing printed about the tables, the host or
# the devices: each of those prints a line once it is looked at).
config_with() {  # KEY LINE: the example with the line starting "KEY =" replaced ("" removes it)
  awk -v key="$1" -v line="$2" 'index($0, key " =") == 1 && !done { done = 1; if (line != "") print line; next } { print }' \
    "$repo/board/sherline_suzuki/rig.toml" >rig.toml
  chmod 600 rig.toml
}
refused_config() {  # PATTERN WHAT [ARGS...]
  local pattern=$1 what=$2
  shift 2
  run_rig --config rig.toml --tables part.stbl "$@"
  expect_status 2
  expect_stderr "$pattern" "$what"
  [ ! -s stdout.txt ] || fail "$what: something ran before the refusal: $(head -n 1 stdout.txt)"
}
case_rig_refuses_a_bad_configuration() {
  mkdir -p parts && "$(dirname "$sim")/stencil-sample-parts" parts >/dev/null || fail "stencil-sample-parts failed"
  "$(dirname "$sim")/stencil-tablegen" parts/hex_prism.stl -o part.stbl --tool ball:d=3 --quiet 2>/dev/null ||
    fail "stencil-tablegen failed"
  config_with serial_port "serial_port = \"$PWD/file_port\""
  cp rig.toml good.toml
  config_with serial_baud $'serial_baud = 57600\nsteps_per_inch = 16000'
  local line
  line=$(grep -n '^steps_per_inch =' rig.toml | cut -d: -f1)
  refused_config "rig.toml:$line: unknown key 'machine.steps_per_inch'" "the unknown key with its line"
  config_with update_hz "update_hz = 0.5"
  refused_config "rig.toml:[0-9]+: machine.update_hz: 0.5 is out of range: expected a number from 1 to 200" "the range"
  config_with force_limit_n "force_limit_n = 50.0"
  refused_config "rig.toml:[0-9]+: haptic.force_limit_n: 50 is out of range: expected a number from 0.5 to 5 \(N, at most the board's 5 N" \
    "the force ceiling no file raises"
  config_with serial_port ""
  refused_config "rig.toml:$(grep -n '^\[machine\]' rig.toml | cut -d: -f1): \[machine\]: missing the key 'machine.serial_port'" \
    "the missing serial port, at its section's line"
  install -m 666 good.toml rig.toml
  refused_config "rig.toml: writable by other users \(mode 0666\)" "the world-writable file"
  install -m 600 good.toml rig.toml && sed -i 's/^travel_mm = \[50.0, 25.0, 25.0\]/travel_mm = [20.0, 25.0, 25.0]/' rig.toml
  grep -q "^travel_mm = \[20.0" rig.toml || fail "the travel could not be set"
  refused_config "part.stbl: the part spans x [0-9.]+ to [0-9.]+ mm; the configured travel reaches x 30 to 50 mm" \
    "the part outside the configured travel, both numbers"
  install -m 600 good.toml rig.toml && : >not_a_tty
  run_rig --config rig.toml --tables part.stbl
  expect_status 3
  expect_stderr "the mill's CY545: .*file_port" "the file's serial port, opened once everything was checked"
  run_rig --config rig.toml --tables part.stbl --serial not_a_tty
  expect_status 3
  expect_stderr "not_a_tty: not a serial port" "the command line's port over the file's"
}

# The shipped example configuration is the compiled-in rig: the same job gives the same report with
# it as without it (wall-clock fields aside). make demo's whole job is compared by hand (README).
case_example_configuration_gives_the_same_report() {
  install -m 600 "$repo/board/sherline_suzuki/rig.toml" rig.toml
  run_sim --fast --pattern random --seed 3 --duration 60 --no-journal --report defaults.json
  expect_status 0
  run_sim --fast --pattern random --seed 3 --duration 60 --no-journal --report configured.json --config rig.toml
  expect_status 0
  if ! diff <(strip_wall_clock defaults.json) <(strip_wall_clock configured.json); then
    fail "the example configuration gave another report than the compiled-in rig"
  fi
}

# A configuration wrong against the simulated mill: X's motor direction the other way round is stopped
# by homing (the job never starts, nothing is cut) and by commissioning; an axis sign (which way the
# table moves under the tool, no matter to homing) is found by commissioning's indicator; steps per mm
# 1 % off by its measured move, which says what the file should say.
case_commissioning_finds_a_wrong_sign_and_wrong_steps() {
  install -m 600 "$repo/board/sherline_suzuki/rig.toml" rig.toml
  sed 's/^step_direction = \[1, 1, 1\]/step_direction = [-1, 1, 1]/' rig.toml >direction.toml
  sed 's/^axis_sign = \[-1, -1, -1\]/axis_sign = [1, -1, -1]/' rig.toml >sign.toml
  sed -e 's/^steps_per_mm = \[640.0, 640.0, 640.0\]/steps_per_mm = [646.4, 646.4, 646.4]/' \
    -e 's/^backlash_mm = [^#]*/backlash_mm = [0.12376237623762376, 0.0495049504950495, 0.12376237623762376] /' rig.toml >steps.toml
  chmod 600 direction.toml sign.toml steps.toml
  grep -q "^step_direction = \[-1, 1, 1\]" direction.toml && grep -q "^axis_sign = \[1, -1, -1\]" sign.toml &&
    grep -q "^steps_per_mm = \[646.4" steps.toml || fail "the mill's truth could not be written"
  run_sim --commission --config rig.toml
  expect_status 0
  grep -q "commissioning: passed" stdout.txt || fail "the example configuration did not pass on its own mill"
  run_sim --commission --config rig.toml --mill-truth direction.toml
  expect_status 3
  grep -q "homing axis X: no home switch within [0-9]* steps of travel moving -: check its step direction" stdout.txt ||
    fail "commissioning did not name the step direction"
  grep -q "axis X moved" stdout.txt && fail "an axis was jogged after homing failed"
  run_sim --fast --pattern raster --config rig.toml --mill-truth direction.toml --no-journal --report job.json
  expect_status 3
  expect_stderr "the machine did not start: homing axis X: .*check its step direction" "that homing stopped the job"
  [ ! -e job.json ] || fail "a job that never started wrote a report"
  run_sim --commission --config rig.toml --mill-truth sign.toml
  expect_status 3
  grep -q "axis X: moved +5.000 mm along the part's axis for -5.000 commanded: it runs the other way (or not at all); check machine.axis_sign" stdout.txt ||
    fail "commissioning did not find the axis sign"
  run_sim --commission --config rig.toml --mill-truth steps.toml
  expect_status 3
  grep -q "axis X: moved 4.950 mm for 5.000 mm commanded (-1.00 %): machine.steps_per_mm would be 646.46; the file says 640" stdout.txt ||
    fail "commissioning did not find the steps per mm 1 % off"
}

# Every program says what built it: the source's version from git at build time, the compiler, its flags.
case_every_program_says_its_version() {
  local program
  for program in stencil-sim stencil-rig stencil-display stencil-tablegen stencil-sample-parts; do
    [ -x "$(dirname "$sim")/$program" ] || continue  # stencil-display needs the page's build (Node.js)
    run "$(dirname "$sim")/$program" --version
    expect_status 0
    head -n 1 stdout.txt | grep -Eq "^$program [^ ]+" || fail "$program --version: no version line"
    grep -q "^built with GNU [0-9.]*: .*-ffp-contract=off" stdout.txt || fail "$program --version: no compiler and flags"
  done
}

# The rig program on a machine without the rig: it checks what it can and says what is missing.
case_rig_without_the_hardware_fails_cleanly() {
  mkdir -p parts && "$(dirname "$sim")/stencil-sample-parts" parts >/dev/null || fail "stencil-sample-parts failed"
  "$(dirname "$sim")/stencil-tablegen" parts/hex_prism.stl -o part.stbl --tool ball:d=3 --quiet 2>/dev/null ||
    fail "stencil-tablegen failed"
  : >not_a_tty
  run_rig --tables part.stbl --serial not_a_tty --haptic pio:/dev/uio-missing
  expect_status 3
  expect_stderr "the mill's CY545: .*not_a_tty: not a serial port" "that the serial port is not a tty"
  grep -q "real-time readiness:" stdout.txt || fail "the real-time readiness was not printed"
  grep -q "PREEMPT_RT kernel:" stdout.txt || fail "PREEMPT_RT was not reported"
  run_rig --tables part.stbl --serial missing-port --haptic can:can0
  expect_status 3
  expect_stderr "missing-port" "the missing serial port by name"
  run_rig --tables part.stbl --serial /dev/ttyS0 --haptic pio:
  expect_status 2
  expect_stderr "--haptic pio:: expected pio:/dev/uioN or can:IFACE" "an empty device path"
  run_rig --tables part.stbl --serial /dev/ttyS0 --haptic usb:0
  expect_status 2
  expect_stderr "--haptic usb:0: expected pio:/dev/uioN or can:IFACE" "the option and what it expects"
  run_rig --tables missing.stbl --serial /dev/ttyS0 --haptic can:can0
  expect_status 2
  expect_stderr "missing.stbl: cannot be read" "the missing table"
  run_rig --serial /dev/ttyS0 --haptic can:can0
  expect_status 2
  expect_stderr "--tables" "the missing option"
  run_rig --tables part.stbl --serial /dev/ttyS0 --haptic can:can0 --work-offset 50,25
  expect_status 2
  expect_stderr "--work-offset 50,25: expected X,Y,Z in mm" "the work offset and what it expects"
  run_rig --tables part.stbl --serial /dev/ttyS0 --haptic can:can0 --stock 0,0,0,50,25,abc
  expect_status 2
  expect_stderr "--stock 0,0,0,50,25,abc: expected X0,Y0,Z0,X1,Y1,Z1" "the stock and what it expects"
  run_rig --tables part.stbl --serial /dev/ttyS0 --haptic can:can0 --stock 0,0,0,10000,25,5
  expect_status 2
  expect_stderr "inside the workspace \[0,50\]x\[0,25\]x\[0,25\]" "that the stock must fit the workspace"
  run_rig --tables part.stbl --serial /dev/ttyS0 --haptic can:can0 --tool-stick-out nan
  expect_status 2
  expect_stderr "--tool-stick-out and --reference-stick-out: expected a length in mm from 0 to 100" "the stick-out's range"
  run_rig --tables part.stbl --serial /dev/ttyS0 --haptic can:can0 --report /nonexistent/rig.json
  expect_status 2
  expect_stderr "/nonexistent/rig.json: cannot be written" "the report that cannot be written, before anything opens"
}

# Job folders (issue 25): a job and its --resume write in one folder of their own, under
# $XDG_STATE_HOME/stencil/jobs by default, and nothing in the current folder; `latest` is that folder.
short_job=(--fast --pattern plunge --duration 2)
case_job_and_its_resume_share_one_folder() {
  run_sim "${short_job[@]}" --inject pose-jump@1
  expect_status 3
  local folder
  folder=$(sed -n 's/^job folder: //p' stdout.txt)
  echo "$folder" | grep -Eq "^$XDG_STATE_HOME/stencil/jobs/stencil-sim-[0-9]{8}-[0-9]{6}\$" ||
    fail "the job's folder is '$folder'; expected \$XDG_STATE_HOME/stencil/jobs/stencil-sim-YYYYMMDD-HHMMSS"
  [ "$(readlink "$XDG_STATE_HOME/stencil/jobs/latest")" = "$(basename "$folder")" ] || fail "latest does not point at $folder"
  run_sim "${short_job[@]}" --resume "$XDG_STATE_HOME/stencil/jobs/latest/job.journal"
  expect_status 0
  grep -q "^report: $XDG_STATE_HOME/stencil/jobs/latest/report-resume-1.json" stdout.txt ||
    fail "the resume's report is not report-resume-1.json in the job's folder"
  local file
  for file in job.journal report.json report-resume-1.json; do
    [ -s "$folder/$file" ] || fail "$folder has no $file"
  done
  [ "$(find "$folder" -name 'report-resume-1.*' ! -name '*.json' | wc -l)" = 1 ] || fail "no picture beside report-resume-1.json"
  [ "$(json_number "$folder/report-resume-1.json" runs)" = 2 ] || fail "the resume's report does not cover both runs"
  [ "$(find "$XDG_STATE_HOME/stencil/jobs" -mindepth 1 -maxdepth 1 | wc -l)" = 2 ] || fail "more than one job's folder and latest"
  local here
  here=$(ls -A | grep -v -x -e stdout.txt -e stderr.txt -e xdg-state)
  [ -z "$here" ] || fail "the jobs wrote in the current folder: $here"
}

# Retention (--keep-jobs 2, this job counted): the oldest finished job is removed as a new one
# starts, and a killed one (its journal has no End: it may be resumed) is kept, each said.
case_retention_keeps_an_interrupted_job() {
  local kept=(--out-dir jobs --keep-jobs 2) first interrupted second
  run_sim "${short_job[@]}" "${kept[@]}"
  expect_status 0
  first=$(sed -n 's/^job folder: //p' stdout.txt)
  echo "\$ stencil-sim --speed 5 --pattern raster --duration 600 ${kept[*]}  (SIGKILL once its journal is open)"
  "$sim" --speed 5 --pattern raster --duration 600 "${kept[@]}" >killed.txt 2>&1 &
  local pid=$! waited=0
  while ! grep -q '^journal: ' killed.txt 2>/dev/null && [ "$waited" -lt 600 ]; do
    sleep 0.05
    waited=$((waited + 1))
  done
  kill -KILL "$pid"
  wait "$pid"
  interrupted=$(sed -n 's/^job folder: //p' killed.txt)
  [ -n "$interrupted" ] || fail "the killed job said no folder: $(cat killed.txt)"
  run_sim "${short_job[@]}" "${kept[@]}"
  expect_status 0
  second=$(sed -n 's/^job folder: //p' stdout.txt)
  grep -q "^jobs: removed $first (finished, [0-9.]* MB)\$" stdout.txt || fail "the third job did not say it removed $first"
  [ ! -e "$first" ] || fail "the oldest finished job $first is still there"
  run_sim "${short_job[@]}" "${kept[@]}"
  expect_status 0
  grep -q "^jobs: kept $interrupted: interrupted, may be resumed\$" stdout.txt || fail "the fourth job did not say it kept $interrupted"
  [ -s "$interrupted/job.journal" ] || fail "the interrupted job $interrupted was removed"
  [ -s "$second/report.json" ] || fail "the newest finished job but this one, $second, was removed"
  [ "$(readlink jobs/latest)" = "$(sed -n 's/^job folder: jobs\///p' stdout.txt)" ] || fail "latest is not the newest job"
}

# A jobs folder that cannot be made or written in is refused before the job starts (exit 2), naming
# the folder and why, whether --out-dir or $XDG_STATE_HOME gives it; no job ran, no report anywhere.
case_refuses_an_out_dir_it_cannot_write() {
  : >a_file
  run_sim "${short_job[@]}" --out-dir a_file/jobs
  expect_status 2
  expect_stderr "--out-dir: a_file/jobs: the jobs folder cannot be created: Not a directory" "the folder and why"
  ! grep -q "^stencil-sim: the baked-in" stdout.txt || fail "the job started"
  XDG_STATE_HOME="$PWD/a_file" run_sim "${short_job[@]}"
  expect_status 2
  expect_stderr "$PWD/a_file/stencil/jobs: the jobs folder cannot be created: Not a directory" "the default folder and why"
  [ -z "$(find . -name '*.json' -o -name '*.journal')" ] || fail "a refused job left a report or a journal"
  run_sim "${short_job[@]}" --resume job.journal --out-dir jobs
  expect_status 2
  expect_stderr "--out-dir: a --resume or a --replay writes in its journal's folder" "that --out-dir has no place in a resume"
}

if ! declare -F "case_$case_name" >/dev/null; then
  echo "sim_cli.sh: no case '$case_name'" >&2
  exit 2
fi
work="$work_root/sim_$case_name"
rm -rf "$work" && mkdir -p "$work" && cd "$work" || exit 1
# Jobs with no --out-dir make their folders under $XDG_STATE_HOME/stencil/jobs: the case's own.
export XDG_STATE_HOME="$work/xdg-state"
"case_$case_name"
if [ "$failures" -gt 0 ]; then
  echo "$failures failure(s); the case's files are in $work" >&2
  exit 1
fi
if [ "${SIM_CLI_KEEP:-0}" != 1 ]; then
  cd / && rm -rf "$work"
fi
exit 0
