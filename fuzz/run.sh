#!/usr/bin/env bash
# Runs each libFuzzer program of the `fuzz` preset for a fixed time, one after the
# other, and fails if any finds a crash.
# usage: bash fuzz/run.sh SECONDS_EACH [TARGET...]   (default: every target)
#   TILTH_FUZZ_BUILD   the fuzz build folder (default build-fuzz)
#   TILTH_FUZZ_WORK    where corpora grow and crashers land (default $TILTH_FUZZ_BUILD/fuzz-work)
# Each target starts from its seeds (fuzz/corpus/T) and its crashers so far
# (fuzz/regressions/T), and keeps what it finds in $TILTH_FUZZ_WORK/T/corpus, so later
# runs go on from there. A crasher is written to $TILTH_FUZZ_WORK/T/crash-*: copy it to
# fuzz/regressions/T/ (docs/reliability.md). The fuzzer's own log goes to
# $TILTH_FUZZ_WORK/T/log, and its last lines to the terminal. A crash of a target listed
# in fuzz/open-crashes.txt (its fix not on main yet) is reported but does not fail.
set -euo pipefail
cd "$(dirname "$0")/.."

if [ $# -lt 1 ] || ! [[ $1 =~ ^[0-9]+$ ]]; then
  echo "usage: bash fuzz/run.sh SECONDS_EACH [TARGET...]" >&2
  exit 2
fi
seconds=$1
shift
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(graph_file calibration frames_csv mcap_reader modbus_request)
build=${TILTH_FUZZ_BUILD:-build-fuzz}
work=${TILTH_FUZZ_WORK:-$build/fuzz-work}

failed=()
open=()
for target in "${targets[@]}"; do
  program="$build/bin/fuzz_$target"
  [ -x "$program" ] || { echo "fuzz: $program is not built (cmake --build --preset fuzz)" >&2; exit 2; }
  dir="$work/$target"
  mkdir -p "$dir/corpus"
  touch "$dir/started"
  seeds=(fuzz/corpus/"$target")
  options=()
  if grep -q "^$target " fuzz/open-crashes.txt; then
    # Its known crashers are left out and the search goes on past each crash (in child
    # processes), so the rest of the reader is still fuzzed for the whole time.
    options=(-fork=1 -ignore_crashes=1 -ignore_timeouts=1 -ignore_ooms=1)
  elif [ -d fuzz/regressions/"$target" ]; then
    seeds+=(fuzz/regressions/"$target")
  fi
  # -timeout: one input taking 10 s is a hang. The outer timeout is a last resort, for a
  # fuzzer that would not stop by itself; it ends that one process.
  status=0
  timeout --kill-after=30 $((seconds + 120)) "$program" "${options[@]}" \
    -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 \
    -artifact_prefix="$dir/" "$dir/corpus" "${seeds[@]}" >"$dir/log" 2>&1 || status=$?
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$dir/log")
  rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$dir/log")
  corpus=$(find "$dir/corpus" -type f | wc -l)
  crashes=$(find "$dir" -maxdepth 1 -name 'crash-*' -newer "$dir/started" | wc -l)
  if [ ${#options[@]} -gt 0 ]; then
    echo "fuzz: $target: known open crashes (fuzz/open-crashes.txt): $crashes crasher(s) in" \
      "${seconds} s, not failing; corpus $corpus files"
    open+=("$target")
  elif [ "$status" -eq 0 ]; then
    echo "fuzz: $target: ${execs:-?} inputs in ${seconds} s (${rate:-?}/s), corpus $corpus files, no crash"
  else
    echo "fuzz: $target: FAILED (exit $status); the end of $dir/log:" >&2
    tail -n 40 "$dir/log" >&2
    failed+=("$target")
  fi
done
[ ${#failed[@]} -eq 0 ] || echo "fuzz: crashes in: ${failed[*]} (inputs: $work/TARGET/crash-*)" >&2
echo "fuzz: $SECONDS s in all; skipped (known open crashes): ${open[*]:-none}"
echo "fuzz: $((${#targets[@]} - ${#failed[@]} - ${#open[@]})) passed, ${#failed[@]} failed, ${#open[@]} skipped"
[ ${#failed[@]} -eq 0 ]
