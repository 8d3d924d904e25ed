#!/usr/bin/env bash
# Proves the link-time check bites: it must fail on LIBRARY and name a symbol matching PATTERN.
set -uo pipefail
checker=$1 library=$2 pattern=$3
output=$("$checker" "$library" 2>&1)
status=$?
echo "$output"
if [ "$status" -ne 1 ]; then
  echo "expect-rejected: the check exited $status on $library; expected 1 (rejected)" >&2
  exit 1
fi
if ! grep -Eq "references ($pattern)" <<<"$output"; then
  echo "expect-rejected: the check did not name a symbol matching '$pattern'" >&2
  exit 1
fi
echo "expect-rejected: rejected as expected"
