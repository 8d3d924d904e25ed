#!/usr/bin/env bash
# make size-check: function sizes checked by a tool, not by eye. clang-tidy's
# readability-function-size (Debian's clang-tidy, only that check) counts each function's lines,
# body and comments included, lambdas counted in the function that holds them; a function fails when
# it has more lines than its limit:
#   - a program's main() (firmware/programs/*_main.cpp):           at most MAIN_LIMIT (150) lines;
#   - every other function in those files, the runtime's and the boards' (firmware/runtime/*.cpp,
#     board/*/*.cpp, the programs' other files): at most FUNCTION_LIMIT (80) lines. A helper beside
#     main() is held to the runtime's limit: only main() itself gets the programs' larger one.
# Only the listed files' own functions count: no header's (clang-tidy's header filter stays off).
#
# The check takes one threshold for a whole run, so clang-tidy runs once over every file at the
# smaller limit and reports every function above it with its exact count; this script then holds
# main() in the programs' files to MAIN_LIMIT and the rest to FUNCTION_LIMIT. Same verdicts as one
# run per limit, each file parsed once. Warnings are errors: any function over its limit fails.
#
# usage: size-check.sh [BUILD_DIR]   (default build: the release preset's, for compile_commands.json)
# Environment: CLANG_TIDY (clang-tidy), SIZE_CHECK_JOBS (files at once; the number of CPUs).
# Prints each offender as `file:line function N lines (limit L)` and a summary line.
# Exit: 0 all within their limits, 1 some function over its limit, 2 the check could not run.
set -euo pipefail
cd "$(dirname "$0")/.."

# The file sets, in one place (globs from the repository root): the programs' mains, and the
# runtime, the boards and the programs' other files. A glob that matches nothing is skipped; a file
# that matches must be in the compile database.
programs=(firmware/programs/*_main.cpp)
runtime=(firmware/runtime/*.cpp board/sim/*.cpp board/sherline_suzuki/*.cpp firmware/programs/*.cpp)
MAIN_LIMIT=150
FUNCTION_LIMIT=80

build=${1:-build}
clang_tidy=${CLANG_TIDY:-clang-tidy}
jobs=${SIZE_CHECK_JOBS:-$(nproc)}
started=$(date +%s)

command -v "$clang_tidy" >/dev/null || { echo "size-check: $clang_tidy is missing (bash toolchain/install-deps.sh)" >&2; exit 2; }
database=$build/compile_commands.json
[ -f "$database" ] || { echo "size-check: $database is missing (cmake --preset release)" >&2; exit 2; }

# The programs' files first, then the runtime's that are not programs; each file once.
declare -A is_program=()
files=()
for file in "${programs[@]}"; do
  [ -f "$file" ] || continue
  is_program[$file]=1
  files+=("$file")
done
for file in "${runtime[@]}"; do
  [ -f "$file" ] || continue
  [ -n "${is_program[$file]:-}" ] && continue
  files+=("$file")
done
[ "${#files[@]}" -gt 0 ] || { echo "size-check: no files match the file sets" >&2; exit 2; }
root=$(pwd)
for file in "${files[@]}"; do
  grep -qF "\"file\": \"$root/$file\"" "$database" ||
    { echo "size-check: $file is not in $database (is it built by that configuration?)" >&2; exit 2; }
done

smaller=$((MAIN_LIMIT < FUNCTION_LIMIT ? MAIN_LIMIT : FUNCTION_LIMIT))
# Lines only: the statement count (800 by default) is switched off by an unreachable threshold. No
# .clang-tidy file is read (-config replaces it), so the header filter is clang-tidy's default: none.
checks='-*,readability-function-size'
config="{CheckOptions: [{key: readability-function-size.LineThreshold, value: $smaller}, \
{key: readability-function-size.StatementThreshold, value: 4294967295}]}"

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
# The build's precompiled headers are GCC's (toolchain/cmake/stencil-build.cmake), which clang cannot
# read: clang-tidy gets the compile commands without them (it parses the headers itself).
mkdir "$work/database"
sed -E 's/ -Winvalid-pch//g; s/ -include [^ "]*cmake_pch[.]hxx//g' "$database" >"$work/database/compile_commands.json"
# One clang-tidy per file, SIZE_CHECK_JOBS at once; each writes its output and exit status apart.
# The compile commands are g++'s: clang's own warnings must not become errors (-Werror) here.
build=$work/database
export clang_tidy build checks config work
# shellcheck disable=SC2016  # expanded by the inner bash, from the exported variables
printf '%s\n' "${files[@]}" | xargs -P "$jobs" -n 1 bash -c '
  out=$work/$(echo "$1" | tr / _)
  status=0
  "$clang_tidy" -p "$build" --quiet -checks="$checks" -config="$config" \
    --extra-arg=-Wno-error --extra-arg=-Wno-unknown-warning-option "$1" >"$out.log" 2>&1 || status=$?
  echo "$status" >"$out.status"' size-check

failed=0
for file in "${files[@]}"; do
  out=$work/$(echo "$file" | tr / _)
  if [ "$(cat "$out.status")" != 0 ]; then
    echo "size-check: clang-tidy failed on $file:" >&2
    grep -E 'error:' "$out.log" >&2 || cat "$out.log" >&2
    failed=1
  fi
done
[ "$failed" -eq 0 ] || exit 2

# warning: function 'NAME' exceeds ... at file:line, then its note: N lines including ... (threshold T).
offenders=$(for file in "${files[@]}"; do
  out=$work/$(echo "$file" | tr / _)
  awk -v root="$root/" -v program="${is_program[$file]:-0}" -v main_limit="$MAIN_LIMIT" -v limit="$FUNCTION_LIMIT" '
    / warning: function .* exceeds recommended size\/complexity thresholds/ {
      split($0, parts, ": warning: ")
      location = parts[1]; sub(/:[0-9]+$/, "", location); sub("^" root, "", location)
      name = $0; sub(/^[^'\'']*'\''/, "", name); sub(/'\'' exceeds.*$/, "", name)
      next
    }
    / note: [0-9]+ lines including whitespace and comments/ && location != "" {
      lines = $0; sub(/^.* note: /, "", lines); sub(/ lines.*$/, "", lines)
      allowed = (program == 1 && name == "main") ? main_limit : limit
      if (lines + 0 > allowed + 0) printf "%s %s %d lines (limit %d)\n", location, name, lines, allowed
      location = ""
    }' "$out.log"
done | sort -t: -k1,1 -k2,2n)

elapsed=$(($(date +%s) - started))
if [ -n "$offenders" ]; then
  echo "$offenders"
  count=$(printf '%s\n' "$offenders" | wc -l)
  echo "size-check: $count function(s) over their limits in ${#files[@]} files (main() in a program: $MAIN_LIMIT lines; any other function: $FUNCTION_LIMIT) in ${elapsed} s"
  exit 1
fi
echo "size-check: every function in ${#files[@]} files within its limit (main() in a program: $MAIN_LIMIT lines; any other function: $FUNCTION_LIMIT) in ${elapsed} s"
