#!/usr/bin/env bash
# include-rules.sh on a tree made to break each rule once: it must fail (exit 1) naming exactly the
# breaking lines, and pass over the fixture's allowed lines. usage: include_rules_tests.sh REPO_ROOT
set -uo pipefail
root=$1
out=$(bash "$root/toolchain/include-rules.sh" "$root/tests/toolchain/include_rules_fixture")
status=$?
expected='firmware/core/control/careless.cpp:3:
firmware/core/control/careless.cpp:4:
firmware/core/control/careless.cpp:5:
firmware/runtime/upward.cpp:2:
firmware/runtime/upward.cpp:3:
sim/mill/upward.cpp:2:'
got=$(sed -E 's/^([^:]+:[0-9]+:).*/\1/' <<<"$out" | sort)
if [ "$status" -ne 1 ] || [ "$got" != "$expected" ]; then
  echo "include-rules.sh on the fixture: exit $status (expected 1), it named:"
  echo "$out"
  echo "expected exactly:"
  echo "$expected"
  exit 1
fi
echo "include-rules.sh named the 6 lines that break the rules, and only those"
