#!/usr/bin/env bash
# Runs a `tilth ab` comparison on Kubernetes with the manifests beside this script
# (docs/fleet.md): the shared volume, the Indexed Job of the shards, and, once that Job
# is Complete, the merge Job. Edit the PARAMETER lines of the manifests first.
#
# usage: submit.sh run [--merge-after ok|any]   shards, wait, merge (ok: only if all succeeded)
#        submit.sh rerun I                      shard I again (Job tilth-ab-shard-I), then
#                                               `submit.sh merge`
#        submit.sh merge                        the merge Job again (replaces the report)
#
# kubectl's current context and namespace are used.
set -euo pipefail

here=$(cd "$(dirname "$0")" && pwd)
usage() { sed -n '/^# usage:/,/^#$/p' "$0" | sed 's/^# \{0,1\}//' >&2; exit 2; }
command -v kubectl >/dev/null || { echo "submit.sh: kubectl not found" >&2; exit 2; }

# Waits until Job $1 is Complete (returns 0) or Failed (returns 1).
wait_for() {
  local state
  while true; do
    state=$(kubectl get job "$1" -o jsonpath='{range .status.conditions[?(@.status=="True")]}{.type} {end}')
    case " $state " in
      *" Complete "*) return 0 ;;
      *" Failed "*) kubectl get job "$1" -o jsonpath='failed indexes: {.status.failedIndexes}{"\n"}' >&2; return 1 ;;
    esac
    kubectl get job "$1" -o jsonpath='{.metadata.name}: {.status.succeeded} succeeded, {.status.active} active, {.status.failed} failed{"\n"}'
    sleep 30
  done
}

merge() {
  kubectl delete job tilth-ab-merge --ignore-not-found
  kubectl apply -f "$here/merge-job.yaml"
  wait_for tilth-ab-merge || { kubectl logs job/tilth-ab-merge >&2; exit 1; }
  kubectl logs job/tilth-ab-merge
}

case "${1:-}" in
  run)
    merge_after=${3:-ok}
    [ "${2:-}" = "" ] || [ "${2:-}" = --merge-after ] || usage
    case "$merge_after" in ok|any) ;; *) usage ;; esac
    kubectl apply -f "$here/storage.yaml"
    kubectl delete job tilth-ab-shards --ignore-not-found
    kubectl apply -f "$here/shards-job.yaml"
    if ! wait_for tilth-ab-shards; then
      [ "$merge_after" = any ] || { echo "submit.sh: shards failed: rerun them, then submit.sh merge" >&2; exit 1; }
    fi
    merge ;;
  rerun)
    [[ "${2:-}" =~ ^[0-9]+$ ]] || usage
    kubectl delete job "tilth-ab-shard-$2" --ignore-not-found
    # The same pod as shards-job.yaml's, once, with its index given by TILTH_AB_INDEX.
    kubectl patch --local -f "$here/shards-job.yaml" --type=json -o yaml -p "[
      {\"op\": \"replace\", \"path\": \"/metadata/name\", \"value\": \"tilth-ab-shard-$2\"},
      {\"op\": \"replace\", \"path\": \"/spec/completions\", \"value\": 1},
      {\"op\": \"replace\", \"path\": \"/spec/parallelism\", \"value\": 1},
      {\"op\": \"add\", \"path\": \"/spec/template/spec/containers/0/env/-\",
       \"value\": {\"name\": \"TILTH_AB_INDEX\", \"value\": \"$2\"}}]" | kubectl apply -f -
    wait_for "tilth-ab-shard-$2" ;;
  merge) merge ;;
  *) usage ;;
esac
