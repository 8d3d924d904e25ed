#!/usr/bin/env bash
# ci-background.sh pause|resume: .ci/run's build beside the tests (a session of its own, its id in the
# file STENCIL_CI_BACKGROUND names), stopped with SIGSTOP and let go with SIGCONT, every process of
# that session (ninja and the compilers it runs). The cases that measure the controller's memory and
# pace under load (the display's browser cases, RUN_SERIAL) hold the machine quiet this way:
# with a build on both cores beside it, e2e.hmi_attack's controller grew its peak memory by 2 to 3 MB.
# Nothing to do outside CI (no STENCIL_CI_BACKGROUND, or no such session any more).
set -uo pipefail
file=${STENCIL_CI_BACKGROUND:-}
[ -n "$file" ] && [ -s "$file" ] || exit 0
session=$(cat "$file")
case "$1" in
  pause) pkill -STOP -s "$session" 2> /dev/null ;;
  resume) pkill -CONT -s "$session" 2> /dev/null ;;
  *) echo "usage: $0 pause|resume" >&2; exit 2 ;;
esac
exit 0
