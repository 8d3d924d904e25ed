#!/usr/bin/env bash
# A refactor's proof that behaviour did not change: stencil-sim of an older commit and of this tree
# run the same deterministic jobs (make demo's, and every case of tests/e2e/sim_cli.sh on the virtual
# clock that sends no signal), and what each wrote is compared, byte for byte where the wall clock
# has no say (issue 19):
#   reports (*.json)      equal apart from wall_s, compute_us, memory_kb and latencies; a field only
#                         the newer report has is listed as added and does not fail
#   journals (*.journal)  equal apart from the start times in the Start and Resume records and those
#                         records' CRC-32s; journals named after their start time
#                         (stencil-sim-YYYYMMDD-HHMMSS.journal) are paired in the order of their names
#   stocks, traces (*.csv) and pictures (*.png; *.svg before issue 25): byte for byte
#   the runs              each command, its exit status and what it wrote on stderr
# A file on one side only, a journal that cannot be read, a case that wrote nothing: all fail.
#
# usage: same-behaviour.sh OLD_COMMIT [NEW_BUILD_DIR]
#   OLD_COMMIT     anything git names a commit by; it is built in a worktree under
#                  build/same-behaviour/old (its own release preset), and kept for the next run
#   NEW_BUILD_DIR  this tree's configured build (default build, make build's); brought up to date
# SAME_BEHAVIOUR_JOBS (default: the CPU count) compiles in parallel; SAME_BEHAVIOUR_CASES="demo
# plunge ..." runs only those (a quick look, not the proof: the summary says so).
# Exit 0 every job the same, 1 something differs, 2 usage or build failure.
set -uo pipefail

if [ "$#" -lt 1 ] || [ "$#" -gt 2 ]; then
  echo "usage: $0 OLD_COMMIT [NEW_BUILD_DIR]" >&2
  exit 2
fi
repo=$(cd "$(dirname "$0")/.." && pwd -P)
new_build=$(realpath -m "${2:-$repo/build}")
out=$repo/build/same-behaviour
jobs=${SAME_BEHAVIOUR_JOBS:-$(nproc)}
sim_cli=$repo/tests/e2e/sim_cli.sh
started=$(date +%s)

die() {
  echo "same-behaviour: $*" >&2
  exit 2
}

old_commit=$(git -C "$repo" rev-parse --verify --quiet "$1^{commit}") || die "$1: not a commit in $repo"
old_name=$(git -C "$repo" rev-parse --short "$old_commit")
[ -f "$new_build/CMakeCache.txt" ] || die "$new_build: not a configured build (make build, or cmake --preset release)"

# --- The jobs -------------------------------------------------------------------------------------

# Why a case of sim_cli.sh is left out, or nothing when it runs: cases on the wall clock (a signal
# mid-cut, --speed 1) give different outputs each time, and stencil-rig is not stencil-sim.
left_out() {
  case $1 in
    sigterm_* | sighup_* | sigquit_* | kill_*) echo "a signal mid-cut (the wall clock decides when)" ;;
    rig_*) echo "stencil-rig" ;;
    job_and_its_resume_share_one_folder) echo "its resume names the job's folder, which older builds do not make" ;;
    retention_keeps_an_interrupted_job) echo "a SIGKILL once the journal is open (the wall clock decides when)" ;;
    refuses_a_bad_display_option) echo "its last refusal is stencil-rig's" ;;
  esac
}

all_cases=$(sed -nE 's/^case_([a-z0-9_]+)\(\).*/\1/p' "$sim_cli")
[ -n "$all_cases" ] || die "$sim_cli: no case_NAME() functions"
job_names=(demo)
left_out_lines=()
for name in $all_cases; do
  reason=$(left_out "$name")
  if [ -n "$reason" ]; then
    left_out_lines+=("left out  $name: $reason")
  else
    job_names+=("$name")
  fi
done
if [ -n "${SAME_BEHAVIOUR_CASES:-}" ]; then
  for name in $SAME_BEHAVIOUR_CASES; do
    [[ " ${job_names[*]} " == *" $name "* ]] || die "SAME_BEHAVIOUR_CASES: '$name' is not a job here (demo or a case that is not left out)"
  done
  read -r -a job_names <<<"$SAME_BEHAVIOUR_CASES"
fi

# make demo's job, as the Makefile has it, run in the job's folder: its outputs named with --journal and
# --report, which every build takes (its --out-dir and --keep-jobs, for a job folder named after the
# wall clock, left out; older builds have neither).
demo_line=$(sed -n '/^demo:/,/^$/p' "$repo/Makefile" | grep -m1 'build/bin/stencil-sim ') ||
  die "$repo/Makefile: no stencil-sim command under demo:"
read -r -a demo_arguments <<<"$(echo "$demo_line" | sed -E -e 's|^[[:space:]]*build/bin/stencil-sim||' -e 's|build/demo/||g' \
  -e 's/--(out-dir|keep-jobs|keep-mb|journal|report)[ =][^ ]+//g')"
demo_arguments+=(--journal job.journal --report report.json)

# --- The two builds -------------------------------------------------------------------------------

# The older commit in a worktree of its own (reused, moved to OLD_COMMIT, when one is there already).
old_src=$out/old/src
old_build=$out/old/build
mkdir -p "$out/old"
if git -C "$old_src" rev-parse --git-dir >/dev/null 2>&1 &&
  [ "$(git -C "$old_src" rev-parse --show-toplevel)" = "$old_src" ]; then
  git -C "$old_src" checkout --quiet --force --detach "$old_commit" || die "$old_src: cannot check out $1"
else
  # --force: the path may still be registered from a build/ that was removed since.
  rm -rf "$old_src"
  git -C "$repo" worktree add --quiet --force --detach "$old_src" "$old_commit" || die "cannot make a worktree of $1 in $old_src"
fi

# build DIR TARGET...: brings the targets up to date, its output in DIR/same-behaviour-build.log.
build() {
  local dir=$1 log=$1/same-behaviour-build.log
  shift
  if ! cmake --build "$dir" -j "$jobs" --target "$@" >"$log" 2>&1; then
    tail -n 30 "$log" >&2
    die "building $* in $dir failed (all of it in $log)"
  fi
}

echo "same-behaviour: old is $(git -C "$repo" log -1 --format='%h (%s)' "$old_commit"), built in $old_build"
# The older commit's own release preset, in a folder of ours.
cmake -S "$old_src" -B "$old_build" --preset release >"$out/old/configure.log" 2>&1 ||
  { tail -n 30 "$out/old/configure.log" >&2; die "configuring $old_src failed (all of it in $out/old/configure.log)"; }
build "$old_build" stencil-sim
echo "same-behaviour: new is this tree, built in $new_build"
build "$new_build" stencil-sim stencil-same-behaviour
compare=$new_build/bin/stencil-same-behaviour

# run_jobs SIDE SIM: every job with SIM; its folders end up in runs/SIDE/<job> and each job's log
# (sim_cli.sh's account of its runs) and exit status in runs/SIDE/log. Both sides run in the same
# folder (work), one after the other, so that a path in an output is the same on both.
run_jobs() {
  local side=$1 sim=$2 work=$out/work name begin
  rm -rf "$work" "$out/runs/$side"
  mkdir -p "$work/log" "$out/runs"
  begin=$(date +%s)
  printf 'same-behaviour: running %d jobs with the %s stencil-sim ' "${#job_names[@]}" "$side"
  for name in "${job_names[@]}"; do
    if [ "$name" = demo ]; then
      mkdir -p "$work/demo"
      (
        cd "$work/demo" || exit 1
        echo "\$ stencil-sim ${demo_arguments[*]}"
        "$sim" "${demo_arguments[@]}" >stdout.txt 2>stderr.txt
        status=$?
        sed 's/^/  stderr: /' stderr.txt
        echo "  exit status $status"
      ) >"$work/log/demo.log" 2>&1
      echo 0 >"$work/log/demo.status"
    else
      SIM_CLI_KEEP=1 bash "$sim_cli" "$name" "$sim" "$work" >"$work/log/$name.log" 2>&1
      echo $? >"$work/log/$name.status"
      mv "$work/sim_$name" "$work/$name" 2>/dev/null
      # The fault cases resume against this case's stock, which sim_cli.sh shares only when every
      # check passed: an older build may fail a newer check and still have run the same job.
      if [ "$name" = reference_job ] && [ ! -s "$work/shared/reference.csv" ] && [ -s "$work/$name/reference.csv" ]; then
        cp "$work/$name/reference.csv" "$work/shared/reference.csv"
      fi
    fi
    printf '.'
  done
  mv "$work" "$out/runs/$side"
  echo " $(($(date +%s) - begin)) s"
}

run_jobs old "$old_build/bin/stencil-sim"
run_jobs new "$new_build/bin/stencil-sim"

# --- The comparison -------------------------------------------------------------------------------

# outputs DIR: "key<TAB>path" for each file compared, sorted by key; a journal named after its start
# time gets the key stencil-sim-<n>.journal, n its place among those in its folder. A job's own folder
# under the case's $XDG_STATE_HOME (sim_cli.sh's xdg-state/stencil/jobs/stencil-sim-YYYYMMDD-HHMMSS/)
# is taken as the case's folder with the names builds before job folders gave: its job.journal as a
# journal named after its start time, report.json and its picture as stencil-sim-report.*.
outputs() {
  (cd "$1" && find . -type f \( -name '*.json' -o -name '*.journal' -o -name '*.csv' -o -name '*.png' -o -name '*.svg' \) | sed 's|^\./||' | LC_ALL=C sort) |
    awk '{
      n = split($0, parts, "/")
      folder = substr($0, 1, length($0) - length(parts[n]))
      key = $0
      stamp = "stencil-sim-[0-9][0-9][0-9][0-9][0-9][0-9][0-9][0-9]-[0-9][0-9][0-9][0-9][0-9][0-9]"
      if ($0 ~ ("^xdg-state/stencil/jobs/" stamp "(-[0-9]+)?/[^/]+$")) {
        folder = ""
        key = parts[n] ~ /^report[.]/ ? "stencil-sim-" parts[n] : parts[n]
        if (parts[n] == "job.journal") {
          key = "stencil-sim-(start time " (++count[folder]) ").journal"
        }
      } else if (parts[n] ~ ("^" stamp "[.]journal$")) {
        key = folder "stencil-sim-(start time " (++count[folder]) ").journal"
      }
      print key "\t" $0
    }' | LC_ALL=C sort -t "$(printf '\t')" -k1,1
}

# runs LOG: what the runs did, as sim_cli.sh logs it: each command, its stderr, its exit status.
runs() {
  grep -E '^(\$ |  stderr: |  exit status )' "$1"
}

same=0 different=0 skipped=0
added_fields=()
for name in "${job_names[@]}"; do
  old_dir=$out/runs/old/$name new_dir=$out/runs/new/$name
  old_status=$(cat "$out/runs/old/log/$name.status") new_status=$(cat "$out/runs/new/log/$name.status")
  if [ "$old_status" = 77 ] && [ "$new_status" = 77 ]; then
    echo "skipped   $name: does not apply here ($(grep -v '^\$' "$out/runs/new/log/$name.log" | head -n 1))"
    skipped=$((skipped + 1))
    continue
  fi
  problems=() notes=() compared=0 added=0
  if [ "$old_status" = 77 ] || [ "$new_status" = 77 ]; then
    problems+=("sim_cli.sh skipped it with one build only (exit status $old_status old, $new_status new)")
  fi
  # The runs: the same commands, exit statuses and stderr.
  run_difference=$(diff <(runs "$out/runs/old/log/$name.log") <(runs "$out/runs/new/log/$name.log") | grep -E '^[<>]' | head -n 4)
  [ -z "$run_difference" ] || problems+=("the runs differ (< old, > new):" "$run_difference")
  run_count=$(runs "$out/runs/new/log/$name.log" | grep -c '^\$ ')
  refusals=$(runs "$out/runs/new/log/$name.log" | grep -c '^  exit status 2$')
  # The files, paired by key.
  if [ ! -d "$old_dir" ] || [ ! -d "$new_dir" ]; then
    problems+=("no folder: $old_dir or $new_dir")
  else
    while IFS=$'\t' read -r side key old_path new_path; do
      case $side in
        old) problems+=("$key: only the old build wrote it") ;;
        new) problems+=("$key: only the new build wrote it") ;;
        both)
          compared=$((compared + 1))
          case $key in
            *.json) result=$("$compare" report "$old_dir/$old_path" "$new_dir/$new_path" 2>&1) ;;
            *.journal) result=$("$compare" journal "$old_dir/$old_path" "$new_dir/$new_path" 2>&1) ;;
            *) result=$(cmp "$old_dir/$old_path" "$new_dir/$new_path" 2>&1) ;;
          esac
          status=$?
          # Not a journal on either side, and the same bytes: an input the case wrote for a refusal
          # (junk.journal), or equally broken in both builds. Said, not passed over.
          if [ "$status" -eq 2 ] && [[ $key == *.journal ]] && cmp -s "$old_dir/$old_path" "$new_dir/$new_path"; then
            notes+=("$key is no journal in either, the same bytes")
            status=0
          fi
          if [ "$status" -ne 0 ]; then
            problems+=("$key: $(echo "$result" | grep -v '^added: ' | head -n 6)")
          fi
          while read -r field; do
            added=$((added + 1))
            added_fields+=("${field%% = *}")
          done < <(echo "$result" | sed -n 's/^added: //p')
          ;;
      esac
    done < <(LC_ALL=C join -t $'\t' -a 1 -a 2 -e - -o 0,1.2,2.2 <(outputs "$old_dir") <(outputs "$new_dir") |
      awk -F '\t' '{ print ($2 == "-" ? "new" : $3 == "-" ? "old" : "both") "\t" $1 "\t" $2 "\t" $3 }')
  fi
  # Never a silent pass: a job must have written something, or be refusals only.
  if [ "$compared" -eq 0 ] && { [ "$run_count" -eq 0 ] || [ "$refusals" -ne "$run_count" ]; }; then
    problems+=("nothing to compare: no report, journal or other output, and not all of its $run_count run(s) refused")
  fi
  if [ "${#problems[@]}" -eq 0 ]; then
    what="$compared file(s), $run_count run(s)"
    [ "$compared" -gt 0 ] || what="$run_count refusal(s): exit statuses and messages"
    [ "$added" -eq 0 ] || what="$what; $added field(s) added"
    [ "${#notes[@]}" -eq 0 ] || what="$what; $(printf '%s; ' "${notes[@]}" | sed 's/; $//')"
    echo "same      $name ($what)"
    same=$((same + 1))
  else
    echo "DIFFERENT $name:"
    printf '%s\n' "${problems[@]}" | sed 's/^/            /'
    different=$((different + 1))
  fi
done
for line in "${left_out_lines[@]}"; do
  [ -z "${SAME_BEHAVIOUR_CASES:-}" ] && echo "$line"
done
if [ "${#added_fields[@]}" -gt 0 ]; then
  echo "added in the new reports (allowed): $(printf '%s\n' "${added_fields[@]}" | sort -u | paste -sd ' ')"
fi

total=${#job_names[@]}
subset=""
[ -z "${SAME_BEHAVIOUR_CASES:-}" ] || subset=" (only SAME_BEHAVIOUR_CASES: not the whole proof)"
echo "same-behaviour: $same of $total jobs the same as $old_name, $different different, $skipped skipped$subset;" \
  "$(($(date +%s) - started)) s; the outputs are in $out/runs"
[ "$different" -eq 0 ] && [ "$same" -gt 0 ]
