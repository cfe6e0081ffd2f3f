#!/usr/bin/env bash
# Compares segmentation variants on simulated recordings of the paper's static cases
# A-E, its dynamic test (the layered track) and the hard cases (dark wet straw, long
# shadows, fully covered soil) with `tilth ab`, and writes the report.
# usage: bash tools/ab/simulated-cases.sh [FRAMES [OUT_DIR [TILTH AB OPTIONS]]]
#   FRAMES per case (default 10), OUT_DIR default ab-simulated; the variants default to
#   graphs/ab/segmentation-variants.json (give --variants/--variant to change them).
#   TILTH=path/to/tilth to use another build.
set -euo pipefail
cd "$(dirname "$0")/../.."
frames=${1:-10}
out=${2:-ab-simulated}
shift 2 || shift $#
tilth=${TILTH:-build/bin/tilth}
variants=(--variants graphs/ab/segmentation-variants.json)
for option in "$@"; do
  case $option in --variant|--variants) variants=() ;; esac
done
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
for preset in case_a case_b case_c case_d case_e layered wet_straw shadows covered; do
  "$tilth" run graphs/simulate.json --quiet --set scene.preset=$preset \
    --set scene.frames="$frames" --set recording.path="$work/$preset" >&2
done
"$tilth" ab "$work" "${variants[@]}" --out "$out" --overwrite "$@"
