#!/usr/bin/env bash
# Runs a suite that needs LinuxCNC's interpreter rs274 (linuxcnc-uspace) but no running LinuxCNC.
# Without rs274 the suite is skipped (exit 77) with a message, unless STENCIL_REQUIRE_LINUXCNC=1 (CI),
# where that fails.
# usage: run_rs274_tests.sh SUITE_EXECUTABLE [SUITE ARGS]
set -uo pipefail
suite="$1"
shift
if ! command -v rs274 >/dev/null 2>&1; then
  if [ "${STENCIL_REQUIRE_LINUXCNC:-0}" = 1 ]; then
    echo "run_rs274_tests: rs274 is not installed, and STENCIL_REQUIRE_LINUXCNC=1 (bash toolchain/install-deps.sh installs linuxcnc-uspace)" >&2
    exit 1
  fi
  echo "run_rs274_tests: skipped: rs274 is not installed (bash toolchain/install-deps.sh installs linuxcnc-uspace)"
  exit 77
fi
exec "$suite" "$@"
