#!/usr/bin/env bash
# Installs exactly the Debian packages the project builds and tests with; does nothing when all are present.
# --cross also installs the aarch64-linux-gnu cross compiler and the arm64 libraries the firmware
# links (zlib), for the `aarch64` preset and its stencil-rig (CLI11 and nlohmann json are header-only:
# the host's copies serve; stencil-display, with Boost.Beast, is a host program).
# --latency adds cyclictest and stress-ng for make latency.
# --fresh-check adds mmdebstrap, for make fresh-check.
set -euo pipefail

cross=0
latency=0
fresh_check=0
for argument in "$@"; do
  case "$argument" in
    --cross) cross=1 ;;
    --latency) latency=1 ;;
    --fresh-check) fresh_check=1 ;;
    -h|--help)
      echo "usage: $0 [--cross] [--latency] [--fresh-check]"
      echo "Installs the Debian packages the project needs (apt-get; as root or via sudo)."
      echo "  --cross   also the aarch64-linux-gnu cross compiler (for the aarch64 preset)"
      echo "  --latency also cyclictest (rt-tests) and stress-ng (for make latency)"
      echo "  --fresh-check also mmdebstrap (for make fresh-check)"
      exit 0 ;;
    *) echo "install-deps: unknown option '$argument' (expected --cross, --latency, --fresh-check or --help)" >&2; exit 2 ;;
  esac
done

packages=(
  g++                # host compiler (C++20)
  cmake              # build system (presets need >= 3.21)
  ninja-build        # generator used by every preset
  make               # the thin top-level Makefile
  libeigen3-dev      # fixed-size linear algebra in the core
  libcpputest-dev    # unit tests
  linux-libc-dev     # kernel headers: SocketCAN (linux/can.h)
  binutils           # nm, for the link-time allocation check
  zlib1g-dev         # CRC-32 of the table files
  nettle-dev         # SHA-256 of the source STL in the table header
  libcli11-dev       # the table generator's command line
  libtomlplusplus-dev  # the rig's configuration file (header-only)
  nlohmann-json3-dev # --inspect --json
  libpng-dev         # stencil-sim's picture of the machined stock (PNG)
  libfcl-dev         # stencil-bench compares the engine with the Flexible Collision Library
  valgrind           # stencil-bench counts one query's instructions and L1 misses (callgrind, its client header)
  clang              # the fuzz preset's compiler (libFuzzer needs clang)
  libclang-rt-14-dev # libFuzzer and the sanitizer runtimes for clang 14 (only recommended by clang)
  clang-tidy         # make size-check: readability-function-size over the programs, runtime and boards
  libboost-dev       # stencil-display's HTTP and WebSocket server: Boost.Beast (header-only)
  chromium           # the display's end-to-end test, headless (driven by playwright-core from npm)
  fonts-dejavu-core  # text in that browser's screenshots
  help2man           # make package: man pages from the programs' --help
  dpkg-dev           # make package: dpkg-shlibdeps finds the package's runtime dependencies
  linuxcnc-uspace    # the LinuxCNC backend's tests run the real LinuxCNC (sim/linuxcnc_mill; about 80 MB)
)
# The display's page is built with npm (three.js and esbuild, pinned by its package-lock.json): the
# machine's own Node.js and npm when it has them, else Debian's (Node 18 on Debian 12: every package
# the lock file pins accepts it, and firmware/services/hmi/page/check-engines.cjs refuses a Node that some
# pinned package does not, before the page is built and before the browser test).
if ! command -v npm >/dev/null 2>&1 || ! command -v node >/dev/null 2>&1; then
  packages+=(nodejs npm)
fi
if [ "$cross" -eq 1 ]; then
  packages+=(g++-aarch64-linux-gnu zlib1g-dev:arm64)
fi
if [ "$latency" -eq 1 ]; then
  packages+=(rt-tests stress-ng)
fi
if [ "$fresh_check" -eq 1 ]; then
  packages+=(mmdebstrap)
fi

missing=()
for package in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q 'install ok installed'; then
    missing+=("$package")
  fi
done

if [ "${#missing[@]}" -eq 0 ]; then
  exit 0
fi

echo "install-deps: installing ${missing[*]}"
if [ "$(id -u)" -eq 0 ]; then
  sudo_cmd=()
elif command -v sudo >/dev/null 2>&1; then
  sudo_cmd=(sudo)
else
  echo "install-deps: need root or sudo to install: ${missing[*]}" >&2
  exit 1
fi

export DEBIAN_FRONTEND=noninteractive
if [ "$cross" -eq 1 ] && ! dpkg --print-foreign-architectures | grep -qx arm64; then
  "${sudo_cmd[@]}" dpkg --add-architecture arm64
fi
"${sudo_cmd[@]}" apt-get update -q
"${sudo_cmd[@]}" apt-get install -y -q --no-install-recommends "${missing[@]}"
