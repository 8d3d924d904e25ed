# Sourced by fresh-check.sh and package-check.sh: a clean Debian 12 root made with mmdebstrap from
# Debian's archive (the release, its updates and its security archive), the host's /proc, /sys and
# /dev bound inside it, and all of it taken off again however the script ends. Needs root.
#
#   debian_root_fresh ROOT     unmount and remove what a killed run left at ROOT (never into a bind mount)
#   debian_root_make ROOT MMDEBSTRAP_OPTIONS...   make it (e.g. --variant=apt --include=git,make)
#   debian_root_mount ROOT     the host's /proc, /sys and /dev inside it
#   debian_root_unmount ROOT   every mount taken off again (the callers trap it on EXIT)

debian_root_unmount() {
  local mount_point
  for mount_point in "$1/dev" "$1/sys" "$1/proc"; do
    if mountpoint -q "$mount_point" 2>/dev/null; then umount -R -l "$mount_point" || true; fi
  done
}

debian_root_fresh() {
  debian_root_unmount "$1"
  rm -rf --one-file-system "$1"
}

debian_root_make() {
  local root=$1
  shift
  mmdebstrap --quiet "$@" bookworm "$root" \
    "deb http://deb.debian.org/debian bookworm main" \
    "deb http://deb.debian.org/debian bookworm-updates main" \
    "deb http://deb.debian.org/debian-security bookworm-security main"
}

debian_root_mount() {
  mount -t proc proc "$1/proc"
  mount --rbind /sys "$1/sys" && mount --make-rslave "$1/sys"
  mount --rbind /dev "$1/dev" && mount --make-rslave "$1/dev"
}
