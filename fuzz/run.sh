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
# in fuzz/open-crashes.txt (a fix not on main yet) is reported and does not fail the run.
set -euo pipefail
cd "$(dirname "$0")/.."

if [ $# -lt 1 ] || ! [[ $1 =~ ^[0-9]+$ ]]; then
  echo "usage: bash fuzz/run.sh SECONDS_EACH [TARGET...]" >&2
  exit 2
fi
seconds=$1
shift
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(graph_file calibration frames_csv png_decoder mcap_reader modbus_request)
build=${TILTH_FUZZ_BUILD:-build-fuzz}
work=${TILTH_FUZZ_WORK:-$build/fuzz-work}

failed=()
open=()
for target in "${targets[@]}"; do
  program="$build/bin/fuzz_$target"
  [ -x "$program" ] || { echo "fuzz: $program is not built (cmake --build --preset fuzz)" >&2; exit 2; }
  dir="$work/$target"
  mkdir -p "$dir/corpus"
  seeds=(fuzz/corpus/"$target")
  open_crash=$(grep "^$target " fuzz/open-crashes.txt || true)
  # A target with a known open crash starts without its crashers, so it is fuzzed until
  # it finds one (or another) again.
  [ -n "$open_crash" ] || [ ! -d fuzz/regressions/"$target" ] || seeds+=(fuzz/regressions/"$target")
  # -timeout: one input taking 10 s is a hang. But the timer counts wall time: an input
  # that then runs at once when replayed alone was not one (a loaded machine starved the
  # fuzzer), so it is set aside in $dir/starved/ and fuzzing goes on for the time left.
  # The outer timeout is a last resort, for a fuzzer that would not stop by itself; it
  # ends that one process.
  start=$SECONDS
  execs=0
  while :; do
    status=0
    left=$((seconds - (SECONDS - start)))
    timeout --kill-after=30 $((left + 120)) "$program" \
      -max_total_time="$left" -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 \
      -artifact_prefix="$dir/" "$dir/corpus" "${seeds[@]}" >"$dir/log" 2>&1 || status=$?
    run_execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$dir/log")
    execs=$((execs + ${run_execs:-0}))
    hang=$(sed -n 's/.*Test unit written to \(.*\/timeout-[0-9a-f]*\)$/\1/p' "$dir/log")
    if [ "$status" -eq 0 ] || [ -z "$hang" ] || ! timeout 60 "$program" -timeout=10 "$hang" \
      >/dev/null 2>&1; then
      break
    fi
    mkdir -p "$dir/starved"
    mv "$hang" "$dir/starved/"
    echo "fuzz: $target: an input timed out but runs at once alone (a starved fuzzer, not a" \
      "hang); kept in $dir/starved/, going on"
    status=0
    [ $((SECONDS - start)) -lt "$seconds" ] || break
  done
  rate=$((execs / (SECONDS - start > 0 ? SECONDS - start : 1)))
  corpus=$(find "$dir/corpus" -type f | wc -l)
  summary="$execs inputs ($rate/s), corpus $corpus files"
  if [ "$status" -ne 0 ] && [ -n "$open_crash" ]; then
    echo "fuzz: $target: crashed after $summary; not failing, as fuzz/open-crashes.txt lists" \
      "a crash of it still open; check that it is that one:" \
      "$(grep -m1 -E '^(SUMMARY|terminate|  what)' "$dir/log" || true)"
    open+=("$target")
  elif [ "$status" -eq 0 ]; then
    echo "fuzz: $target: $summary, no crash"
  else
    echo "fuzz: $target: FAILED (exit $status); the end of $dir/log:" >&2
    tail -n 40 "$dir/log" >&2
    failed+=("$target")
  fi
done
[ ${#failed[@]} -eq 0 ] || echo "fuzz: crashes in: ${failed[*]} (inputs: $work/TARGET/crash-*)" >&2
echo "fuzz: $SECONDS s in all; crashed but listed as open: ${open[*]:-none}"
echo "fuzz: $((${#targets[@]} - ${#failed[@]} - ${#open[@]})) passed, ${#failed[@]} failed, ${#open[@]} skipped"
[ ${#failed[@]} -eq 0 ]
