#!/usr/bin/env bash
# make latency: the cycle's wake-up latency on this host, beside cyclictest's in the same conditions.
# Two consecutive phases of LATENCY_SECONDS (60) each, with stress-ng loading CPU 0 throughout:
# cyclictest on CPU 1 at the cycle's priority and period, then stencil-sim in real time with its
# cycle pinned to CPU 1. Prints both latencies (p99, p99.9, max, us), their ratio, and the sim's
# safe state. A measurement, not a test: it needs root (or CAP_SYS_NICE) for SCHED_FIFO.
set -euo pipefail
cd "$(dirname "$0")/.."

seconds=${LATENCY_SECONDS:-60}
priority=80
sim=build/bin/stencil-sim
out=build/latency
mkdir -p "$out"
for tool in cyclictest stress-ng; do
  command -v "$tool" >/dev/null || { echo "latency: $tool is missing (bash toolchain/install-deps.sh --latency)" >&2; exit 1; }
done
[ -x "$sim" ] || { echo "latency: $sim is missing (make build)" >&2; exit 1; }

stress-ng --cpu 1 --taskset 0 --timeout $((2 * seconds + 30))s --quiet &
stress=$!
trap 'kill $stress 2>/dev/null || true' EXIT
sleep 2

echo "latency: cyclictest, ${seconds} s on CPU 1 at SCHED_FIFO $priority, 1 ms period, stress-ng on CPU 0"
cyclictest --mlockall --priority=$priority --interval=1000 --affinity=1 --threads=1 --duration=${seconds}s \
  --histogram=10000 --quiet >"$out/cyclictest.txt"

echo "latency: stencil-sim --speed 1, ${seconds} s, cycle on CPU 1 at SCHED_FIFO $priority"
set +e
"$sim" --speed 1 --cpu 1 --priority $priority --pattern raster --duration "$seconds" --report "$out/sim-report.json" \
  >"$out/sim.txt" 2>&1
sim_status=$?
set -e

# cyclictest's histogram: "us count" rows, then "# Max Latencies: N".
read -r c_p99 c_p999 c_max < <(awk '
  /^[0-9]/ { n[$1 + 0] = $2; total += $2 }
  /^# Max Latencies:/ { max = $4 + 0 }
  END {
    seen = 0; p99 = -1; p999 = -1
    for (us = 0; us < 10000; ++us) {
      seen += n[us]
      if (p99 < 0 && seen >= 0.99 * total) p99 = us
      if (p999 < 0 && seen >= 0.999 * total) p999 = us
    }
    print p99, p999, max
  }' "$out/cyclictest.txt")
json() { grep -A5 "\"$1\"" "$out/sim-report.json" | grep "\"$2\"" | head -n 1 | sed -E 's/.*: ([-0-9.eE+]+|null).*/\1/'; }
s_p99=$(json wakeup_latency_us p99)
s_p999=$(json wakeup_latency_us p999)
s_max=$(json wakeup_latency_us max)
safe=$(grep '"safe_state"' "$out/sim-report.json" | sed -E 's/.*: //; s/,$//')
ratio() { awk -v a="$1" -v b="$2" 'BEGIN { printf (b > 0 ? "%.2f" : "n/a"), (b > 0 ? a / b : 0) }'; }
printf '\n%-22s %10s %10s %10s\n' "wake-up latency (us)" p99 p99.9 max
printf '%-22s %10s %10s %10s\n' cyclictest "$c_p99" "$c_p999" "$c_max"
printf '%-22s %10s %10s %10s\n' stencil-sim "$s_p99" "$s_p999" "$s_max"
printf '%-22s %10s %10s %10s\n' "ratio sim/cyclictest" "$(ratio "$s_p99" "$c_p99")" "$(ratio "$s_p999" "$c_p999")" \
  "$(ratio "$s_max" "$c_max")"
top_level() { grep -E "^  \"$1\": " "$out/sim-report.json" | head -n 1 | sed -E 's/.*: ([0-9]+).*/\1/'; }
echo "stencil-sim: $(top_level overruns) overruns, $(top_level missed_periods) periods skipped after a late wake-up"
echo "stencil-sim safe_state: $safe (exit status $sim_status); files in $out/"
