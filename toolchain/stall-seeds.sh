#!/usr/bin/env bash
# The mill-follows measurement: the random operator on the built-in part for HOURS simulated hours,
# once per seed 1..SEEDS, JOBS at a time (--fast: each run is deterministic). A measurement, not a
# test: it prints a line per seed and a summary, and fails (exit 1) if any run stalled, ended in
# any other safe state, or gouged deeper than 0.005 mm (the mill's ground truth).
#
# usage: stall-seeds.sh STENCIL_SIM OUT_DIR SEEDS HOURS JOBS
# Only bash, coreutils, grep, sed, awk and xargs.
set -uo pipefail

if [ "$#" -ne 5 ]; then
  echo "usage: $0 STENCIL_SIM OUT_DIR SEEDS HOURS JOBS" >&2
  exit 2
fi
sim=$(realpath "$1") out=$2 seeds=$3 hours=$4 jobs=$5
mkdir -p "$out" && cd "$out" || exit 2
total_s=$(awk -v h="$hours" 'BEGIN { printf "%d", h * 3600 }')
moves=$(awk -v h="$hours" 'BEGIN { printf "%d", h * 300 }')  # 600 moves outlast 2 hours

echo "stall-seeds: seeds 1-$seeds, $hours simulated h each ($total_s s, $moves moves), $jobs at a time, in $out"
export sim total_s moves
seq 1 "$seeds" | xargs -P "$jobs" -I{} bash -c \
  '"$sim" --fast --pattern random --seed {} --moves "$moves" --duration "$total_s" --no-journal \
     --report seed-{}.json > seed-{}.txt 2>&1; echo $? > seed-{}.rc'

json_number() { grep -E "\"$2\": " "$1" | head -n 1 | sed -E 's/.*": ([-0-9.eE+]+|null).*/\1/'; }
printf '%-5s %11s %-14s %9s %11s %12s %s\n' seed simulated_s safe_state gouge_mm unmachined coverage error
failures=0 stalls=0 worst=0
for seed in $(seq 1 "$seeds"); do
  r=seed-$seed.json
  if [ ! -s "$r" ]; then
    echo "$seed: no report (exit $(cat "seed-$seed.rc" 2>/dev/null)); see $out/seed-$seed.txt"
    failures=$((failures + 1))
    continue
  fi
  simulated=$(json_number "$r" simulated_s)
  safe=$(grep -E '"safe_state": ' "$r" | head -n 1 | sed -E 's/.*": "?([^",]*)"?,?$/\1/')
  [ "$safe" = null ] && safe=none  # the report's null: the job ended in no safe state
  gouge=$(grep -A3 '"gouge"' "$r" | json_number /dev/stdin max_depth_mm)
  unmachined=$(grep -A3 '"unmachined"' "$r" | json_number /dev/stdin fraction)
  coverage=$(json_number "$r" coverage_fraction)
  error=$(grep -E '"error": "' "$r" | head -n 1 | sed -E 's/.*"error": "([^"]*)".*/\1/')
  printf '%-5s %11.1f %-14s %9.6f %10.2f%% %11.1f%% %s\n' "$seed" "$simulated" "$safe" "$gouge" \
    "$(awk -v f="$unmachined" 'BEGIN { print 100 * f }')" "$(awk -v f="$coverage" 'BEGIN { print 100 * f }')" "$error"
  case $error in *stalled*) stalls=$((stalls + 1)) ;; esac
  [ "$safe" != none ] && failures=$((failures + 1))
  awk -v g="$gouge" 'BEGIN { exit !(g > 0.005) }' && failures=$((failures + 1))
  worst=$(awk -v g="$gouge" -v w="$worst" 'BEGIN { print (g > w ? g : w) }')
done
echo "stall-seeds: $stalls stalled of $seeds; deepest gouge $worst mm; $failures runs failed"
[ "$failures" -eq 0 ]
