#!/usr/bin/env bash
# Render one scene on a Slurm cluster: a job array with one task per row
# band (lfrender --tile I/N), each checkpointing so a preempted or requeued
# task resumes, and a merge job that runs when every task has succeeded.
#
#   tools/slurm/lfrender-slurm.sh submit SCENE.pbrt OUT.exr TASKS [lfrender options...]
#
# Parts go to OUT.parts/part-I.exr; the merge writes OUT.exr, bit-identical
# to a single-machine render with the same options. Slurm runs the same
# script with "task" and "merge" (which also work by hand, without Slurm:
# SLURM_ARRAY_TASK_ID=3 tools/slurm/lfrender-slurm.sh task ...).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
LFRENDER=${LFRENDER:-$here/../../build/bin/lfrender}
cmd=${1:-}
case "$cmd" in
submit)
  [ $# -ge 4 ] || { echo "usage: $0 submit SCENE.pbrt OUT.exr TASKS [lfrender options...]" >&2; exit 2; }
  scene=$2 out=$3 tasks=$4; shift 4
  mkdir -p "$out.parts"
  array=$(sbatch --parsable --array=0-$((tasks - 1)) --requeue --job-name=lfrender \
    --output="$out.parts/task-%a.log" "$0" task "$scene" "$out" "$tasks" "$@")
  merge=$(sbatch --parsable --dependency=afterok:"$array" --job-name=lfrender-merge \
    --output="$out.parts/merge.log" "$0" merge "$out" "$tasks")
  echo "submitted array job $array ($tasks tasks) and merge job $merge"
  ;;
task)
  [ $# -ge 4 ] || { echo "usage: $0 task SCENE.pbrt OUT.exr TASKS [lfrender options...]" >&2; exit 2; }
  scene=$2 out=$3 tasks=$4; shift 4
  i=${SLURM_ARRAY_TASK_ID:?task needs SLURM_ARRAY_TASK_ID}
  mkdir -p "$out.parts"
  exec "$LFRENDER" "$scene" -o "$out.parts/part-$i.exr" --tile "$i/$tasks" \
    --checkpoint-every "${LF_CHECKPOINT_EVERY:-300}" --resume --quiet "$@"
  ;;
merge)
  [ $# -eq 3 ] || { echo "usage: $0 merge OUT.exr TASKS" >&2; exit 2; }
  out=$2 tasks=$3
  parts=()
  for i in $(seq 0 $((tasks - 1))); do parts+=("$out.parts/part-$i.exr"); done
  exec "$LFRENDER" merge "${parts[@]}" -o "$out"
  ;;
*)
  echo "usage: $0 submit|task|merge ..." >&2
  exit 2
  ;;
esac
