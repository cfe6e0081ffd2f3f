#!/usr/bin/env bash
# Long fuzzing runs of the readers: builds the `fuzz` preset and gives each target an
# equal share of HOURS (default 6: an hour each), one after the other. The corpora
# grow in build-fuzz/fuzz-work/ and later runs continue from them; see
# docs/reliability.md for what to do with a crasher.
# usage: bash bench/fuzz.sh [HOURS] [TARGET...]
set -euo pipefail
cd "$(dirname "$0")/.."
hours=${1:-6}
shift || true
targets=("$@")
count=${#targets[@]}
[ "$count" -gt 0 ] || count=6
cmake --preset fuzz >/dev/null
nice -n 10 cmake --build --preset fuzz
exec nice -n 10 bash fuzz/run.sh $((hours * 3600 / count)) "${targets[@]}"
