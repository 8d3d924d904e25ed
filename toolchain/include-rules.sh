#!/usr/bin/env bash
# The dependency direction of ARCHITECTURE.md, checked on the sources' #include lines rather than
# trusted to review:
#   - the core (firmware/core/) includes only the core, hal/'s interfaces (hal/*.hpp, not a
#     backend's folder), Eigen, zlib's CRC (<zlib.h>), the compiler's intrinsics and the standard
#     library (an <angle> header with no folder); the link check (linker/) proves the rest;
#   - the runtime (firmware/runtime/), the services (firmware/services/), hal/, sim/ and toolchain/
#     include nothing from board/ (boards include them, never the other way round);
#   - nothing outside firmware/programs/ includes a program's file.
# usage: include-rules.sh [REPO_ROOT]. Prints each offending line as file:line: #include ... (why);
# exit 0 none, 1 some.
set -uo pipefail
root=${1:-$(cd "$(dirname "$0")/.." && pwd)}
cd "$root" || exit 2
status=0
offend() {  # file:line:text  why
  echo "$1 ($2)"
  status=1
}

sources() { find "$@" -type f \( -name '*.cpp' -o -name '*.hpp' -o -name '*.h' \) -not -path '*/node_modules/*' 2>/dev/null; }

while IFS= read -r hit; do
  header=$(sed -E 's/^[^:]+:[0-9]+:[[:space:]]*#[[:space:]]*include[[:space:]]*(["<][^">]*[">]).*/\1/' <<<"$hit")
  case $header in
    \"firmware/core/*) ;;
    \"hal/*/*) offend "$hit" "the core includes hal/'s interfaces, not a backend" ;;
    \"hal/*) ;;
    \<Eigen/*\> | \<zlib.h\> | \<immintrin.h\>) ;;
    \<*/*\>) offend "$hit" "the core includes the standard library, Eigen and zlib's CRC only" ;;
    \<*\>) ;;
    *) offend "$hit" "the core includes only the core and hal/'s interfaces" ;;
  esac
done < <(sources firmware/core | xargs grep -nE '^[[:space:]]*#[[:space:]]*include' /dev/null)

while IFS= read -r hit; do
  offend "$hit" "only programs and boards include board/"
done < <(sources firmware/core firmware/runtime firmware/services hal sim toolchain |
           xargs grep -nE '^[[:space:]]*#[[:space:]]*include[[:space:]]*"board/' /dev/null)

while IFS= read -r hit; do
  offend "$hit" "a program's files are its own"
done < <(sources firmware/core firmware/runtime firmware/services hal sim toolchain board |
           xargs grep -nE '^[[:space:]]*#[[:space:]]*include[[:space:]]*"firmware/programs/' /dev/null)

[ "$status" -eq 0 ] && echo "include-rules: the core, the runtime, the services, hal/, sim/ and toolchain/ keep the dependency direction"
exit "$status"
