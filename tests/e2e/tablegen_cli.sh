#!/usr/bin/env bash
# End-to-end cases for stencil-tablegen and stencil-sample-parts, one function case_NAME per ctest e2e.NAME.
#
# usage: tablegen_cli.sh CASE TABLEGEN SAMPLE_PARTS WORK_ROOT SOURCE_DIR
# Each case runs in a fresh directory under WORK_ROOT (the ctest build folder), removed when the case
# passes and kept, with its path printed, when it fails. Exit 0 pass, 1 fail, 77 skipped.
# Only bash, coreutils, grep, sed, awk, od, dd and gzip (all in a Debian base system); python3 is used
# to parse --json strictly when it happens to be installed.
set -uo pipefail

if [ "$#" -ne 5 ]; then
  echo "usage: $0 CASE TABLEGEN SAMPLE_PARTS WORK_ROOT SOURCE_DIR" >&2
  exit 2
fi
case_name=$1 tablegen=$2 sample_parts=$3 work_root=$4 source_dir=$5

failures=0
status=0

fail() {
  echo "FAIL: $*" >&2
  failures=$((failures + 1))
}

# run PROGRAM ARGS...: runs it in the case's folder; sets status, and keeps stdout/stderr in files.
run() {
  echo "\$ $(basename "$1") ${*:2}"
  "$@" >stdout.txt 2>stderr.txt
  status=$?
  sed 's/^/  stderr: /' stderr.txt
  echo "  exit status $status"
}

tablegen() { run "$tablegen" "$@"; }

expect_status() {
  [ "$status" -eq "$1" ] || fail "exit status $status; expected $1"
}

# expect_stderr EXTENDED_REGEX WHAT
expect_stderr() {
  grep -Eq -- "$1" stderr.txt || fail "stderr does not name $2 (no match for /$1/)"
}

expect_stderr_not() {
  if grep -Eq -- "$1" stderr.txt; then fail "stderr says $2 (matches /$1/)"; fi
}

expect_stderr_names_file() {
  grep -Fq -- "$1" stderr.txt || fail "stderr does not name the file $1"
}

expect_stdout() {
  grep -Eq -- "$1" stdout.txt || fail "stdout does not show $2 (no match for /$1/)"
}

# expect_nothing_written PATH...: none of the paths exists, and no temporary file is left anywhere.
expect_nothing_written() {
  local path
  for path in "$@"; do
    if [ -e "$path" ]; then fail "$path was left behind; expected nothing written"; fi
  done
  local partial
  partial=$(find . -name '*.partial-*' -print)
  if [ -n "$partial" ]; then fail "temporary files left behind: $partial"; fi
}

# expect_refused FILE PLACE_REGEX PLACE_WHAT ARGS...: exit 2, stderr names FILE and the place, no output.
expect_refused() {
  local file=$1 place=$2 what=$3
  shift 3
  tablegen "$@" -o out.stbl
  expect_status 2
  expect_stderr_names_file "$file"
  expect_stderr "$place" "$what"
  expect_nothing_written out.stbl
}

# expect_option_refused OPTION_REGEX WHAT ARGS...: exit 2, stderr names the option, no output.
expect_option_refused() {
  local option=$1 what=$2
  shift 2
  tablegen "$@" -o out.stbl
  expect_status 2
  expect_stderr "$option" "$what"
  expect_nothing_written out.stbl
}

make_sample_parts() {
  run "$sample_parts" .
  [ "$status" -eq 0 ] || fail "stencil-sample-parts exited $status"
}

# put_bytes FILE OFFSET HEX...: overwrites bytes in place (HEX like 7f).
put_bytes() {
  local file=$1 offset=$2
  shift 2
  local text="" byte
  for byte in "$@"; do text+="\\x$byte"; done
  printf "$text" | dd of="$file" bs=1 seek="$offset" conv=notrunc status=none
}

# put_u32 FILE OFFSET VALUE: a little-endian 32-bit integer.
put_u32() {
  local value=$3
  put_bytes "$1" "$2" "$(printf %02x $((value & 255)))" "$(printf %02x $(((value >> 8) & 255)))" \
    "$(printf %02x $(((value >> 16) & 255)))" "$(printf %02x $(((value >> 24) & 255)))"
}

read_u64() { od -An -t u8 -j "$2" -N 8 "$1" | tr -d ' '; }
read_u32() { od -An -t u4 -j "$2" -N 4 "$1" | tr -d ' '; }
file_size() { stat -c %s "$1"; }

# fix_table_crc FILE: recomputes the header's CRC-32 over bytes [20, end) (zlib's CRC-32 is gzip's),
# so a test can corrupt a field the CRC would otherwise catch first.
fix_table_crc() {
  tail -c +21 "$1" | gzip -c | tail -c 8 | head -c 4 | dd of="$1" bs=1 seek=16 conv=notrunc status=none
}

# json_value FILE KEY [DEPTH]: the value of KEY at DEPTH (1: top level, 2: inside tool or source) in
# the output of --inspect --json, which nlohmann::json::dump(2) prints one key per line.
json_value() {
  local indent
  indent=$(printf '%*s' $((2 * ${3:-1})) '')
  sed -n "s/^$indent\"$2\": \\(.*\\)$/\\1/p" "$1" | head -n 1 | sed 's/,$//; s/^"//; s/"$//'
}

# check_json FILE: without python3 (CI has none), a line-by-line check of the form that
# nlohmann::json::dump(2) prints: brackets balanced, every line a key and a value or a lone value,
# strings and numbers well-formed, commas between items and none before a closing bracket.
# A strict parse as well when python3 happens to be installed.
check_json() {
  local file=$1
  awk 'BEGIN { depth = 0; bad = 0; string = "\"([^\"\\\\]|\\\\.)*\""
               number = "-?(0|[1-9][0-9]*)(\\.[0-9]+)?([eE][-+]?[0-9]+)?"
               scalar = "(" string "|" number "|true|false|null)" }
       function fault(why) { if (!bad) print "  json line " NR ": " why ": " $0; bad = 1 }
       { line = $0; sub(/^ +/, "", line)
         closing = line ~ /^[]}]/
         if (NR > 1 && closing && previous_comma) fault("comma before a closing bracket")
         if (NR > 1 && !closing && !previous_comma && !previous_open) fault("missing comma")
         if (line ~ /^[]}],?$/) { depth--; if (depth < 0) fault("unbalanced") }
         else if (line ~ "^(" string ": )?[[{]$") depth++
         else if (line !~ "^(" string ": )?" scalar ",?$") fault("not a key and a value")
         if (NR == 1 && line != "{") fault("does not begin with {")
         previous_comma = line ~ /,$/; previous_open = line ~ /[[{]$/ }
       END { if (depth != 0) fault("unbalanced brackets at the end"); exit bad }' "$file" ||
    fail "--inspect --json output is not well-formed JSON"
  if command -v python3 >/dev/null 2>&1 && python3 -c 'import json' >/dev/null 2>&1; then
    if python3 -c 'import json, sys; json.load(open(sys.argv[1]))' "$file" 2>python3.txt; then
      echo "  (also parsed with python3)"
    else
      fail "--inspect --json output does not parse: $(tail -n 1 python3.txt)"
    fi
  fi
}

# ---------------------------------------------------------------------------------------------------
# A shipped sample part by name (sample:NAME): from the build tree's parts/ here (installed, from
# share/stencil/parts: e2e.sim_installed_programs_find_their_page_and_parts); an unknown name is
# refused naming where it looked and which there are, and nothing is written.

case_sample_part_by_name() {
  local build
  build=$(cd "$(dirname "$tablegen")/.." && pwd)
  tablegen sample:thin_fin --tool ball:d=3 -o fin.stbl --quiet
  expect_status 0
  [ -s fin.stbl ] || fail "no table from sample:thin_fin"
  tablegen "$build/parts/thin_fin.stl" --tool ball:d=3 -o by_path.stbl --quiet
  cmp -s fin.stbl by_path.stbl || fail "sample:thin_fin is not the build tree's parts/thin_fin.stl"
  tablegen sample:no_such --tool ball:d=3 -o none.stbl
  expect_status 2
  expect_stderr "sample:no_such: no such sample part in $build/parts \\(expected sample:NAME with NAME one of .*thin_fin" \
    "where it looked and which parts there are"
  [ ! -e none.stbl ] || fail "a table was written for an unknown sample"
}

# ---------------------------------------------------------------------------------------------------
# Bad STL input: exit 2, the file and the place named, nothing written.

case_empty_stl_is_refused() {
  : >empty.stl
  expect_refused empty.stl 'empty' "that the file is empty" empty.stl --tool ball:d=3
  # A binary header that promises no triangles is as empty.
  make_sample_parts
  head -c 84 thin_fin.stl >no_triangles.stl
  put_u32 no_triangles.stl 80 0
  expect_refused no_triangles.stl '0 triangles' "the triangle count" no_triangles.stl --tool ball:d=3
}

case_ascii_stl_without_facets_is_refused() {
  printf 'solid nothing\nendsolid nothing\n' >no_facets.stl
  expect_refused no_facets.stl 'facet' "the missing facets" no_facets.stl --tool ball:d=3
  # There is nothing to be degenerate: the message must say the file has no facets.
  expect_stderr_not 'degenerate' "that facets are degenerate, for a file without any"
}

case_truncated_binary_stl_is_refused() {
  make_sample_parts
  head -c 500 thin_fin.stl >truncated.stl  # 12 facets need 84 + 12 * 50 = 684 bytes
  expect_refused truncated.stl '\b500\b' "the file's size (500 bytes)" truncated.stl --tool ball:d=3
  expect_stderr '\b684\b' "the size the header's triangle count needs (684 bytes)"
}

case_truncated_binary_stl_with_solid_header_is_refused() {
  # Many CAD programs begin a binary STL's 80-byte header with "solid"; truncated, it must still be
  # reported as a binary file whose size disagrees with its count, not as an ASCII syntax error.
  make_sample_parts
  cp thin_fin.stl solid_header.stl
  put_bytes solid_header.stl 0 73 6f 6c 69 64 20 66 69 6e  # "solid fin"
  head -c 500 solid_header.stl >truncated.stl
  tablegen solid_header.stl -o whole.stbl --tool ball:d=3 --place center --quiet
  expect_status 0
  expect_refused truncated.stl '\b500\b' "the file's size (500 bytes)" truncated.stl --tool ball:d=3 --place center
  expect_stderr '\b684\b|binary' "that it is a binary STL whose count needs 684 bytes"
}

case_binary_triangle_count_disagreeing_with_size_is_refused() {
  make_sample_parts
  cp thin_fin.stl more.stl
  put_u32 more.stl 80 13  # one more than the 12 facets present
  expect_refused more.stl '13 triangles' "the header's triangle count" more.stl --tool ball:d=3 --place center
  expect_stderr '\b684\b' "the file's size"
  cp thin_fin.stl fewer.stl
  put_u32 fewer.stl 80 11
  expect_refused fewer.stl '11 triangles' "the header's triangle count" fewer.stl --tool ball:d=3 --place center
  expect_stderr '\b684\b' "the file's size"
}

case_binary_nan_coordinate_is_refused() {
  make_sample_parts
  cp thin_fin.stl nan.stl
  put_bytes nan.stl $((84 + 2 * 50 + 12 + 12 * 1 + 4 * 1)) 00 00 c0 7f  # facet 2, vertex 1, y = NaN
  expect_refused nan.stl 'facet 2\b.*byte (208|212)\b' "facet 2 and its byte offset" nan.stl --tool ball:d=3 --place center
  expect_stderr 'vertex 1' "the vertex"
  expect_stderr '[Nn]a[Nn]|non-finite|not finite' "what is wrong (NaN)"
}

case_binary_inf_coordinate_is_refused() {
  make_sample_parts
  cp thin_fin.stl inf.stl
  put_bytes inf.stl $((84 + 5 * 50 + 12 + 12 * 2 + 4 * 2)) 00 00 80 ff  # facet 5, vertex 2, z = -Inf
  expect_refused inf.stl 'facet 5\b.*byte (370|378)\b' "facet 5 and its byte offset" inf.stl --tool ball:d=3 --place center
  expect_stderr 'vertex 2' "the vertex"
  expect_stderr 'inf|non-finite|not finite' "what is wrong (infinity)"
}

case_ascii_nan_coordinate_is_refused() {
  make_sample_parts
  sed '12s/.*/      vertex 25 nan 0/' hex_prism.stl >nan.stl
  expect_refused nan.stl 'line 12\b' "line 12" nan.stl --tool ball:d=3
  expect_stderr 'nan|not finite' "what is wrong (NaN)"
}

case_ascii_inf_coordinate_is_refused() {
  make_sample_parts
  sed '21s/.*/      vertex 29 19.4282032 -inf/' hex_prism.stl >inf.stl
  expect_refused inf.stl 'line 21\b' "line 21" inf.stl --tool ball:d=3
  expect_stderr 'inf|not finite' "what is wrong (infinity)"
  # A number too large for a double is as bad as infinity.
  sed '21s/.*/      vertex 29 19.4282032 1e999/' hex_prism.stl >huge.stl
  expect_refused huge.stl 'line 21\b' "line 21" huge.stl --tool ball:d=3
}

case_ascii_several_solids_are_all_read() {
  make_sample_parts
  # A second solid: the same prism moved 16 mm to -x, so the two touch at one edge.
  awk '$1 == "vertex" { $2 = $2 - 16; print "      " $0; next } { sub(/hex_prism/, "second"); print }' \
    hex_prism.stl >second.stl
  cat hex_prism.stl second.stl >two_solids.stl
  tablegen two_solids.stl -o two_solids.stbl --tool ball:d=3 --quiet
  expect_status 0
  expect_stderr "two_solids\.stl: 2 'solid' blocks" "the file and the number of solids"
  expect_stderr 'all of them were read' "that all solids were read"
  [ -f two_solids.stbl ] || fail "two_solids.stbl was not written"
  tablegen --inspect two_solids.stbl --json
  expect_status 0
  cp stdout.txt two_solids.json
  [ "$(json_value two_solids.json triangles)" = 48 ] ||
    fail "the table has $(json_value two_solids.json triangles) triangles; expected 48 (24 from each solid)"
}

case_some_degenerate_facets_are_dropped_and_counted() {
  make_sample_parts
  # Facet 2 collapsed to a point, facet 3 to a line (three collinear vertices).
  awk '/facet normal/ { facet++; corner = 0 }
       $1 == "vertex" && facet == 2 { print "      vertex 25 12.5 6"; next }
       $1 == "vertex" && facet == 3 { corner++; print "      vertex " 20 + corner " 12.5 3"; next }
       { print }' hex_prism.stl >degenerate.stl
  tablegen degenerate.stl -o degenerate.stbl --tool ball:d=3 --quiet
  expect_status 0
  expect_stderr 'degenerate\.stl: dropped 2 degenerate' "the file and how many facets were dropped"
  [ -f degenerate.stbl ] || fail "degenerate.stbl was not written"
  tablegen --inspect degenerate.stbl --json
  expect_status 0
  cp stdout.txt degenerate.json
  [ "$(json_value degenerate.json degenerate_dropped 2)" = 2 ] || fail "the table records $(json_value degenerate.json degenerate_dropped 2) degenerate facets dropped; expected 2"
  [ "$(json_value degenerate.json triangles)" = 22 ] || fail "the table has $(json_value degenerate.json triangles) triangles; expected 22"
}

case_all_degenerate_facets_are_refused() {
  make_sample_parts
  awk '$1 == "vertex" { print "      vertex 1 1 1"; next } { print }' hex_prism.stl >all_degenerate.stl
  expect_refused all_degenerate.stl 'all 24 facets.*degenerate' "that all 24 facets are degenerate" \
    all_degenerate.stl --tool ball:d=3
}

case_ascii_syntax_error_names_the_line() {
  make_sample_parts
  sed '12s/vertex/vertx/' hex_prism.stl >misspelt.stl
  expect_refused misspelt.stl 'line 12\b' "line 12" misspelt.stl --tool ball:d=3
  expect_stderr "expected 'vertex'" "what was expected"
  sed '29s/.*/      vertex 33 12.5.0 6/' hex_prism.stl >bad_number.stl
  expect_refused bad_number.stl 'line 29\b' "line 29" bad_number.stl --tool ball:d=3
  expect_stderr 'number' "that a number was expected"
}

case_ascii_file_ending_inside_a_solid_is_refused() {
  make_sample_parts
  head -n 30 hex_prism.stl >cut.stl
  expect_refused cut.stl 'line 3[01]\b' "the line where the file ends" cut.stl --tool ball:d=3
  expect_stderr 'end of the file|ends' "that the file ends early"
}

case_part_that_is_a_directory_is_refused() {
  mkdir part.stl
  expect_refused part.stl 'directory|not a regular file' "that the part is a directory" part.stl --tool ball:d=3
}

case_missing_part_is_refused() {
  expect_refused missing.stl 'cannot open|[Nn]o such file' "that the file is missing" missing.stl --tool ball:d=3
}

# ---------------------------------------------------------------------------------------------------
# Parts the controller cannot take.

case_part_outside_workspace_names_the_axis() {
  make_sample_parts  # the hex prism spans x [17, 33], y [5.57, 19.43], z [0, 6]
  expect_refused hex_prism.stl '\bx \[17, 33\].*workspace \[0, 30\]' "axis x and its ranges" \
    hex_prism.stl --tool ball:d=3 --workspace 30,25,25
  expect_refused hex_prism.stl '\by \[.*workspace \[0, 15\]' "axis y and its ranges" \
    hex_prism.stl --tool ball:d=3 --workspace 50,15,25
  expect_refused hex_prism.stl '\bz \[0, 6\].*workspace \[0, 5\]' "axis z and its ranges" \
    hex_prism.stl --tool ball:d=3 --workspace 50,25,5
  expect_refused hex_prism.stl '\bx \[' "axis x, when centred but too large" \
    hex_prism.stl --tool ball:d=3 --scale 10 --place center
}

case_more_points_than_capacity_is_refused() {
  # A flat 3 mm end mill at the default --max-gouge needs a covering radius of 0.004 mm.
  run "$sample_parts" --dome 2000 dome.stl
  [ "$status" -eq 0 ] || fail "stencil-sample-parts --dome exited $status"
  expect_refused dome.stl 'needs [0-9]+ points.*capacity of 4194304' "the points needed and the capacity" \
    dome.stl --tool flat:d=3
  expect_stderr '--max-gouge' "the option that would help"
}

# ---------------------------------------------------------------------------------------------------
# Output paths.

case_output_under_missing_directory_is_refused() {
  make_sample_parts
  tablegen hex_prism.stl --tool ball:d=3 -o missing/folder/out.stbl
  expect_status 2
  expect_stderr_names_file missing/folder/out.stbl
  expect_stderr 'No such file|cannot' "why it cannot be written"
  expect_nothing_written missing
}

case_output_that_is_a_directory_is_refused() {
  make_sample_parts
  mkdir existing.stbl
  tablegen hex_prism.stl --tool ball:d=3 -o existing.stbl
  expect_status 2
  expect_stderr_names_file existing.stbl
  expect_stderr '[Ii]s a directory' "why it cannot be written"
  [ -d existing.stbl ] || fail "existing.stbl is no longer a directory"
  [ -z "$(ls -A existing.stbl)" ] || fail "something was written into existing.stbl/"
  expect_nothing_written
}

case_output_in_read_only_directory_is_refused() {
  # Root writes through a mode of 0555, so this case means something only for other users.
  if [ "$(id -u)" -eq 0 ]; then
    echo "SKIP: running as root, where a read-only directory mode does not stop writes"
    exit 77
  fi
  make_sample_parts
  mkdir read_only
  chmod 0555 read_only
  tablegen hex_prism.stl --tool ball:d=3 -o read_only/out.stbl
  chmod 0755 read_only
  expect_status 2
  expect_stderr_names_file read_only/out.stbl
  expect_stderr '[Pp]ermission denied' "why it cannot be written"
  expect_nothing_written read_only/out.stbl
}

case_refused_run_keeps_the_previous_table() {
  make_sample_parts
  tablegen hex_prism.stl --tool ball:d=3 -o out.stbl --quiet
  expect_status 0
  cp out.stbl previous.stbl
  sed '12s/.*/      vertex 25 nan 0/' hex_prism.stl >nan.stl
  tablegen nan.stl --tool ball:d=3 -o out.stbl
  expect_status 2
  cmp out.stbl previous.stbl || fail "a refused run changed the existing out.stbl"
  expect_nothing_written
}

# ---------------------------------------------------------------------------------------------------
# Options.

case_coarse_spacing_is_refused_without_force() {
  make_sample_parts
  expect_option_refused '--spacing 0\.5\b.*--max-gouge 0\.004\b' "--spacing, its gouge bound and --max-gouge" \
    hex_prism.stl --tool ball:d=3 --spacing 0.5
  expect_stderr '--force' "the way to insist"
  tablegen hex_prism.stl --tool ball:d=3 --spacing 0.5 --force -o forced.stbl --quiet
  expect_status 0
  [ -f forced.stbl ] || fail "--force did not write forced.stbl"
  tablegen --inspect forced.stbl --json
  expect_status 0
  cp stdout.txt forced.json
  [ "$(json_value forced.json requested_spacing_mm)" = 0.5 ] ||
    fail "the forced table asked for spacing $(json_value forced.json requested_spacing_mm); expected 0.5"
}

case_unknown_tool_kind_is_refused() {
  make_sample_parts
  expect_option_refused "--tool 'drill:d=3'" "--tool and the spec" hex_prism.stl --tool drill:d=3
  expect_stderr 'flat:d=D.*ball:d=D.*bull:d=D,r=RC' "the kinds expected"
}

case_tool_without_diameter_is_refused() {
  make_sample_parts
  expect_option_refused "--tool 'ball:l=3'.*d=D" "--tool and the missing d" hex_prism.stl --tool ball:l=3
  expect_option_refused "--tool 'flat'.*d=D" "--tool and the missing d" hex_prism.stl --tool flat
}

case_corner_radius_larger_than_radius_is_refused() {
  make_sample_parts
  expect_option_refused '--tool.*corner_radius_mm 2\b.*cutter radius' "--tool, the corner radius and the limit" \
    hex_prism.stl --tool bull:d=3,r=2
  expect_option_refused "--tool 'bull:d=3'.*r=RC" "--tool and the missing r" hex_prism.stl --tool bull:d=3
}

case_malformed_tool_keys_are_refused() {
  make_sample_parts
  expect_option_refused "--tool: d='abc'" "the key and its value" hex_prism.stl --tool ball:d=abc
  expect_option_refused "--tool: key 'd' given twice" "the repeated key" hex_prism.stl --tool ball:d=3,d=4
  expect_option_refused "--tool: unknown key 'r'" "the unknown key" hex_prism.stl --tool flat:d=3,r=1
  expect_option_refused '--tool.*diameter_mm -3\b' "the field and value" hex_prism.stl --tool ball:d=-3
  expect_option_refused '--holder.*holder_diameter_mm 2\b' "the holder field and value" \
    hex_prism.stl --tool ball:d=3 --holder d=2
}

# ---------------------------------------------------------------------------------------------------
# --inspect on bad tables: exit 2, the file and the field named.

make_table() {
  make_sample_parts
  tablegen hex_prism.stl --tool ball:d=3 -o good.stbl --quiet
  [ "$status" -eq 0 ] || fail "could not generate good.stbl"
}

case_inspect_refuses_corrupted_table() {
  make_table
  cp good.stbl corrupted.stbl
  put_bytes corrupted.stbl $(($(file_size good.stbl) / 2)) a5
  cmp -s good.stbl corrupted.stbl && fail "the corruption did not change the file"
  tablegen --inspect corrupted.stbl
  expect_status 2
  expect_stderr_names_file corrupted.stbl
  expect_stderr 'header\.crc32' "the field header.crc32"
  tablegen --inspect corrupted.stbl --json
  expect_status 2
  expect_stderr 'header\.crc32' "the field header.crc32 (with --json)"
  [ -s stdout.txt ] && fail "--inspect --json printed a description of a corrupted table"
  return 0
}

case_inspect_refuses_truncated_table() {
  make_table
  head -c 100000 good.stbl >truncated.stbl
  tablegen --inspect truncated.stbl
  expect_status 2
  expect_stderr_names_file truncated.stbl
  expect_stderr 'header\.file_bytes' "the field header.file_bytes"
  head -c 100 good.stbl >stub.stbl
  tablegen --inspect stub.stbl
  expect_status 2
  expect_stderr_names_file stub.stbl
  expect_stderr 'header\b.*512 bytes' "the header and its size"
}

case_inspect_names_exact_sizes_of_a_truncated_table() {
  # The numbers in the message are the ones to compare with ls -l: printed whole, not rounded.
  make_table
  head -c 100000 good.stbl >truncated.stbl
  tablegen --inspect truncated.stbl
  expect_status 2
  expect_stderr "\\b$(file_size good.stbl)\\b" "the header's file_bytes exactly ($(file_size good.stbl))"
  expect_stderr_not 'e\+0[0-9]' "a size in floating-point notation"
}

case_inspect_refuses_table_with_bad_magic() {
  make_table
  cp good.stbl magic.stbl
  put_bytes magic.stbl 0 58  # "XTENCILT"
  tablegen --inspect magic.stbl
  expect_status 2
  expect_stderr_names_file magic.stbl
  expect_stderr 'header\.magic' "the field header.magic"
  make_sample_parts
  tablegen --inspect hex_prism.stl
  expect_status 2
  expect_stderr 'header\.magic' "the field header.magic, for an STL given as a table"
}

case_inspect_refuses_non_finite_point_with_a_valid_crc() {
  make_table
  cp good.stbl nan_point.stbl
  points=$(read_u64 good.stbl 64)  # sections[1] (points): offset
  put_bytes nan_point.stbl $((points + 12 * 5 + 4)) 00 00 c0 7f  # point 5, y = NaN
  fix_table_crc nan_point.stbl
  tablegen --inspect nan_point.stbl
  expect_status 2
  expect_stderr_names_file nan_point.stbl
  expect_stderr 'points \(at 5\)' "the field points and the index 5"
}

case_inspect_refuses_wrong_format_version() {
  make_table
  cp good.stbl version.stbl
  put_u32 version.stbl 8 6  # a version after this build's (5)
  tablegen --inspect version.stbl
  expect_status 2
  expect_stderr_names_file version.stbl
  expect_stderr 'header\.format_version' "the field header.format_version"
}

# A table of format version 1 (before the packed leaves), 2 (leaves of 32 points), 3 (no leaf
# moments) or 4 (no group moments) is to be made again, in those words.
case_inspect_of_an_older_table_says_regenerate() {
  make_table
  for version in 1 2 3 4; do
    cp good.stbl old.stbl
    put_u32 old.stbl 8 "$version"
    tablegen --inspect old.stbl
    expect_status 2
    expect_stderr_names_file old.stbl
    expect_stderr "format version $version: regenerate with stencil-tablegen" \
      "format version $version: regenerate with stencil-tablegen"
  done
}

case_inspect_of_a_directory_is_refused() {
  mkdir table.stbl
  tablegen --inspect table.stbl
  expect_status 2
  expect_stderr_names_file table.stbl
  expect_stderr 'directory|not a regular file' "that it is a directory"
}

case_inspect_of_missing_table_is_refused() {
  tablegen --inspect missing.stbl
  expect_status 2
  expect_stderr_names_file missing.stbl
}

# ---------------------------------------------------------------------------------------------------
# --emit-cpp.

case_emit_cpp_writes_the_table_as_a_constant_array() {
  make_sample_parts
  mkdir emitted
  tablegen hex_prism.stl --tool ball:d=3 -o hex_prism.stbl --emit-cpp emitted --quiet
  expect_status 0
  local source=emitted/stencil_table_hex_prism.cpp
  [ -f "$source" ] || { fail "$source was not written"; return; }
  grep -q 'alignas(64) const unsigned char stencil_table_hex_prism\[\] __attribute__((section(".stencil_tables"), used))' \
    "$source" || fail "$source does not declare the aligned constant array in .stencil_tables"
  local size
  size=$(file_size hex_prism.stbl)
  grep -q "^const std::size_t stencil_table_hex_prism_size = $size;" "$source" ||
    fail "$source does not give stencil_table_hex_prism_size = $size (the .stbl's size)"
  local bytes
  bytes=$(grep -o '0x[0-9a-f][0-9a-f],' "$source" | wc -l)
  [ "$bytes" -eq "$size" ] || fail "$source holds $bytes bytes; expected $size"
  # The first bytes are the table's magic, "STENCILT".
  grep -q '0x53, 0x54, 0x45, 0x4e, 0x43, 0x49, 0x4c, 0x54,' "$source" || fail "$source does not begin with the magic"
  expect_nothing_written
}

case_emit_cpp_into_missing_directory_is_refused() {
  make_sample_parts
  expect_option_refused '--emit-cpp nowhere' "--emit-cpp and the folder" hex_prism.stl --tool ball:d=3 --emit-cpp nowhere
  expect_nothing_written nowhere
}

case_emit_cpp_failure_leaves_no_table() {
  # The C++ cannot be written (its name is taken by a directory): exit 2, and no table either.
  make_sample_parts
  mkdir -p emitted/stencil_table_out.cpp
  tablegen hex_prism.stl --tool ball:d=3 -o out.stbl --emit-cpp emitted
  expect_status 2
  expect_stderr_names_file emitted/stencil_table_out.cpp
  expect_nothing_written out.stbl
}

# ---------------------------------------------------------------------------------------------------
# The sample parts: valid tables, the same for any thread count, the same on every run.

placement_of() {
  [ "$1" = hex_prism ] && echo as-is || echo center
}

check_valid_table() {
  local part=$1 place
  place=$(placement_of "$part")
  make_sample_parts
  tablegen "$part.stl" --tool ball:d=3 --place "$place" -o "$part.stbl"
  expect_status 0
  expect_stdout "$part\\.stl -> $part\\.stbl: [0-9]+ triangles, [0-9]+ points" "the summary line"
  [ -f "$part.stbl" ] || { fail "$part.stbl was not written"; return; }
  expect_nothing_written
  tablegen --inspect "$part.stbl"
  expect_status 0
  expect_stdout "$part\\.stbl: valid stencil table" "that the table is valid"
  expect_stdout 'tool +ball d=3\b' "the tool"
  local points_text
  points_text=$(sed -n 's/^  points  *\([0-9][0-9]*\) .*/\1/p' stdout.txt)
  tablegen --inspect "$part.stbl" --json
  expect_status 0
  cp stdout.txt "$part.json"
  check_json "$part.json"
  [ "$(json_value "$part.json" file)" = "$part.stbl" ] || fail "json file is '$(json_value "$part.json" file)'; expected $part.stbl"
  [ "$(json_value "$part.json" bytes)" = "$(file_size "$part.stbl")" ] || fail "json bytes differ from the file's size"
  [ "$(json_value "$part.json" kind 2)" = ball ] || fail "json tool kind is '$(json_value "$part.json" kind 2)'; expected ball"
  [ "$(json_value "$part.json" diameter_mm 2)" = 3.0 ] || fail "json tool diameter is '$(json_value "$part.json" diameter_mm 2)'; expected 3.0"
  [ -n "$points_text" ] && [ "$(json_value "$part.json" points)" = "$points_text" ] ||
    fail "json points '$(json_value "$part.json" points)' differ from the summary's '$points_text'"
  local gouge
  gouge=$(json_value "$part.json" gouge_bound_mm)
  awk -v g="$gouge" 'BEGIN { exit !(g > 0 && g <= 0.004) }' || fail "json gouge_bound_mm $gouge; expected in (0, 0.004]"
}

check_same_for_thread_counts() {
  local part=$1 place
  place=$(placement_of "$part")
  make_sample_parts
  tablegen "$part.stl" --tool ball:d=3 --place "$place" -o one_thread.stbl --threads 1 --quiet "${@:2}"
  expect_status 0
  tablegen "$part.stl" --tool ball:d=3 --place "$place" -o two_threads.stbl --threads 2 --quiet "${@:2}"
  expect_status 0
  cmp one_thread.stbl two_threads.stbl || fail "--threads 1 and --threads 2 wrote different tables"
}

check_reproducible() {
  local part=$1 place
  place=$(placement_of "$part")
  make_sample_parts
  tablegen "$part.stl" --tool ball:d=3 --place "$place" -o first.stbl --quiet
  expect_status 0
  tablegen "$part.stl" --tool ball:d=3 --place "$place" -o second.stbl --quiet
  expect_status 0
  cmp first.stbl second.stbl || fail "two identical runs wrote different tables"
}

case_hex_prism_table_is_valid() { check_valid_table hex_prism; }
case_slotted_block_table_is_valid() { check_valid_table slotted_block; }
case_thin_fin_table_is_valid() { check_valid_table thin_fin; }
case_hex_prism_is_the_same_for_1_and_2_threads() { check_same_for_thread_counts hex_prism; }
case_slotted_block_is_the_same_for_1_and_2_threads() { check_same_for_thread_counts slotted_block; }
case_thin_fin_is_the_same_for_1_and_2_threads() { check_same_for_thread_counts thin_fin; }
case_hex_prism_with_extra_points_is_the_same_for_1_and_2_threads() {
  check_same_for_thread_counts hex_prism --extra-points 5000 --seed 7
}
case_hex_prism_is_reproducible() { check_reproducible hex_prism; }
case_slotted_block_is_reproducible() { check_reproducible slotted_block; }
case_thin_fin_is_reproducible() { check_reproducible thin_fin; }

case_sample_parts_match_the_committed_files() {
  make_sample_parts
  local part
  for part in hex_prism slotted_block thin_fin; do
    cmp "$part.stl" "$source_dir/sim/parts/$part.stl" ||
      fail "sim/parts/$part.stl differs from what stencil-sample-parts writes now (regenerate it: stencil-sample-parts sim/parts)"
  done
}

# ---------------------------------------------------------------------------------------------------

if ! declare -F "case_$case_name" >/dev/null; then
  echo "tablegen_cli.sh: no case '$case_name'; the cases are:" >&2
  declare -F | sed -n 's/^declare -f case_/  /p' >&2
  exit 2
fi

mkdir -p "$work_root" || exit 1
work=$(mktemp -d "$work_root/$case_name.XXXXXX") || exit 1
cd "$work" || exit 1
echo "case $case_name in $work"
"case_$case_name"
if [ "$failures" -ne 0 ]; then
  echo "FAILED: $case_name ($failures failed checks); its files are kept in $work" >&2
  exit 1
fi
cd / && rm -rf "$work"
echo "PASSED: $case_name"
