#!/usr/bin/env bash
# Reproduces docs/accuracy-paper-cases.md: simulates the paper's static cases A-E (and the hard
# cases) into image-folder recordings, replays them through the measurement chain with
# `tilth ab` (whose figures, 95 % intervals included, the report takes as they are), and
# tabulates the distance error against ground truth like the paper's Table 2.
# usage: bash tools/accuracy.sh [FRAMES_PER_CASE [REPORT OPTIONS]] > docs/accuracy-paper-cases.md
#   (after building; TILTH=path/to/tilth to use another build, COLOR_FORMAT=bayer_rggb8
#   to have the colour camera deliver a Bayer mosaic instead of bgr8)
set -euo pipefail
cd "$(dirname "$0")/.."
frames=${1:-20}
shift || true
tilth=${TILTH:-build/bin/tilth}
color_format=${COLOR_FORMAT:-bgr8}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cases="case_a case_b case_c case_d case_e wet_straw covered"
echo "recording,set" > "$work/tags.csv"
for preset in $cases; do
  "$tilth" run graphs/simulate.json --quiet --set scene.preset=$preset \
    --set scene.frames=$frames --set scene.color_format="$color_format" \
    --set recording.path="$work/recordings/$preset" >&2
  case $preset in case_?) echo "$preset,paper" >> "$work/tags.csv" ;; esac
done
"$tilth" ab "$work"/recordings/* --variant chain --tags "$work/tags.csv" --overlays 0 \
  --jobs 2 --out "$work/ab" --quiet >&2
/usr/bin/python3 tools/accuracy_report.py --frames "$frames" "$@" "$work/ab"
