#!/usr/bin/env bash
# The soak: one long simulated job (a random operator in --fast mode) with faults injected at random
# times, each followed by --resume from the journal, until the job is done. A measurement, not a
# test: it prints a line per run and the whole job's figures, and fails (exit 1) if anything is not
# accounted for: a run that did not end as its fault should, a gouge, a leak (under ASan), a report
# that does not cover every run and fault.
#
# usage: soak.sh STENCIL_SIM OUT_DIR HOURS FAULTS SEED
#   HOURS: simulated hours (8 for the issue's soak); FAULTS: how many to inject; SEED: the operator's
#   walk and the faults' kinds and times.
# Only bash, coreutils, grep, sed and awk.
set -uo pipefail

if [ "$#" -ne 5 ]; then
  echo "usage: $0 STENCIL_SIM OUT_DIR HOURS FAULTS SEED" >&2
  exit 2
fi
sim=$(realpath "$1") out=$2 hours=$3 faults=$4 seed=$5
mkdir -p "$out" && cd "$out" || exit 2
rm -f soak.journal run-*.json run-*.png run-*.svg run-*.txt
RANDOM=$seed

total_s=$(awk -v h="$hours" 'BEGIN { printf "%d", h * 3600 }')
moves=$(awk -v h="$hours" 'BEGIN { printf "%d", h * 300 + 50 }')  # 200 moves take about 40 minutes
job=(--fast --pattern random --seed "$seed" --moves "$moves" --duration "$total_s")
gap_s=$((total_s / (faults + 1)))
kinds=(device-frozen pose-nan pose-jump device-fault cy545-silent cy545-garbled serial-closed position-mismatch
  can-bad-frames overrun-storm kill)
declare -A expected=([device-frozen]=device_stale [pose-nan]=pose_not_finite [pose-jump]=pose_jump
  [device-fault]=device_fault [cy545-silent]=machine_fault [cy545-garbled]=machine_fault [serial-closed]=machine_fault
  [position-mismatch]=machine_fault [can-bad-frames]=device_stale [overrun-storm]=overrun_storm)

failures=0
fail() {
  echo "FAIL: $*" >&2
  failures=$((failures + 1))
}
json_number() { grep -E "\"$2\": " "$1" | head -n 1 | sed -E 's/.*": ([-0-9.eE+]+|null).*/\1/'; }
json_string() { grep -E "\"$2\": " "$1" | head -n 1 | sed -E 's/.*": "?([^",]*)"?,?$/\1/'; }

echo "soak: $hours simulated h ($total_s s), random operator (seed $seed, $moves moves), $faults faults, in $out"
printf '%-4s %-18s %-9s %-16s %12s %10s %10s %9s %12s %12s %9s\n' run fault transport ended at_job_s detect_ms stop_ms gouge_mm \
  setup_rss_kb max_rss_kb wall_s
started=$(date +%s.%N)
kills=0 injected=0 unplanned=0 run=0 done=0
most_list=() setup_list=()
while [ "$done" -eq 0 ]; do
  resume=(--journal soak.journal)
  [ "$run" -gt 0 ] && resume=(--resume soak.journal)
  kind=none transport=direct inject=()
  if [ "$run" -lt "$faults" ]; then
    kind=${kinds[$((RANDOM % ${#kinds[@]}))]}
    case $kind in
      can-bad-frames) transport=can ;;
      kill) transport=direct ;;
      *) transport=$(
        t=(direct pio can)
        echo "${t[$((RANDOM % 3))]}"
      ) ;;
    esac
    # Into the run: past the way back to the cut (up to a minute), then anywhere within two gaps.
    at_s=$((60 + (RANDOM * 32768 + RANDOM) % (2 * gap_s)))
    [ "$kind" != kill ] && inject=(--inject "$kind@$at_s")
  fi
  report=run-$run.json
  t0=$(date +%s.%N)
  if [ "$kind" = kill ]; then
    # SIGKILL at a random moment: while it rebuilds the job, or mid-cut.
    "$sim" "${job[@]}" "${resume[@]}" --haptic-transport "$transport" --report "$report" >"run-$run.txt" 2>&1 &
    pid=$!
    # Once its journal is open (the run has its Start or Resume record), at a random moment.
    for _ in $(seq 6000); do
      grep -q '^journal: ' "run-$run.txt" 2>/dev/null && break
      kill -0 "$pid" 2>/dev/null || break
      sleep 0.1
    done
    sleep "$(awk -v r=$RANDOM -v g="$gap_s" 'BEGIN { printf "%.2f", 0.5 + (r / 32768.0) * g / 50.0 }')"
    kill -KILL "$pid" 2>/dev/null
    wait "$pid"
    status=$?
  else
    "$sim" "${job[@]}" "${resume[@]}" --haptic-transport "$transport" "${inject[@]}" --report "$report" >"run-$run.txt" 2>&1
    status=$?
  fi
  wall=$(awk -v a="$t0" -v b="$(date +%s.%N)" 'BEGIN { printf "%.1f", b - a }')
  if grep -q "LeakSanitizer\|AddressSanitizer\|runtime error" "run-$run.txt"; then
    fail "run $run: the sanitizers reported: $(grep -m1 'Sanitizer\|runtime error' "run-$run.txt")"
  fi
  ended=- at=- detect=- stop=- gouge=- setup=- most=-
  if [ "$kind" = kill ] && [ "$status" -eq 137 ]; then
    ended=killed
    kills=$((kills + 1))
    rm -f "$report"
  elif [ -s "$report" ]; then
    ended=$(json_string "$report" safe_state)
    gouge=$(json_number "$report" max_depth_mm)
    setup=$(grep -A3 '"memory_kb"' "$report" | json_number /dev/stdin after_setup)
    most=$(grep -A3 '"memory_kb"' "$report" | json_number /dev/stdin most)
    awk -v g="$gouge" 'BEGIN { exit !(g != "null" && g + 0 <= 0.005) }' || fail "run $run: gouge $gouge mm"
    most_list+=("$most")
    setup_list+=("$setup")
    if [ "$kind" = none ] || [ "$kind" = kill ]; then
      # No fault (or a kill that came too late): it finished, or met a safe state of its own.
      [ "$kind" = kill ] && kind="kill (too late)"
      if [ "$status" -eq 0 ] && [ "$ended" = null ]; then
        done=1
      elif [ "$status" -eq 3 ] && [ "$ended" != null ]; then
        unplanned=$((unplanned + 1))
        ended="$ended (unplanned)"
      else
        fail "run $run ($kind) ended with status $status, safe state $ended"
      fi
    elif [ -z "$(json_number "$report" injected_s)" ]; then
      # The run ended before its fault was due: the job is done, or it met a safe state of its own.
      kind="$kind (not due)"
      if [ "$status" -eq 0 ]; then
        done=1
      elif [ "$ended" != null ]; then
        unplanned=$((unplanned + 1))
        ended="$ended (unplanned)"
      else
        fail "run $run: exit status $status with no safe state"
      fi
    else
      injected=$((injected + 1))
      at=$(awk -v s="$(json_number "$report" total_simulated_s)" -v r="$(json_number "$report" simulated_s)" \
        -v i="$(json_number "$report" injected_s)" 'BEGIN { printf "%.1f", s - r + i }')
      detect=$(awk -v i="$(json_number "$report" injected_s)" -v s="$(json_number "$report" safe_state_s)" 'BEGIN { printf "%.0f", (s - i) * 1000 }')
      stop=$(awk -v s="$(json_number "$report" safe_state_s)" -v m="$(json_number "$report" machine_stopped_s)" 'BEGIN { printf "%.0f", (m - s) * 1000 }')
      [ "$ended" = "${expected[$kind]}" ] || fail "run $run: $kind ended in $ended; expected ${expected[$kind]}"
      [ "$status" -eq 3 ] || fail "run $run: $kind gave exit status $status; expected 3"
      awk -v s="$(json_number "$report" safe_state_s)" -v f="$(json_number "$report" force_zero_s)" 'BEGIN { exit !(f >= s && f - s <= 0.0011) }' ||
        fail "run $run: force zero at $(json_number "$report" force_zero_s) s, the safe state at $(json_number "$report" safe_state_s) s"
    fi
  else
    fail "run $run ($kind): exit status $status and no report"
    break
  fi
  printf '%-4s %-18s %-9s %-16s %12s %10s %10s %9s %12s %12s %9s\n' "$run" "$kind" "$transport" "$ended" "$at" "$detect" "$stop" \
    "$gouge" "$setup" "$most" "$wall"
  run=$((run + 1))
  [ "$run" -gt $((2 * faults + 10)) ] && { fail "the job did not finish after $run runs"; break; }
done

last=run-$((run - 1)).json
wall=$(awk -v a="$started" -v b="$(date +%s.%N)" 'BEGIN { printf "%.0f", b - a }')
echo
echo "the whole job (from the last run's report, $last):"
runs=$(json_number "$last" runs)
safe_states=$(grep -c '"reason": ' "$last")
unrecorded=$(grep -c '"ending": "unrecorded' "$last")
echo "  runs $runs (made $run), simulated $(json_number "$last" total_simulated_s) s in $wall s wall"
echo "  safe states in the report $safe_states (faults injected that reached their run: $injected; safe states of the job's own: $unplanned);" \
  "runs ended unrecorded $unrecorded (kills: $kills)"
echo "  gouge $(json_number "$last" max_depth_mm) mm deepest over the whole job; coverage $(json_number "$last" coverage_fraction);" \
  "max force $(json_number "$last" max_force_n) N"
echo "  journal $(stat -c %s soak.journal) bytes"
[ "$runs" = "$run" ] || fail "the report covers $runs runs; $run were made"
[ "$safe_states" -eq $((injected + unplanned)) ] ||
  fail "the report has $safe_states safe states; $injected faults were injected and $unplanned came of themselves"
[ "$unrecorded" -eq "$kills" ] || fail "the report has $unrecorded runs ended unrecorded; $kills were killed"
# Memory flat: the journal grows with the job, the process must not. No run's memory after setting
# up (the rebuild has read all of the journal so far by then) is more than 20 % over the first run's,
# nor its peak over the first's by more than 20 % and the reader's 16 MB window onto the journal.
first_most=${most_list[0]:-0} first_setup=${setup_list[0]:-0}
for i in "${!most_list[@]}"; do
  awk -v m="${most_list[$i]}" -v f="$first_most" -v s="${setup_list[$i]}" -v g="$first_setup" \
    'BEGIN { exit !(m <= 1.2 * f + 16384 && s <= 1.2 * g) }' ||
    fail "memory grew: a run peaked at ${most_list[$i]} kB (${setup_list[$i]} kB after setup); the first at $first_most kB ($first_setup kB)"
done
echo "  memory: peak per run $(printf '%s ' "${most_list[@]}")kB; after setup $(printf '%s ' "${setup_list[@]}")kB"
if [ "$failures" -gt 0 ]; then
  echo "soak: $failures failure(s)"
  exit 1
fi
echo "soak: every fault accounted for, no gouge"
