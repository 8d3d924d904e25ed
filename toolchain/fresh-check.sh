#!/usr/bin/env bash
# make fresh-check: README's two commands as a new user meets them. Builds a clean Debian 12 root
# with mmdebstrap (Debian's packages only, plus git and make), clones the committed HEAD into it and
# runs `make demo`, then `bash toolchain/install-deps.sh && make test` there, printing each one's
# result and time. What the development machines carry from outside Debian (a newer Node, say) is
# not in the root, so a missing install step fails here rather than at a user's (issue 17).
#
#   fresh-check.sh [--remove-root] WORK_DIR
# Needs root (mmdebstrap, mounts, chroot) and Debian's package archive; takes about half an hour.
# The root stays in WORK_DIR/root to look into (removed at the next run, or at the end with
# --remove-root); the logs are WORK_DIR/demo.log and WORK_DIR/test.log.
set -euo pipefail

usage() {
  echo "usage: $0 [--remove-root] WORK_DIR"
  echo "Runs README's two commands in a clean Debian 12 root made with mmdebstrap (needs root)."
  echo "  --remove-root  delete the root afterwards (by default it stays in WORK_DIR/root to look into)"
}

remove_root=0
work=""
for argument in "$@"; do
  case "$argument" in
    --remove-root) remove_root=1 ;;
    -h|--help) usage; exit 0 ;;
    -*) echo "fresh-check: unknown option '$argument'" >&2; usage >&2; exit 2 ;;
    *) if [ -n "$work" ]; then echo "fresh-check: one WORK_DIR only (got '$work' and '$argument')" >&2; exit 2; fi
       work=$argument ;;
  esac
done
if [ -z "$work" ]; then usage >&2; exit 2; fi
if [ "$(id -u)" -ne 0 ]; then
  echo "fresh-check: needs root (mmdebstrap's root mode, bind mounts and chroot)" >&2
  exit 1
fi

repo=$(git -C "$(dirname "$0")/.." rev-parse --show-toplevel)
commit=$(git -C "$repo" rev-parse HEAD)
if [ -n "$(git -C "$repo" status --porcelain --untracked-files=no)" ]; then
  echo "fresh-check: note: uncommitted changes are not checked; the root gets the committed HEAD ${commit:0:12}"
fi
mkdir -p "$work"
work=$(cd "$work" && pwd)
root=$work/root

# Everything mounted under the root comes off again, however the script ends.
source "$repo/toolchain/debian-root.sh"
trap 'debian_root_unmount "$root"' EXIT
debian_root_fresh "$root"

# Debian 12 as a fresh install sees it: the release, its updates and its security archive. The apt
# variant is Essential plus apt, as minimal as a container image: whatever else the commands need,
# they must install themselves.
echo "fresh-check: a clean Debian 12 root in $root (mmdebstrap)"
start=$(date +%s)
debian_root_make "$root" --variant=apt --include=git,make
echo "fresh-check: root made in $(( $(date +%s) - start )) s"

# This host's extra certificate authorities (a TLS-inspecting proxy here): a user's machine has its
# own. They are merged into the root's store when install-deps installs ca-certificates (nodejs
# depends on it), and npm's Node reads them from there through NODE_EXTRA_CA_CERTS.
if compgen -G "/usr/local/share/ca-certificates/*.crt" >/dev/null; then
  mkdir -p "$root/usr/local/share/ca-certificates"
  cp /usr/local/share/ca-certificates/*.crt "$root/usr/local/share/ca-certificates/"
fi
cp -L /etc/resolv.conf "$root/etc/resolv.conf"

git clone --quiet --no-hardlinks "$repo" "$root/root/stencil"
git -C "$root/root/stencil" checkout --quiet "$commit"

# The tests use pseudo-terminals, memfds, SCHED_FIFO, a tmpfs mount and Chromium: the host's /dev,
# /proc and /sys, as on a machine of its own.
debian_root_mount "$root"

# run_in_root NAME COMMAND: runs COMMAND in the clone as root with a login's plain environment,
# logs to WORK_DIR/NAME.log, prints its result and time; the status is kept in the global `failed`.
failed=()
summary=()
run_in_root() {
  local name=$1 command=$2 status started seconds
  echo
  echo "fresh-check: [$name] $command   (log: $work/$name.log)"
  started=$(date +%s)
  set +e
  chroot "$root" /usr/bin/env -i HOME=/root LANG=C.UTF-8 TERM=dumb \
    PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin \
    NODE_EXTRA_CA_CERTS=/etc/ssl/certs/ca-certificates.crt \
    bash -c "cd /root/stencil && $command" 2>&1 | tee "$work/$name.log" | sed -u "s/^/  [$name] /"
  status=${PIPESTATUS[0]}
  set -e
  seconds=$(( $(date +%s) - started ))
  if [ "$status" -eq 0 ]; then
    summary+=("$(printf '%-5s passed in %4d s: %s' "$name" "$seconds" "$command")")
  else
    summary+=("$(printf '%-5s FAILED (exit %d) after %4d s: %s' "$name" "$status" "$seconds" "$command")")
    failed+=("$name")
  fi
}

run_in_root demo "make demo"
run_in_root test "bash toolchain/install-deps.sh && make test"

echo
echo "fresh-check: Debian 12 root, commit ${commit:0:12}, $(chroot "$root" node --version 2>/dev/null || echo 'no node')"
printf 'fresh-check: %s\n' "${summary[@]}"
grep -E '^(simulated|gouge|stock removed|coverage|safe state)' "$work/demo.log" | sed 's/^/fresh-check: demo: /' || true
grep -E 'tests passed|tests failed' "$work/test.log" | sed 's/^/fresh-check: test: /' || true

debian_root_unmount "$root"
if [ "$remove_root" -eq 1 ]; then rm -rf --one-file-system "$root"; fi
if [ "${#failed[@]}" -ne 0 ]; then
  echo "fresh-check: FAILED: ${failed[*]}" >&2
  exit 1
fi
echo "fresh-check: both commands passed"
