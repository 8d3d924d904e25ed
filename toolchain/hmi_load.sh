#!/usr/bin/env bash
# A measurement, not a test: the cycle's loop timing in real time (stencil-sim --speed 1, the cycle
# on CPU CYCLE_CPU (1), SCHED_FIFO as root) without the display, then with it serving a page in
# headless Chromium and STALLED (2) clients that never read (the browser and the clients on CPU
# LOAD_CPU (0), as a display on another machine would be), alternately ROUNDS (2) times, SECONDS
# (30) each; and the frames the page saw.
#   bash toolchain/hmi_load.sh build/bin/stencil-sim build/hmi-npm/node_modules OUT_DIR
set -euo pipefail
sim=$1 modules=$2 out=$3
seconds=${SECONDS_EACH:-30} rounds=${ROUNDS:-2} stalled=${STALLED:-2} cycle_cpu=${CYCLE_CPU:-1} load_cpu=${LOAD_CPU:-0}
mkdir -p "$out"
figures() {  # the report's loop timing
  python3 - "$1" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
w, c = r["wakeup_latency_us"], r["compute_us"]
print(f"{r['simulated_s']:.1f} s, safe state {r['safe_state'] or 'none'}; "
      f"wakeup p99 {w['p99']:.0f} us, p99.9 {w['p999']:.0f} us, max {w['max']:.0f} us; "
      f"compute p99 {c['p99']:.0f} us, max {c['max']:.0f} us; overruns {r['overruns']}")
PY
}
for round in $(seq 1 "$rounds"); do
  "$sim" --speed 1 --cpu "$cycle_cpu" --pattern raster --duration "$seconds" --no-journal --report "$out/plain-$round.json" >"$out/plain-$round.log" 2>&1 || true
  echo "round $round without the display: $(figures "$out/plain-$round.json")"
  port=$((18000 + round))
  "$sim" --speed 1 --cpu "$cycle_cpu" --pattern raster --duration "$seconds" --no-journal --hmi "127.0.0.1:$port" \
    --report "$out/hmi-$round.json" >"$out/hmi-$round.log" 2>&1 &
  pid=$!
  for _ in $(seq 1 100); do grep -q "display:" "$out/hmi-$round.log" && break; sleep 0.1; done
  NODE_PATH=$modules taskset -c "$load_cpu" node "$(dirname "$0")/hmi_load.cjs" "http://127.0.0.1:$port/" $((seconds - 8)) "$stalled" || true
  wait "$pid" || true
  echo "round $round with the display:    $(figures "$out/hmi-$round.json")"
  grep "display: .* frames" "$out/hmi-$round.log" || true
done
