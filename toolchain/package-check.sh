#!/usr/bin/env bash
# make package-check (ctest label `package`): the Debian package as the rig box meets it. In a clean
# Debian 12 root (mmdebstrap, the `important` set a standard install has, systemd among them), entered
# with chroot: apt installs the .deb and what it pulled is listed (none of the build or test tools);
# stencil-sim --version; a 60-simulated-second job run by an ordinary user from their home folder;
# systemd-analyze verify on both units; stencil-rig status against a running simulated rig (over its
# socket, as the service's control commands go); then a purge, and what is left of the package
# listed (nothing but the users' runs).
#
#   package-check.sh [--remove-root] WORK_DIR PACKAGE.deb|BUILD_DIR
# Needs root (mmdebstrap, mounts, chroot) and Debian's package archive; takes a few minutes.
set -euo pipefail

usage() {
  echo "usage: $0 [--remove-root] WORK_DIR PACKAGE.deb"
  echo "Installs, uses and purges the package in a clean Debian 12 root made with mmdebstrap (needs root)."
}
remove_root=0
arguments=()
for argument in "$@"; do
  case "$argument" in
    --remove-root) remove_root=1 ;;
    -h|--help) usage; exit 0 ;;
    -*) echo "package-check: unknown option '$argument'" >&2; usage >&2; exit 2 ;;
    *) arguments+=("$argument") ;;
  esac
done
if [ "${#arguments[@]}" -ne 2 ]; then usage >&2; exit 2; fi
work=${arguments[0]} deb=${arguments[1]}
if [ -d "$deb" ]; then  # a build folder: the newest package make package left there
  deb=$(ls -t "$deb"/stencil_*.deb 2>/dev/null | head -n 1 || true)
  [ -n "$deb" ] || { echo "package-check: no stencil_*.deb in ${arguments[1]} (make package builds it)" >&2; exit 2; }
fi
if [ ! -f "$deb" ]; then echo "package-check: $deb: no such package (make package builds it)" >&2; exit 2; fi
if [ "$(id -u)" -ne 0 ]; then echo "package-check: needs root (mmdebstrap, bind mounts and chroot)" >&2; exit 1; fi
mkdir -p "$work"
work=$(cd "$work" && pwd)
deb=$(cd "$(dirname "$deb")" && pwd)/$(basename "$deb")
root=$work/root

source "$(dirname "$0")/debian-root.sh"
trap 'debian_root_unmount "$root"' EXIT
debian_root_fresh "$root"

failures=0
fail() { echo "package-check: FAIL: $*" >&2; failures=$((failures + 1)); }
step() { echo; echo "package-check: == $*"; }
in_root() { chroot "$root" /usr/bin/env -i HOME=/root LANG=C.UTF-8 PATH=/usr/sbin:/usr/bin:/sbin:/bin "$@"; }
as_user() { chroot "$root" /usr/bin/env -i LANG=C.UTF-8 PATH=/usr/bin:/bin su - machinist -s /bin/bash -c "$1"; }

step "a clean Debian 12 root in $root (mmdebstrap --variant=important)"
started=$(date +%s)
debian_root_make "$root" --variant=important
echo "root made in $(( $(date +%s) - started )) s"
cp -L /etc/resolv.conf "$root/etc/resolv.conf"
debian_root_mount "$root"

step "install $(basename "$deb") with apt ($(du -h "$deb" | cut -f1) on disk)"
cp "$deb" "$root/tmp/"
# mmdebstrap leaves the root without package lists; the package's libraries beyond the important set
# (libpng16-16, for the simulation's picture) come from the archive, as on a machinist's machine.
in_root apt-get update -qq >"$work/update.log" 2>&1 || { cat "$work/update.log"; fail "apt-get update in the root"; }
in_root dpkg-query -W -f '${Package}\n' | sort >"$work/before.txt"
in_root apt-get install -y --no-install-recommends "/tmp/$(basename "$deb")" >"$work/install.log" 2>&1 ||
  { cat "$work/install.log"; fail "apt could not install the package"; }
in_root dpkg-query -W -f '${Package}\n' | sort >"$work/after.txt"
pulled=$(comm -13 "$work/before.txt" "$work/after.txt" | tr '\n' ' ')
echo "pulled: $pulled"
echo "Depends: $(in_root dpkg-query -W -f '${Depends}' stencil)"
echo "Installed-Size: $(in_root dpkg-query -W -f '${Installed-Size}' stencil) KiB"
for banned in libfcl clang chromium nodejs npm cpputest libcpputest; do
  if grep -qE "(^| )$banned" <<<" $pulled"; then fail "the package pulled $banned (a build or test tool)"; fi
done
in_root getent passwd stencil >/dev/null || fail "no service user stencil"
echo "service user: $(in_root id stencil)"
in_root id -nG stencil | grep -qw dialout || fail "the service user is not in dialout (the serial port)"
for file in /usr/bin/stencil-sim /usr/bin/stencil-rig /usr/bin/stencil-display /usr/bin/stencil-tablegen \
            /usr/share/stencil/page/index.html /usr/share/stencil/parts/hex_prism.stl /etc/stencil/rig.toml \
            /etc/stencil/display.token /usr/share/man/man1/stencil-rig.1.gz /usr/lib/systemd/system/stencil-rig.service; do
  [ -e "$root$file" ] || fail "$file is not installed"
done

step "the maintainer scripts again (dpkg-reconfigure): what the machinist set is kept"
echo '# edited by the machinist' >>"$root/etc/stencil/rig.toml"
sums_before=$(cd "$root/etc/stencil" && sha256sum rig.toml display.token job.env)
in_root dpkg-reconfigure stencil || fail "dpkg-reconfigure stencil"
[ "$(cd "$root/etc/stencil" && sha256sum rig.toml display.token job.env)" = "$sums_before" ] ||
  fail "running postinst again changed /etc/stencil"
sed -i '$d' "$root/etc/stencil/rig.toml"
echo "/etc/stencil kept: $(ls "$root/etc/stencil" | tr '\n' ' ')"

step "stencil-sim --version"
in_root stencil-sim --version || fail "stencil-sim --version"

step "a 60-simulated-second job by an ordinary user (machinist) from their home folder"
in_root useradd --create-home --shell /bin/bash machinist
as_user 'cd ~ && stencil-sim --fast --pattern raster --duration 60 --report job.json' >"$work/job.log" 2>&1 ||
  fail "the job (exit status $?)"
sed 's/^/  /' "$work/job.log"
as_user 'ls -l ~' || true
grep -q '"version"' "$root/home/machinist/job.json" || fail "the report has no provenance"
as_user 'stencil-tablegen sample:hex_prism --tool ball:d=3 -o ~/hex.stbl --quiet' || fail "stencil-tablegen sample:hex_prism"

step "systemd-analyze verify on both units (--man=no: the root has no man-db; the pages were checked above)"
in_root systemd-analyze verify --man=no /usr/lib/systemd/system/stencil-rig.service /usr/lib/systemd/system/stencil-display.service ||
  fail "systemd-analyze verify"

step "stencil-rig status against a running simulated rig"
as_user 'cd ~ && (setsid stencil-sim --speed 1 --pattern raster --duration 60 --no-journal --report rig.json \
  --display-socket ~/control.sock >sim.log 2>&1 &)'
for _ in $(seq 1 150); do
  if as_user 'stencil-rig status --socket ~/control.sock' 2>/dev/null | grep -q '^job: running'; then break; fi
  sleep 0.2
done
as_user 'stencil-rig status --socket ~/control.sock' | tee "$work/status.log" || fail "stencil-rig status"
grep -q '^job: running' "$work/status.log" || fail "status does not show a running job"
as_user 'stencil-rig stop --socket ~/control.sock' || fail "stencil-rig stop"
for _ in $(seq 1 100); do grep -q '^report:' "$root/home/machinist/sim.log" && break; sleep 0.1; done
grep -E '^(safe state|report)' "$root/home/machinist/sim.log" | sed 's/^/  stencil-sim: /'

step "a job left for the service as a machinist would: the display enabled, the part's tables and a run"
in_root systemctl enable stencil-display.service || fail "systemctl enable stencil-display"
[ -L "$root/etc/systemd/system/multi-user.target.wants/stencil-display.service" ] || fail "the display is not enabled"
cp "$root/home/machinist/hex.stbl" "$root/var/lib/stencil/part.stbl"
mkdir -p "$root/var/lib/stencil/jobs/stencil-rig-20261203-120000"
cp "$root"/home/machinist/.local/state/stencil/jobs/latest/job.journal "$root/var/lib/stencil/jobs/stencil-rig-20261203-120000/job.journal"
in_root chown -R stencil:stencil /var/lib/stencil

step "purge"
in_root apt-get purge -y stencil >"$work/purge.log" 2>&1 || { cat "$work/purge.log"; fail "apt-get purge"; }
in_root dpkg-query -W stencil >/dev/null 2>&1 && fail "dpkg still knows the package"
in_root getent passwd stencil >/dev/null && fail "the service user is still there"
[ -e "$root/etc/systemd/system/multi-user.target.wants/stencil-display.service" ] && fail "the display is still enabled"
left=$(cd "$root" && find . -xdev \( -path ./proc -o -path ./sys -o -path ./dev -o -path ./tmp \) -prune -o \
  \( -iname '*stencil*' -print \) 2>/dev/null | grep -v '^./var/lib/dpkg/' || true)
echo "left with 'stencil' in its name (and what is in /var/lib/stencil):"
echo "${left:-(nothing)}" | sed 's/^/  /'
(cd "$root" && find ./var/lib/stencil -printf '  %p %u:%g\n' 2>/dev/null) || true
# The runs only: users' in their homes, the service's in /var/lib/stencil (its journals and the tables
# they were cut from), given to root.
if grep -vE '^\./(home/|var/lib/stencil($|/))' <<<"$left" | grep -q .; then fail "the purge left files besides the runs"; fi
[ -f "$root/var/lib/stencil/jobs/stencil-rig-20261203-120000/job.journal" ] || fail "the purge took the service's run"
if [ -n "$(cd "$root" && find ./var/lib/stencil ! -user root 2>/dev/null)" ]; then
  fail "files in /var/lib/stencil still belong to the removed user"
fi

debian_root_unmount "$root"
if [ "$remove_root" -eq 1 ]; then rm -rf --one-file-system "$root"; fi
echo
if [ "$failures" -ne 0 ]; then echo "package-check: $failures failure(s)" >&2; exit 1; fi
echo "package-check: passed"
