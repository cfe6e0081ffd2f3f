#!/usr/bin/env bash
# Submits a `tilth ab` comparison to Slurm (docs/fleet.md): the job array of its N shards
# (shard.sbatch, at most K at a time) and the merge (merge.sbatch), which starts when
# every task of the array has ended: with --merge-after ok (default) only if all
# succeeded, with --merge-after any in any case (the report then lists missing jobs).
#
# usage: submit.sh --shards N [--parallel K] --variants FILE --out DIR [--report DIR]
#                  [--cpus C] [--tilth PROGRAM] [--merge-after ok|any]
#                  [--sbatch-option OPT]... RECORDING... [-- TILTH_AB_OPTION...]
#
# Paths are made absolute; DIR must be on storage every node sees. Prints the array's
# and the merge's job ids. Task logs: DIR/logs/shard-I.out and DIR/logs/merge.out.
set -euo pipefail

here=$(cd "$(dirname "$0")" && pwd)
usage() {
  sed -n '/^# usage:/,/^#$/p' "$0" | sed 's/^# \{0,1\}//' >&2
  exit 2
}
fail() { echo "submit.sh: $*" >&2; usage; }

shards="" parallel="" variants="" out="" report="" cpus="" merge_after=ok
sbatch_options=() recordings=() options=()
while [ $# -gt 0 ]; do
  case "$1" in
    --shards|--parallel|--variants|--out|--report|--cpus|--tilth|--merge-after|--sbatch-option)
      [ $# -ge 2 ] || fail "$1 needs a value"
      case "$1" in
        --shards) shards=$2 ;;
        --parallel) parallel=$2 ;;
        --variants) variants=$(realpath -m "$2") ;;
        --out) out=$(realpath -m "$2") ;;
        --report) report=$(realpath -m "$2") ;;
        --cpus) cpus=$2 ;;
        --tilth) TILTH=$(realpath -m "$2"); export TILTH ;;
        --merge-after) merge_after=$2 ;;
        --sbatch-option) sbatch_options+=("$2") ;;
      esac
      shift 2 ;;
    --) shift; options=("$@"); break ;;
    -h|--help) usage ;;
    -*) fail "unknown option $1" ;;
    *) recordings+=("$(realpath -m "$1")"); shift ;;
  esac
done

[[ "$shards" =~ ^[1-9][0-9]*$ ]] || fail "--shards N is required (a number of shards, 1 or more)"
[ -z "$parallel" ] || [[ "$parallel" =~ ^[1-9][0-9]*$ ]] || fail "--parallel K must be a number"
[ -z "$cpus" ] || [[ "$cpus" =~ ^[1-9][0-9]*$ ]] || fail "--cpus C must be a number"
[ -n "$variants" ] || fail "--variants FILE is required"
[ -f "$variants" ] || fail "$variants: no such file"
[ -n "$out" ] || fail "--out DIR is required"
[ ${#recordings[@]} -gt 0 ] || fail "no recording given"
for r in "${recordings[@]}"; do
  [ -e "$r" ] || fail "$r: no such recording"
  [[ "$r" != *[[:space:]]* ]] || fail "$r: paths with spaces are not supported"
done
case "$merge_after" in ok|any) ;; *) fail "--merge-after must be ok or any" ;; esac
command -v sbatch >/dev/null || fail "sbatch not found: run this on a Slurm submit host"

mkdir -p "$out/logs"
export TILTH_AB_SHARDS=$shards TILTH_AB_VARIANTS=$variants TILTH_AB_OUT=$out
export TILTH_AB_RECORDINGS="${recordings[*]}" TILTH_AB_OPTIONS="${options[*]}"
export TILTH_AB_REPORT=${report:-$out/report}

array="0-$((shards - 1))${parallel:+%$parallel}"
resources=()
[ -z "$cpus" ] || resources=(--cpus-per-task "$cpus")
array_id=$(sbatch --parsable --export=ALL --array="$array" "${resources[@]}" \
  --output="$out/logs/shard-%a.out" "${sbatch_options[@]}" "$here/shard.sbatch")
array_id=${array_id%%;*}  # "id;cluster" on multi-cluster setups
# afterok/afterany on an array job waits for every task of the array.
merge_options=(--dependency="after$merge_after:$array_id")
[ "$merge_after" = any ] || merge_options+=(--kill-on-invalid-dep=yes)
merge_id=$(sbatch --parsable --export=ALL "${merge_options[@]}" \
  --output="$out/logs/merge.out" "${sbatch_options[@]}" "$here/merge.sbatch")
merge_id=${merge_id%%;*}

echo "array $array_id ($shards shards, --array=$array), merge $merge_id after$merge_after"
echo "watch: squeue -j $array_id,$merge_id   logs: $out/logs/   report: $TILTH_AB_REPORT"
