#!/usr/bin/env bash
# The two front-door commands (see README.md):
#   bash tools/dev.sh demo   install what is missing, build, run the built-in demo graph
#   bash tools/dev.sh test   install what is missing, build, run every test (incl. TSan)
set -euo pipefail
cd "$(dirname "$0")/.."

mode=${1:-}
case "$mode" in
  demo|test) ;;
  *) echo "usage: bash tools/dev.sh demo|test" >&2; exit 2 ;;
esac

bash tools/setup.sh
cmake --preset default >/dev/null
cmake --build --preset default

if [ "$mode" = demo ]; then
  shift
  exec build/bin/tilth run graphs/demo.json --frames 100 "$@"
fi

ctest --preset default
# The concurrency tests again under ThreadSanitizer.
cmake --preset tsan >/dev/null
cmake --build --preset tsan
ctest --preset tsan
