#!/usr/bin/env bash
# Checks an executable linked with linker/stencil_tables.ld: its output section .stencil_tables exists,
# is allocated and not writable, is 64-byte aligned, and lies in a segment that is not writable.
# usage: check-table-section.sh READELF EXECUTABLE
set -uo pipefail
readelf=$1 executable=$2

fail() {
  echo "check-table-section: $executable: $*" >&2
  exit 1
}

sections=$("$readelf" -S -W "$executable") || fail "readelf -S failed"
# readelf -S -W: [Nr] Name Type Address Off Size ES Flg Lk Inf Al (Flg may be empty, so read from the end)
line=$(awk '$0 ~ /\] \.stencil_tables / { sub(/^.*\] /, ""); print }' <<<"$sections")
[ -n "$line" ] || fail "no output section .stencil_tables (is the table compiled in and the script passed with -Wl,-T?)"
echo "section: $line"
read -r name type address offset size entry_size rest <<<"$line"
flags=$(awk '{ print (NF == 10) ? $7 : "" }' <<<"$line")
alignment=$(awk '{ print $NF }' <<<"$line")
[ "$type" = PROGBITS ] || fail "section .stencil_tables has type $type; expected PROGBITS"
[ "$((16#$size))" -gt 0 ] || fail "section .stencil_tables is empty; expected the baked table"
[[ "$flags" == *A* ]] || fail "section .stencil_tables has flags '$flags'; expected A (allocated)"
[[ "$flags" != *W* ]] || fail "section .stencil_tables has flags '$flags'; expected no W (read-only)"
[ "$((alignment % 64))" -eq 0 ] || fail "section .stencil_tables is aligned to $alignment; expected a multiple of 64"
[ "$((16#$address % 64))" -eq 0 ] || fail "section .stencil_tables starts at 0x$address; expected a multiple of 64"

# The segment that maps it must not be writable either (a read-only section in an RW segment is writable).
segments=$("$readelf" -l -W "$executable") || fail "readelf -l failed"
segment_index=$(awk '/Section to Segment mapping/ { mapping = 1; next }
                     mapping && / \.stencil_tables( |$)/ { print $1 + 0; exit }' <<<"$segments")
[ -n "$segment_index" ] || fail "no segment maps .stencil_tables"
segment=$(awk -v wanted="$segment_index" '/Program Headers/ { table = 1; next }
                                          table && /^  [A-Z]/ && $1 != "Type" { if (index_ == wanted) { print; exit } index_++ }' <<<"$segments")
echo "segment $segment_index: $segment"
[[ "$segment" =~ ^[[:space:]]*LOAD[[:space:]] ]] || fail "segment $segment_index holding .stencil_tables is not a LOAD segment: $segment"
permissions=$(awk '{ for (i = 1; i <= NF; ++i) if ($i ~ /^R?W?E?$/ && $i != "") { print $i; exit } }' <<<"$segment")
[[ "$permissions" != *W* ]] || fail "segment $segment_index holding .stencil_tables is writable ($permissions)"
echo "check-table-section: .stencil_tables is read-only (flags $flags, align $alignment, segment $permissions)"
