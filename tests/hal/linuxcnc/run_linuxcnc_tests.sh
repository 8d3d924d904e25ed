#!/usr/bin/env bash
# Runs a suite against the real LinuxCNC (ctest label linuxcnc): hands it linuxcnc-sim.sh and a fresh
# instance folder, and stops LinuxCNC afterwards whatever happened. Without LinuxCNC installed the
# suite is skipped (exit 77) with a message, unless STENCIL_REQUIRE_LINUXCNC=1 (CI), where that fails.
# usage: run_linuxcnc_tests.sh SUITE_EXECUTABLE SOURCE_DIR [SUITE ARGS]
set -uo pipefail
suite="$1"
source_dir="$2"
shift 2
if ! command -v linuxcnc >/dev/null 2>&1 || ! command -v linuxcncrsh >/dev/null 2>&1; then
  if [ "${STENCIL_REQUIRE_LINUXCNC:-0}" = 1 ]; then
    echo "run_linuxcnc_tests: LinuxCNC is not installed, and STENCIL_REQUIRE_LINUXCNC=1 (bash toolchain/install-deps.sh installs linuxcnc-uspace)" >&2
    exit 1
  fi
  echo "run_linuxcnc_tests: skipped: LinuxCNC is not installed (bash toolchain/install-deps.sh installs linuxcnc-uspace)"
  exit 77
fi
export LCNC_SIM="$source_dir/sim/linuxcnc_mill/linuxcnc-sim.sh"
LCNC_DIR="$(mktemp -d /tmp/stencil-linuxcnc.XXXXXX)"
export LCNC_DIR
chmod 755 "$LCNC_DIR"
cleanup() { bash "$LCNC_SIM" stop "$LCNC_DIR" >/dev/null 2>&1; }
trap cleanup EXIT
"$suite" "$@"
status=$?
if [ "$status" -ne 0 ]; then
  echo "run_linuxcnc_tests: the suite failed; linuxcnc-sim.sh's log ($LCNC_DIR.log) ends:" >&2
  tail -n 40 "$LCNC_DIR.log" >&2 2>/dev/null
  tail -n 40 "$LCNC_DIR/linuxcnc.log" >&2 2>/dev/null
fi
exit "$status"
