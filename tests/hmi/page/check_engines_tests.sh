#!/usr/bin/env bash
# check-engines.cjs: passes the page's own lock file on this Node, and refuses a lock file that pins a
# package this Node does not satisfy, naming the package, its requirement and the Node found; bad
# lock files and ranges are named, not guessed at.
#   check_engines_tests.sh NODE CHECK_ENGINES PAGE_LOCK NODE_MODULES WORK_DIR
set -uo pipefail
node=$1 check=$2 page_lock=$3 node_modules=$4 work=$5
rm -rf "$work" && mkdir -p "$work"
failures=0
node_version=$("$node" --version)

# run_check NAME LOCK EXPECTED_STATUS PATTERN...: the check's exit status and every pattern in its output
run_check() {
  local name=$1 lock=$2 expected=$3; shift 3
  local output status
  output=$(NODE_PATH=$node_modules "$node" "$check" "$lock" 2>&1); status=$?
  if [ "$status" -ne "$expected" ]; then
    echo "FAIL $name: exit status $status, expected $expected; output:"; echo "$output"; failures=$((failures + 1)); return
  fi
  for pattern in "$@"; do
    if ! grep -qF -- "$pattern" <<<"$output"; then
      echo "FAIL $name: output lacks '$pattern':"; echo "$output"; failures=$((failures + 1)); return
    fi
  done
  echo "ok   $name"
}

# write_lock FILE NAME VERSION RANGE: a lockfileVersion 3 file pinning one package besides the root
write_lock() {
  cat >"$1" <<JSON
{ "name": "page", "lockfileVersion": 3, "requires": true,
  "packages": { "": { "name": "page", "version": "0.1.0" },
    "node_modules/$2": { "version": "$3", "dev": true, "engines": { "node": $4 } },
    "node_modules/plain": { "version": "1.0.0" } } }
JSON
}

run_check "the page's own lock passes on this Node" "$page_lock" 0 "satisfies every package"

write_lock "$work/too_new.json" playwright-core 1.65.1 '">=99"'
run_check "a package needing a newer Node is named with its requirement and this Node" "$work/too_new.json" 1 \
  "playwright-core 1.65.1" "requires Node >=99" "this Node is $node_version"

write_lock "$work/too_old.json" old-tool 2.0.0 '"<10 || 11.x"'
run_check "an upper bound and alternatives are read as npm reads them" "$work/too_old.json" 1 \
  "old-tool 2.0.0" "requires Node <10 || 11.x"

write_lock "$work/accepts.json" fine 3.1.4 '"^10 || >=12.0.0"'
run_check "a range this Node satisfies passes" "$work/accepts.json" 0 "satisfies every package"

write_lock "$work/bad_range.json" odd 1.0.0 '"newest please"'
run_check "a range that is not one is named" "$work/bad_range.json" 1 "odd 1.0.0" '"newest please" is not a version range'

write_lock "$work/not_text.json" odd 1.0.0 '18'
run_check "a range that is not text is named" "$work/not_text.json" 1 "odd 1.0.0" "18 is not a version range"

echo '{ "lockfileVersion": 1, "dependencies": {} }' >"$work/v1.json"
run_check "a lock file without a packages map is refused" "$work/v1.json" 2 "v1.json: expected a lock file of lockfileVersion 2 or 3"

echo '{ "packages": ' >"$work/torn.json"
run_check "a torn lock file is named" "$work/torn.json" 2 "torn.json: not JSON"

run_check "a missing lock file is named" "$work/absent.json" 2 "absent.json: cannot read the lock file (ENOENT)"

if [ "$failures" -ne 0 ]; then echo "$failures case(s) failed"; exit 1; fi
echo "all cases passed"
