#!/usr/bin/env bash
# The engine as it was before the packed leaf layout (issue 30), built for stencil-bench's
# "previous" rows: main at commit 1f546f3, with today's bench harness (tests/bench/stencil_bench.cpp
# compiled with STENCIL_BENCH_PREVIOUS against that tree's engine and table generator), and that
# commit's stencil-tablegen. One run of stencil-bench then times both engines on the same machine
# at the same time, so the speed-up is a ratio from one run.
#
# usage: toolchain/bench-previous.sh [OUT_DIR]   (default build/previous; binaries in OUT_DIR/bin,
# the commit's sources in OUT_DIR-src)
# Needs the repository's history (a clone, not an exported tarball). Idempotent: the sources are
# extracted once, and the build is incremental.
set -euo pipefail
cd "$(dirname "$0")/.."
readonly commit=1f546f35b8cbd4d6842afb889624cef4c6adb91a
out="${1:-build/previous}"
if ! git cat-file -e "$commit^{commit}" 2> /dev/null; then
  echo "bench-previous: commit ${commit:0:7} is not in this checkout's history (a shallow clone or a" >&2
  echo "tarball): stencil-bench will leave out its \"previous\" rows" >&2
  exit 1
fi
src="$out-src"
# The commit the sources are from, so a tree extracted from any other is replaced.
if [ ! -f "$src/CMakeLists.txt" ] || [ "$(cat "$src.commit" 2> /dev/null)" != "$commit" ]; then
  echo "bench-previous: extracting ${commit:0:7} into $src"
  rm -rf "$src"
  mkdir -p "$src"
  git archive "$commit" | tar -x -C "$src"
  echo "$commit" > "$src.commit"
fi
# Today's harness (only a changed one is copied, so the build stays incremental).
cmp -s tests/bench/stencil_bench.cpp "$src/tests/bench/stencil_bench.cpp" ||
  cp tests/bench/stencil_bench.cpp "$src/tests/bench/stencil_bench.cpp"
cmake -S "$src" -B "$out" -G Ninja -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_TOOLCHAIN_FILE="$(realpath "$src")/toolchain/cmake/host.cmake" -DSTENCIL_BUILD_TESTS=OFF \
  -DCMAKE_CXX_FLAGS=-DSTENCIL_BENCH_PREVIOUS > /dev/null
cmake --build "$out" --target stencil-bench stencil-tablegen
echo "bench-previous: $out/bin/stencil-bench and $out/bin/stencil-tablegen (commit ${commit:0:7})"
