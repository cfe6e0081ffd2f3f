#!/usr/bin/env bash
# Installs the SDK from the build tree into a scratch prefix, builds the example plugin
# against it out of tree, and runs it in a graph with the in-tree plugins and its stage
# alone through the SDK's stage harness.
# usage: run_test.sh BUILD_DIR SOURCE_DIR
set -euo pipefail
build=$1
here=$(cd "$(dirname "$0")" && pwd)
scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT

# As the packages tilth-dev and the tilth it depends on (the SDK's shared library) install it.
for component in runtime sdk; do
  cmake --install "$build" --component $component --prefix "$scratch/prefix" >/dev/null
done
cmake -S "$here" -B "$scratch/build" -G Ninja -DCMAKE_PREFIX_PATH="$scratch/prefix" \
  -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$scratch/build" >/dev/null

plugin="$scratch/build/tilth_example.so"
# The plugin links the SDK and nothing of the runtime.
needed=$(readelf -d "$plugin" | awk '/NEEDED/ {print $5}' | tr -d '[]' | tr '\n' ' ')
echo "plugin needs: $needed"
case "$needed" in *libtilth_sdk.so*) ;; *) echo "FAIL: plugin does not link the SDK"; exit 1 ;; esac
case "$needed" in *tbb*|*boost*) echo "FAIL: plugin links runtime libraries"; exit 1 ;; esac

out=$(LD_LIBRARY_PATH="$scratch/prefix/lib" TILTH_PLUGIN_PATH="$scratch/build" \
  "$build/bin/tilth" run "$here/graph.json" --quiet)
echo "$out"
# 518 mm + 23.97 mm z offset at the centre pixel, quantised to 0.0229 mm gray steps:
# round(541.9702 / 0.0229) = 23667 -> 541.97 mm.
expected=$(printf 'frame %d: centre range 541.97 mm\n' 0 1 2 3 4)
if [ "$out" != "$expected" ]; then
  echo "FAIL: expected"; echo "$expected"; exit 1
fi
echo "out-of-tree plugin OK"

# The stage alone, through the SDK's stage harness.
LD_LIBRARY_PATH="$scratch/prefix/lib" "$scratch/build/centre_range_check"
echo "out-of-tree stage harness OK"

