#!/usr/bin/env bash
# Do the tests fail when the behaviour breaks? For each row of tests/mutations.tsv (a behaviour
# README names, a one-line change to the source that breaks it, and the ctest test that must then
# fail), on a copy of this tree: apply the change, rebuild that test's executable, run it, and
# expect it to fail; then put the line back. First, unchanged, every test named must pass (a test
# that fails anyway catches nothing).
#
# tests/mutations.tsv: one mutation per line, tab-separated, # for comments:
#   behaviour  <TAB> source file <TAB> exact text (once in the file) <TAB> replacement <TAB> ctest test name
# The test's executable is the ctest name unless the name is "TEST:TARGET".
#
# usage: mutation-check.sh [WORK_DIR]   (default build/mutation: a copy of the tree as it is, committed
# or not, in WORK_DIR/src, with its own release build in WORK_DIR/src/build, kept between runs)
# Prints a Markdown table (behaviour, file, the change, the test, caught); exit 0 when every
# mutation was caught, 1 when one survived, 2 when the set-up failed.
set -uo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
work=$(realpath -m "${1:-$root/build/mutation}")
table=$root/tests/mutations.tsv
src=$work/src
build=$src/build  # inside the copy, as in the tree: ccache (used when installed) then hits across copies

die() { echo "mutation-check: $*" >&2; exit 2; }

[ -f "$table" ] || die "no $table"
mkdir -p "$work" || die "cannot make $work"
# A copy of the tree as it is now (committed and not), so the check runs on what is being changed;
# kept between runs with its build. Only a file whose bytes differ is written (so it is newer than
# what was built from it: a line a run put back, or a file changed since, is rebuilt), and a file
# the tree no longer has is removed.
mkdir -p "$src" || die "cannot make $src"
(cd "$root" && git ls-files -co --exclude-standard -z) | python3 -c '
import os, sys
root, src = sys.argv[1:3]
wanted = set()
for path in sys.stdin.buffer.read().split(b"\0"):
    if not path:
        continue
    path = path.decode()
    wanted.add(path)
    source, copy = os.path.join(root, path), os.path.join(src, path)
    if not os.path.isfile(source):
        continue
    data = open(source, "rb").read()
    if os.path.isfile(copy) and open(copy, "rb").read() == data:
        continue
    os.makedirs(os.path.dirname(copy), exist_ok=True)
    open(copy, "wb").write(data)
    os.chmod(copy, os.stat(source).st_mode & 0o777)
for folder, dirs, files in os.walk(src):
    if folder == os.path.join(src, "build") or folder.startswith(os.path.join(src, "build") + os.sep):
        dirs[:] = []
        continue
    for name in files:
        path = os.path.relpath(os.path.join(folder, name), src)
        if path not in wanted:
            os.remove(os.path.join(folder, name))
' "$root" "$src" || die "cannot copy the tree to $src"
launcher=()
command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
cmake -S "$src" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DSTENCIL_BUILD_TESTS=ON "${launcher[@]}" \
  -DCMAKE_TOOLCHAIN_FILE="$src/toolchain/cmake/host.cmake" >"$work/configure.log" 2>&1 ||
  die "configure failed: $work/configure.log"

rows=()
while IFS= read -r line; do
  [[ -z $line || $line == \#* ]] && continue
  rows+=("$line")
done <"$table"
[ "${#rows[@]}" -gt 0 ] || die "$table holds no mutation"
# The files a run mutates are rebuilt once first: an object built from a mutation is newer than the
# line put back by a run that was stopped, or than a copy older than that run.
for row in "${rows[@]}"; do
  IFS=$'\t' read -r _ file _ <<<"$row"
  touch "$src/$file"
done

split() {  # row -> behaviour file from to test target
  IFS=$'\t' read -r behaviour file from to test <<<"$1"
  target=${test#*:}
  test=${test%%:*}
}

run_test() {  # test target -> 0 pass, 1 fail, 2 build failed
  cmake --build "$build" --target "$2" >>"$work/build.log" 2>&1 || return 2
  ctest --test-dir "$build" -R "^$1\$" --timeout 600 >>"$work/test.log" 2>&1 && return 0
  return 1
}

: >"$work/build.log"
: >"$work/test.log"
echo "mutation-check: ${#rows[@]} mutations; building and running each test unchanged first" >&2
declare -A checked=()
for row in "${rows[@]}"; do
  split "$row"
  [ -n "${checked[$test]:-}" ] && continue
  checked[$test]=1
  run_test "$test" "$target"
  case $? in
    0) ;;
    1) die "$test fails on the unchanged tree: it cannot tell a mutation ($work/test.log)" ;;
    *) die "$target does not build on the unchanged tree ($work/build.log)" ;;
  esac
done

survived=0
echo "| behaviour (README) | file | the change | test | caught |"
echo "|---|---|---|---|---|"
n=0
for row in "${rows[@]}"; do
  split "$row"
  n=$((n + 1))
  echo "mutation-check: $n/${#rows[@]}: $file: $behaviour" >&2
  python3 - "$src/$file" "$from" "$to" <<'PY' || die "$file: the text to change is not there exactly once: $from"
import sys
path, old, new = sys.argv[1:4]
text = open(path, encoding="utf-8").read()
if text.count(old) != 1:
    sys.exit(1)
open(path, "w", encoding="utf-8").write(text.replace(old, new))
PY
  run_test "$test" "$target"
  verdict=$?
  cp "$root/$file" "$src/$file"
  case $verdict in
    1) caught=yes ;;
    2) caught="no: the change does not compile" ; survived=$((survived + 1)) ;;
    *) caught="**NO: $test still passes**" ; survived=$((survived + 1)) ;;
  esac
  echo "| $behaviour | \`$file\` | \`${from//|/\\|}\` → \`${to//|/\\|}\` | \`$test\` | $caught |"
done
if [ "$survived" -gt 0 ]; then
  echo "mutation-check: $survived of ${#rows[@]} mutations survived" >&2
  exit 1
fi
echo "mutation-check: every one of the ${#rows[@]} mutations was caught" >&2
exit 0
