#!/usr/bin/env bash
# The two front-door commands (see README.md):
#   bash tools/dev.sh demo   install what is missing, build, run the built-in demo graph
#   bash tools/dev.sh test   install what is missing, build, run every test; install the
#                            .deb packages into a bare Debian root; every test
#                            again under ASan+UBSan; the threaded code under TSan; and each
#                            fuzz target for TILTH_FUZZ_SECONDS (default 60) seconds
#                            (docs/reliability.md)
#   bash tools/dev.sh sanitize   only the ASan+UBSan part of `test`
set -euo pipefail
cd "$(dirname "$0")/.."

mode=${1:-}
case "$mode" in
  demo|test|sanitize) ;;
  *) echo "usage: bash tools/dev.sh demo|test|sanitize" >&2; exit 2 ;;
esac

bash tools/setup.sh
# ccache hits across clones (CI builds in a fresh one): paths taken relative to the clone,
# and the build folder left out of the hash of objects with debug info.
export CCACHE_BASEDIR=$PWD CCACHE_NOHASHDIR=true
cmake --preset default >/dev/null
cmake --build --preset default

if [ "$mode" = demo ]; then
  shift
  exec build/bin/tilth run graphs/demo.json --frames 100 "$@"
fi

# Each step's duration, for the CI log (docs/reliability.md keeps the figures).
step() {
  local start=$SECONDS
  "$@"
  echo "dev.sh: '$*' took $((SECONDS - start)) s"
}

# Every test again under AddressSanitizer + UndefinedBehaviorSanitizer.
asan() {
  cmake --preset asan >/dev/null
  step cmake --build --preset asan
  step ctest --preset asan
}

if [ "$mode" = sanitize ]; then
  asan
  exit 0
fi

step ctest --preset default
# The .deb packages installed with apt into a bare Debian root, and run there.
step bash tests/packaging/deb_in_clean_root.sh build
asan
# The runtime, every parallel stage and the threaded serial stages under ThreadSanitizer.
cmake --preset tsan >/dev/null
step cmake --build --preset tsan
step ctest --preset tsan
# The readers under libFuzzer; a crash fails the run.
cmake --preset fuzz >/dev/null
step cmake --build --preset fuzz
bash fuzz/run.sh "${TILTH_FUZZ_SECONDS:-60}"
