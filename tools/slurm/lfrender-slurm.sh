#!/usr/bin/env bash
# Render one scene on a Slurm cluster: a job array with one task per row
# band (lfrender --tile I/N), each checkpointing so a preempted or requeued
# task resumes, and a merge job that checks every part and merges them into
# the image a single-machine render gives, bit for bit (docs/distributed.md).
#
#   lfrender-slurm.sh submit SCENE.pbrt OUT.exr TASKS [options] [lfrender options...]
#       options: --partition P, --time T (each task and the merge),
#                --sbatch ARG (any sbatch flag, repeatable), --max-running K,
#                --checkpoint-every SECONDS (default 300), --lfrender PATH
#   lfrender-slurm.sh status OUT.exr
#   lfrender-slurm.sh task  [--lfrender PATH] [--checkpoint-every S] SCENE.pbrt OUT.exr TASKS [lfrender options...]
#   lfrender-slurm.sh merge [--lfrender PATH] OUT.exr TASKS
#
# submit resolves lfrender, the scene and the output to absolute paths and
# hands them to the jobs as arguments: Slurm runs a copy of this script from
# slurmd's spool directory, so nothing may be derived from $0 there.
# Parts, checkpoints and logs go to OUT.parts/; the merge writes OUT.exr.
# task and merge also run by hand without Slurm (SLURM_ARRAY_TASK_ID=I ... task).
set -euo pipefail

me=lfrender-slurm
usage() {
  cat >&2 <<'EOF'
usage: lfrender-slurm.sh submit SCENE.pbrt OUT.exr TASKS [options] [lfrender options...]
         options: --partition P  --time T  --sbatch ARG (repeatable)  --max-running K
                  --checkpoint-every SECONDS (default 300)  --lfrender PATH
       lfrender-slurm.sh status OUT.exr
       lfrender-slurm.sh task [--lfrender PATH] [--checkpoint-every S] SCENE.pbrt OUT.exr TASKS [lfrender options...]
       lfrender-slurm.sh merge [--lfrender PATH] OUT.exr TASKS
EOF
  exit 2
}
die() { echo "$me: $*" >&2; exit 1; }

# Absolute form of a path (its directory must exist), symlinks kept.
absdir() { (cd -- "$1" 2>/dev/null && pwd) || die "no such directory: $1"; }
abspath() {
  local d b
  d=$(dirname -- "$1") b=$(basename -- "$1")
  d=$(absdir "$d")
  if [ "$b" = . ]; then echo "$d"; elif [ "$d" = / ]; then echo "/$b"; else echo "$d/$b"; fi
}

# lfrender: --lfrender PATH, else $LFRENDER, else lfrender on PATH, else the
# build next to this script's checkout (only meaningful at submit time or by
# hand, never inside a job, where this script is a copy in the spool).
find_lfrender() {
  local p=${1:-${LFRENDER:-}}
  if [ -z "$p" ]; then
    if p=$(command -v lfrender 2>/dev/null); then :; else
      p=$(dirname -- "${BASH_SOURCE[0]}")/../../build/bin/lfrender
      [ -x "$p" ] || die "cannot find lfrender: build it (cmake --build build), put it on PATH, or give --lfrender PATH (or LFRENDER=PATH)"
    fi
  fi
  [ -f "$p" ] && [ -x "$p" ] || die "lfrender \"$p\" is not an executable file"
  abspath "$p"
}

int_arg() { [[ $2 =~ ^[0-9]+$ ]] && [ "$2" -ge "$3" ] || die "$1 expects an integer >= $3, got \"$2\""; }

# Tiles finished in a checkpoint, as "DONE TOTAL" (16x16 tiles; the
# lensfield:done_tiles attribute is a hex bitmap, bit t%4 of digit t/4).
checkpoint_tiles() {
  command -v iinfo > /dev/null || return 1
  local info w h hex done=0 k
  info=$(iinfo -v "$1" 2>/dev/null) || return 1
  read -r w h < <(sed -n '1s/^.*: *\([0-9][0-9]*\) x *\([0-9][0-9]*\),.*$/\1 \2/p' <<< "$info")
  hex=$(sed -n 's/^ *lensfield:done_tiles: "\([0-9a-f]*\)".*$/\1/p' <<< "$info")
  [ -n "${w:-}" ] && [ -n "${h:-}" ] || return 1
  for ((k = 0; k < ${#hex}; k++)); do
    case ${hex:k:1} in
      1 | 2 | 4 | 8) done=$((done + 1)) ;; 3 | 5 | 6 | 9 | a | c) done=$((done + 2)) ;;
      7 | b | d | e) done=$((done + 3)) ;; f) done=$((done + 4)) ;;
    esac
  done
  echo "$done $((((w + 15) / 16) * ((h + 15) / 16)))"
}

# Slurm's view of one job or array task: "STATE EXITCODE RESTARTS", from the
# controller (recent jobs) or the accounting database; nothing if unknown.
job_state() {
  local line st ec rs
  if command -v scontrol > /dev/null && line=$(scontrol -o show job "$1" 2>/dev/null) && [ -n "$line" ]; then
    line=$(head -n 1 <<< "$line")
    st=$(grep -o 'JobState=[^ ]*' <<< "$line" | cut -d= -f2)
    ec=$(grep -o ' ExitCode=[^ ]*' <<< "$line" | cut -d= -f2)
    rs=$(grep -o 'Restarts=[^ ]*' <<< "$line" | cut -d= -f2)
    if [ "$st" = PENDING ]; then
      st="PENDING($(grep -o ' Reason=[^ ]*' <<< "$line" | cut -d= -f2))"
    fi
    echo "${st:-?} ${ec:-?} ${rs:-0}"
  elif command -v sacct > /dev/null && line=$(sacct -n -X -P -j "$1" -o State,ExitCode 2>/dev/null | tail -n 1) &&
    [ -n "$line" ]; then
    echo "${line%%|*} ${line#*|} ?"
  fi
}

# OUT.parts/jobs, written by submit: "array=ID merge=ID tasks=N".
read_jobs() {
  array='' merge='' ntasks=''
  [ -f "$1/jobs" ] || return 0
  local kv
  for kv in $(cat "$1/jobs"); do
    case $kv in array=*) array=${kv#array=} ;; merge=*) merge=${kv#merge=} ;; tasks=*) ntasks=${kv#tasks=} ;; esac
  done
}

cmd=${1:-}
[ $# -gt 0 ] && shift
case "$cmd" in
submit)
  [ $# -ge 3 ] || usage
  scene=$1 out=$2 tasks=$3
  shift 3
  int_arg TASKS "$tasks" 1
  [ -f "$scene" ] && [ -r "$scene" ] || die "cannot read scene \"$scene\""
  case $out in *.exr | *.EXR) ;; *) die "the output must be an .exr (got \"$out\"): parts carry exact sums" ;; esac
  sb=() lf=() ck=300 maxrun='' lfr=''
  while [ $# -gt 0 ]; do
    a=$1
    case $a in
    --partition=* | --time=* | --sbatch=* | --max-running=* | --checkpoint-every=* | --lfrender=*)
      set -- "${a%%=*}" "${a#*=}" "${@:2}"
      continue
      ;;
    --partition | --time | --sbatch | --max-running | --checkpoint-every | --lfrender | --camera-plugin)
      [ $# -ge 2 ] || die "$a needs a value"
      case $a in
      --partition) sb+=("--partition=$2") ;;
      --time) sb+=("--time=$2") ;;
      --sbatch) sb+=("$2") ;;
      --max-running) int_arg "$a" "$2" 1 && maxrun=$2 ;;
      --checkpoint-every) ck=$2 ;;
      --lfrender) lfr=$2 ;;
      --camera-plugin) # the jobs run elsewhere
        pl=$(abspath "$2") || exit 1
        lf+=("$a" "$pl")
        ;;
      esac
      shift 2
      ;;
    -o | --tile | --checkpoint | --resume)
      die "$a is set by the script for each task (part OUT.parts/part-I.exr, band I/TASKS, its checkpoint)"
      ;;
    *)
      lf+=("$a")
      shift
      ;;
    esac
  done
  [[ $ck =~ ^[0-9]*\.?[0-9]+$ ]] && [[ ! $ck =~ ^[0.]+$ ]] || die "--checkpoint-every expects seconds > 0, got \"$ck\""
  command -v sbatch > /dev/null || die "sbatch not found: this needs a Slurm client (see docs/distributed.md for running the same split without Slurm)"
  lfr=$(find_lfrender "$lfr")
  scene=$(abspath "$scene")
  mkdir -p -- "$(dirname -- "$out")"
  out=$(abspath "$out")
  parts=$out.parts
  # never pull the files from under an earlier submission still in the queue
  read_jobs "$parts"
  if [ -n "$array" ]; then
    q=$(squeue -h -o %F) || die "cannot ask Slurm (squeue) whether jobs $array and $merge of an earlier submission to $out still run"
    if grep -qx -e "$array" ${merge:+-e "$merge"} <<< "$q"; then
      die "a render of $out is still queued or running (array job $array${merge:+, merge job $merge}): wait, or cancel it with scancel $array $merge"
    fi
  fi
  script=$(abspath "${BASH_SOURCE[0]}")
  mkdir -p -- "$parts"
  # A resubmission of the same render resumes its tasks' checkpoints; a
  # different render (scene file, options, tasks) starts afresh.
  key="$(cksum < "$scene") $scene $tasks ${lf[*]}"
  if [ -f "$parts/render.key" ] && [ "$(cat "$parts/render.key")" != "$key" ]; then
    rm -f -- "$parts"/part-*.exr.checkpoint.exr
  fi
  resumed=0
  for ((i = 0; i < tasks; i++)); do
    [ -f "$parts/part-$i.exr.checkpoint.exr" ] && resumed=$((resumed + 1))
    # stale results of an earlier submission (regular files only)
    for f in "$parts/part-$i.exr" "$parts/task-$i.log"; do [ ! -f "$f" ] || rm -f -- "$f"; done
  done
  rm -f -- "$parts/merge.log" "$parts/jobs"
  name=lfrender-$(basename -- "$out" .exr)
  array=$(cd -- "$parts" && sbatch --parsable --array="0-$((tasks - 1))${maxrun:+%$maxrun}" --requeue \
    --open-mode=append --job-name="$name" --output="$parts/task-%a.log" "${sb[@]}" \
    "$script" task --lfrender "$lfr" --checkpoint-every "$ck" "$scene" "$out" "$tasks" "${lf[@]}") ||
    die "sbatch refused the array job (its message is above); nothing submitted"
  array=${array%%;*}
  echo "array=$array tasks=$tasks" > "$parts/jobs" # before the merge job can run
  # afterany, not afterok: the merge runs when every task has ended, however,
  # and fails naming the missing parts instead of waiting forever.
  merge=$(cd -- "$parts" && sbatch --parsable --dependency="afterany:$array" --job-name="$name-merge" \
    --open-mode=append --output="$parts/merge.log" "${sb[@]}" \
    "$script" merge --lfrender "$lfr" "$out" "$tasks") || {
    scancel "$array" 2>/dev/null || true
    die "submitting the merge job failed; cancelled array job $array"
  }
  merge=${merge%%;*}
  echo "array=$array merge=$merge tasks=$tasks" > "$parts/jobs"
  printf '%s\n' "$key" > "$parts/render.key"
  note=''
  [ "$resumed" -eq 0 ] || note=", $resumed resuming from their checkpoints"
  echo "submitted array job $array ($tasks tasks$note) and merge job $merge"
  echo "progress: $script status $out"
  ;;
task)
  lfr='' ck=${LF_CHECKPOINT_EVERY:-300}
  while [ $# -gt 0 ]; do
    case $1 in
    --lfrender | --checkpoint-every)
      [ $# -ge 2 ] || usage
      if [ "$1" = --lfrender ]; then lfr=$2; else ck=$2; fi
      shift 2
      ;;
    *) break ;;
    esac
  done
  [ $# -ge 3 ] || usage
  scene=$1 out=$2 tasks=$3
  shift 3
  int_arg TASKS "$tasks" 1
  i=${SLURM_ARRAY_TASK_ID:-}
  [ -n "$i" ] || die "task needs SLURM_ARRAY_TASK_ID (the band to render, 0 to TASKS-1)"
  int_arg SLURM_ARRAY_TASK_ID "$i" 0
  [ "$i" -lt "$tasks" ] || die "SLURM_ARRAY_TASK_ID $i is not below TASKS $tasks"
  lfr=$(find_lfrender "$lfr")
  part=$out.parts/part-$i.exr
  mkdir -p -- "$out.parts"
  # one thread per CPU Slurm gave the task (lfrender would take the whole node)
  threads=${SLURM_CPUS_PER_TASK:-}
  if [ -z "$threads" ] && [ -n "${SLURM_JOB_CPUS_PER_NODE:-}" ]; then threads=${SLURM_JOB_CPUS_PER_NODE%%[!0-9]*}; fi
  [ -n "$threads" ] || threads=$(nproc)
  echo "$me: task $i of $tasks: $part, job ${SLURM_JOB_ID:-(by hand)} on $(hostname), attempt $((${SLURM_RESTART_COUNT:-0} + 1)), threads $threads, $(date -u +%FT%TZ)"
  if [ -f "$part.checkpoint.exr" ]; then
    if t=$(checkpoint_tiles "$part.checkpoint.exr"); then
      echo "$me: resuming from $part.checkpoint.exr: ${t% *} of ${t#* } tiles done"
    else
      echo "$me: resuming from $part.checkpoint.exr"
    fi
  fi
  exec "$lfr" "$scene" -o "$part" --tile "$i/$tasks" --threads "$threads" \
    --checkpoint-every "$ck" --resume --quiet "$@"
  ;;
merge)
  lfr=''
  if [ "${1:-}" = --lfrender ] && [ $# -ge 2 ]; then lfr=$2 && shift 2; fi
  [ $# -eq 2 ] || usage
  out=$1 tasks=$2
  int_arg TASKS "$tasks" 1
  lfr=$(find_lfrender "$lfr")
  read_jobs "$out.parts"
  parts=() missing=0
  for ((i = 0; i < tasks; i++)); do
    p=$out.parts/part-$i.exr
    parts+=("$p")
    [ -f "$p" ] && continue
    missing=$((missing + 1))
    why="did not finish"
    if [ -n "$array" ] && s=$(job_state "${array}_$i") && [ -n "$s" ]; then
      read -r st ec rs <<< "$s"
      why="ended $st (exit code $ec)"
    fi
    echo "$me: part $i is missing: task $i ${array:+(job ${array}_$i) }$why; $p not written; see $out.parts/task-$i.log" >&2
    if [ -f "$out.parts/task-$i.log" ]; then tail -n 3 "$out.parts/task-$i.log" | sed 's/^/    /' >&2; fi
  done
  [ "$missing" -eq 0 ] || die "not merging $out: $missing of $tasks parts missing"
  "$lfr" merge "${parts[@]}" -o "$out"
  echo "$me: merged $tasks parts into $out"
  ;;
status)
  [ $# -eq 1 ] || usage
  out=$1
  parts=$out.parts
  [ -d "$parts" ] || die "no render parts for $out (no directory $parts)"
  read_jobs "$parts"
  tasks=$ntasks
  if [ -z "$tasks" ]; then # parts rendered by hand: count what is there
    tasks=0
    for f in "$parts"/part-*.exr "$parts"/part-*.exr.checkpoint.exr; do
      [ -e "$f" ] || continue
      n=${f##*/part-} n=${n%%.*}
      [ "$n" -ge "$tasks" ] && tasks=$((n + 1))
    done
  fi
  echo "$out: ${array:+array job $array, }${merge:+merge job $merge, }$tasks tasks"
  now=$(date +%s)
  for ((i = 0; i < tasks; i++)); do
    p=$parts/part-$i.exr st=-- notes=()
    if [ -n "$array" ] && s=$(job_state "${array}_$i") && [ -n "$s" ]; then
      read -r st ec rs <<< "$s"
    fi
    if [ -f "$p" ]; then
      pct=100 notes+=("$p")
      [ "$st" != -- ] || st=done
    elif [ -f "$p.checkpoint.exr" ]; then
      age=$((now - $(stat -c %Y "$p.checkpoint.exr")))
      [ "$age" -ge 0 ] || age=0
      if t=$(checkpoint_tiles "$p.checkpoint.exr"); then
        pct=$((100 * ${t% *} / ${t#* }))
        notes+=("${t% *} of ${t#* } tiles at the last checkpoint (${age} s old)")
      else
        pct='?' notes+=("checkpoint ${age} s old")
      fi
    else
      pct=0
    fi
    case $st in -- | done | COMPLETED | RUNNING | PENDING* | REQUEUED* | CONFIGURING | COMPLETING) ;; *) notes+=("exit code $ec") ;; esac
    case ${rs:-0} in 0 | '?') ;; 1) notes+=("requeued once") ;; *) notes+=("requeued $rs times") ;; esac
    [ -f "$p" ] || [ ! -f "$parts/task-$i.log" ] || notes+=("log $parts/task-$i.log")
    line=$(printf 'part %-3d %-20s %4s%%' "$i" "$st" "$pct")
    if [ ${#notes[@]} -gt 0 ]; then line+="  ${notes[0]}"; fi
    for ((k = 1; k < ${#notes[@]}; k++)); do line+="; ${notes[k]}"; done
    echo "$line"
    rs=0
  done
  if [ -n "$merge" ]; then
    s=$(job_state "$merge") || true
    st=${s%% *}
    line=$(printf 'merge    %s' "${st:---}")
    if [ -f "$out" ] && [ "$st" = COMPLETED ]; then line+="  $out"; fi
    if [ -n "$st" ] && [ "$st" != COMPLETED ] && [ -f "$parts/merge.log" ]; then line+="  log $parts/merge.log"; fi
    echo "$line"
  fi
  ;;
*)
  usage
  ;;
esac
