#!/usr/bin/env bash
# tests/ mirrors the source, checked rather than hoped for: every source file (each .cpp, and each
# .hpp with no .cpp of the same name, under firmware/ hal/ sim/ board/ toolchain/) has its suite at
# the mirrored path, or a line in tests/UNTESTED.md saying why not. A newcomer who changes
# hal/socketcan/fd_can_channel.cpp finds tests/hal/socketcan/fd_can_channel_tests.cpp.
#
# The mirror: firmware/core/AREA/NAME.cpp      -> tests/AREA/NAME_tests.cpp
#             firmware/services/AREA/NAME.cpp  -> tests/AREA/NAME_tests.cpp
#             firmware/runtime|programs/NAME   -> tests/runtime|programs/NAME_tests.cpp
#             toolchain/AREA/NAME.cpp          -> tests/AREA/NAME_tests.cpp
#             hal/ sim/ board/ PATH/NAME.cpp   -> tests/hal|sim|board/PATH/NAME_tests.cpp
# (the core's and the services' areas are named apart, so the shorter paths do not collide.)
# More suites for one file are NAME_ASPECT_tests.cpp beside it.
#
# tests/UNTESTED.md lines read "- `SOURCE`: why" (a reason is required). A line for a file that has
# its suite, or for a file that no longer exists, is an error too: the list stays true.
#
# usage: test-mirror.sh [REPO_ROOT]   prints each problem; exit 0 none, 1 some.
set -uo pipefail
root=${1:-$(cd "$(dirname "$0")/.." && pwd)}
cd "$root" || exit 2
untested=tests/UNTESTED.md

mirror() {  # source path -> its suite's path
  local dir base
  dir=$(dirname "$1")
  base=$(basename "$1")
  base=${base%.*}
  case $dir in
    firmware/core/* | firmware/services/*) dir=${dir#firmware/*/} ;;
    firmware/*) dir=${dir#firmware/} ;;
    toolchain/*) dir=${dir#toolchain/} ;;
  esac
  echo "tests/$dir/${base}_tests.cpp"
}

sources() {
  local top
  for top in firmware hal sim board toolchain; do
    [ -d "$top" ] || continue
    find "$top" -type f -name '*.cpp' -not -path '*/node_modules/*'
    find "$top" -type f -name '*.hpp' -not -path '*/node_modules/*' | while IFS= read -r h; do
      [ -f "${h%.hpp}.cpp" ] || echo "$h"
    done
  done | sort
}

declare -A excused=()
if [ -f "$untested" ]; then
  while IFS= read -r line; do
    if [[ $line =~ ^-\ \`([^\`]+)\`:[[:space:]]*(.*)$ ]]; then
      path=${BASH_REMATCH[1]}
      reason=${BASH_REMATCH[2]}
      if [ -z "$reason" ]; then
        echo "$untested: \`$path\` gives no reason"
        status=1
      fi
      excused[$path]=1
    fi
  done <"$untested"
fi

status=${status:-0}
count=0
suites=0
while IFS= read -r src; do
  count=$((count + 1))
  suite=$(mirror "$src")
  if [ -f "$suite" ]; then
    suites=$((suites + 1))
    if [ -n "${excused[$src]:-}" ]; then
      echo "$untested: \`$src\` is listed as untested, but $suite exists: remove the line"
      status=1
    fi
  elif [ -z "${excused[$src]:-}" ]; then
    echo "$src: no $suite, and no line in $untested saying why"
    status=1
  fi
  unset "excused[$src]"
done < <(sources)

for src in "${!excused[@]}"; do
  echo "$untested: \`$src\` is not a source file (moved or removed?): remove or correct the line"
  status=1
done

if [ "$status" -eq 0 ]; then
  echo "test-mirror: $count source files: $suites with a mirrored suite, $((count - suites)) in $untested with a reason"
fi
exit "$status"
