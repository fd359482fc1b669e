#!/usr/bin/env bash
# tools/slurm/lfrender-slurm.sh, by hand and on a real single-node Slurm.
#
# 1. By hand (runs everywhere): the task and merge steps as Slurm would run
#    them reproduce the single-machine render bit for bit; status reports
#    the parts; a missing part makes merge fail naming the part and its log;
#    submit with a stand-in sbatch, each recorded job then run as slurmd
#    runs it (a copy of the script in a spool directory, empty environment).
# 2. On Slurm: the test starts its own munged, slurmctld and slurmd (its own
#    key, socket, ports, state, spool and slurm.conf in a temporary
#    directory; SLURM_CONF points the clients there, so a system-wide
#    Slurm or munge is neither used nor disturbed), submits from another
#    directory with an empty environment, requeues one task mid-render with
#    `scontrol requeue`, and checks that the task resumed from its checkpoint,
#    that status showed its progress, and that the merged image equals the
#    local render bit for bit; a render cancelled mid-render and submitted
#    again resumes both tasks and is identical too; then a task forced to
#    fail (its part path is a directory) must make the merge job fail naming
#    the part and its log.
#    Every daemon it started is stopped by pid on exit, jobs first.
# Where the daemons cannot start (not root, Slurm or munge not installed) the
# Slurm part is skipped with the reason (exit 77, ctest "Skipped"), except
# with CI=true, where that is a failure.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
bin=$(cd "${1:?usage: test_slurm.sh BUILD_BIN_DIR}" && pwd)
script=$root/tools/slurm/lfrender-slurm.sh
unset LFRENDER SLURM_CONF
tmp=$(mktemp -d)
chmod 755 "$tmp" # munged wants every directory above its socket searchable
daemon_pids=() # munged slurmctld slurmd, in start order
host=$(hostname -s)
fail() {
  echo "FAIL: $*" >&2
  exit 1
}
say() { echo "test_slurm: $*"; }

# Stop what this test started: cancel its jobs and wait for their steps to
# end (slurmstepd outlives slurmd otherwise), then the daemons, newest first.
stop_pid() {
  local p=$1 k
  kill -0 "$p" 2>/dev/null || return 0
  kill -TERM "$p" 2>/dev/null || true
  for k in $(seq 100); do
    kill -0 "$p" 2>/dev/null || return 0
    sleep 0.1
  done
  kill -KILL "$p" 2>/dev/null || true
}
cleanup() {
  local rc=$? k i p q
  set +e
  if [ ${#daemon_pids[@]} -ge 3 ] && kill -0 "${daemon_pids[1]}" 2>/dev/null && kill -0 "${daemon_pids[2]}" 2>/dev/null; then
    # cancel every job and let slurmd see its steps end (jobs leave squeue
    # once completed; each running step has a socket in the spool)
    q=$(squeue -h -o %A 2>/dev/null)
    [ -z "$q" ] || scancel --quiet $q 2>/dev/null
    for k in $(seq 150); do
      q=$(squeue -h -o %A 2>/dev/null) || break
      [ -n "$q" ] || ls "$tmp/slurm/spool/${host}_"[0-9]* > /dev/null 2>&1 || break
      sleep 0.2
    done
  fi
  for ((i = ${#daemon_pids[@]} - 1; i >= 0; i--)); do stop_pid "${daemon_pids[i]}"; done
  # last resort, for steps that would not end: every process working in
  # this test's directory was started by it (slurmstepd, job processes)
  for p in /proc/[0-9]*; do
    i=${p#/proc/}
    [ "$i" != $$ ] || continue
    case "$(readlink "$p/cwd" 2>/dev/null)" in "$tmp" | "$tmp"/*) kill -KILL "$i" 2>/dev/null ;; esac
  done
  if [ $rc -ne 0 ] && [ $rc -ne 77 ] && [ -d "$tmp/slurm/log" ]; then
    for f in "$tmp"/slurm/log/*; do
      echo "--- last lines of $f" >&2
      tail -n 15 "$f" >&2
    done
  fi
  rm -rf "$tmp"
  exit $rc
}
trap cleanup EXIT
trap 'exit 143' TERM
trap 'exit 130' INT

# A small scene; --spp sets the cost. 96x64 in 4 bands of 96x16: 6 tiles a band.
cat > "$tmp/s.pbrt" <<'SCENE'
LookAt 0 1 -5 0 0.5 0 0 1 0
Camera "perspective" "float fov" [40]
Film "rgb" "integer xresolution" [96] "integer yresolution" [64] "bool savefp16" false
Sampler "zsobol" "integer pixelsamples" [16]
WorldBegin
LightSource "infinite" "rgb L" [0.5 0.6 0.7]
Material "diffuse"
Shape "bilinearmesh" "point3 P" [-5 0 -5 5 0 -5 -5 0 5 5 0 5]
Translate 0 0.5 0
Shape "sphere" "float radius" [0.5]
SCENE
identical() { idiff -fail 0 -warn 0 "$1" "$2" > /dev/null || fail "$2 differs from the single-machine render $1"; }
passed=0

# ---- 1. by hand ----
"$bin/lfrender" "$tmp/s.pbrt" -o "$tmp/ref16.exr" --seed 4 --quiet
mkdir "$tmp/hand"
for i in 0 1 2; do
  SLURM_ARRAY_TASK_ID=$i "$script" task --lfrender "$bin/lfrender" "$tmp/s.pbrt" "$tmp/hand/out.exr" 3 --seed 4 \
    > "$tmp/hand/task-$i.out"
done
grep -q "task 1 of 3: $tmp/hand/out.exr.parts/part-1.exr" "$tmp/hand/task-1.out" || fail "task did not say what it renders"
"$script" merge --lfrender "$bin/lfrender" "$tmp/hand/out.exr" 3 > /dev/null
identical "$tmp/ref16.exr" "$tmp/hand/out.exr"
"$script" status "$tmp/hand/out.exr" > "$tmp/hand/status"
[ "$(grep -c '^part [0-2] .* 100%' "$tmp/hand/status")" = 3 ] || fail "status of finished parts: $(cat "$tmp/hand/status")"
# a missing part: merge fails naming it and its log, and writes nothing
mv "$tmp/hand/out.exr.parts/part-1.exr" "$tmp/hand/part-1.exr"
rm "$tmp/hand/out.exr"
if PATH=$bin:$PATH "$script" merge "$tmp/hand/out.exr" 3 2> "$tmp/hand/merge.err"; then fail "merge with a missing part succeeded"; fi
grep -q "part 1 is missing.*see $tmp/hand/out.exr.parts/task-1.log" "$tmp/hand/merge.err" ||
  fail "merge message does not name part 1 and its log: $(cat "$tmp/hand/merge.err")"
[ ! -e "$tmp/hand/out.exr" ] || fail "merge with a missing part wrote $tmp/hand/out.exr"
# paths: a relative scene and output from another directory, lfrender found on PATH
mkdir "$tmp/hand/elsewhere"
(cd "$tmp/hand/elsewhere" && SLURM_ARRAY_TASK_ID=0 PATH=$bin:$PATH "$script" task ../../s.pbrt ../rel.exr 1 --seed 4 > /dev/null &&
  PATH=$bin:$PATH "$script" merge ../rel.exr 1 > /dev/null)
identical "$tmp/ref16.exr" "$tmp/hand/rel.exr"
passed=$((passed + 1))
say "by hand: 3 tasks + merge identical to the local render; status; missing part refused; relative paths"

# submit as slurmd would run it, without Slurm: a stand-in sbatch records
# each job; every job then runs as a copy of the script in a spool directory
# of its own, from that directory, with an empty environment (lfrender not
# on PATH): everything must come from the arguments resolved at submit
F=$tmp/fake
mkdir -p "$F/bin" "$F/submit"
cat > "$F/bin/sbatch" <<EOF
#!/bin/bash
n=\$(ls "$F" | grep -c '^job-[0-9]*$')
printf '%s\n' "\$@" > "$F/job-\$((n + 1))"
echo "\$((n + 1))"
EOF
printf '#!/bin/sh\nexit 0\n' > "$F/bin/squeue"
chmod +x "$F/bin/sbatch" "$F/bin/squeue"
if [ "$bin" -ef "$root/build/bin" ]; then lfopt=(); else lfopt=(--lfrender "$bin/lfrender"); fi
(cd "$F/submit" && env -i PATH="$F/bin:/usr/bin:/bin" bash "$script" submit ../../s.pbrt ../out/fake.exr 3 "${lfopt[@]}" \
  --partition p1 --time 0:30:00 --sbatch --qos=low --seed 4 > /dev/null)
run_job() { # N [TASK]: runs recorded job N as slurmd runs a batch script
  local args=() k
  mapfile -t args < "$F/job-$1"
  for ((k = 0; k < ${#args[@]}; k++)); do [ "${args[k]}" != "$script" ] || break; done
  [ $k -lt ${#args[@]} ] || fail "job $1 does not run the script: ${args[*]}"
  printf '%s\n' "${args[@]:0:k}" > "$F/opts-$1"
  mkdir -p "$F/spool/job$1"
  cp "$script" "$F/spool/job$1/slurm_script"
  (cd "$F/spool/job$1" && env -i PATH=/usr/bin:/bin ${2:+SLURM_ARRAY_TASK_ID=$2} bash slurm_script "${args[@]:k+1}") \
    >> "$F/job-$1.out" 2>&1 || fail "job $1${2:+ task $2} failed: $(cat "$F/job-$1.out")"
}
for i in 0 1 2; do run_job 1 "$i"; done
run_job 2
identical "$tmp/ref16.exr" "$F/out/fake.exr"
grep -qx -- '--array=0-2' "$F/opts-1" && grep -qx -- '--requeue' "$F/opts-1" || fail "array job options: $(cat "$F/opts-1")"
for o in --partition=p1 --time=0:30:00 --qos=low; do
  grep -qx -- "$o" "$F/opts-1" && grep -qx -- "$o" "$F/opts-2" || fail "$o not passed to both jobs"
done
grep -qx -- '--dependency=afterany:1' "$F/opts-2" || fail "merge job dependency: $(cat "$F/opts-2")"
passed=$((passed + 1))
say "submit without Slurm: the jobs, run as copies from a spool directory with an empty environment, reproduce the render"

# ---- 2. on a single-node Slurm started here ----
skip() {
  if [ "${CI:-}" = true ]; then fail "CI=true but the Slurm part cannot run: $*"; fi
  echo "skipped: the Slurm part: $* ($passed passed: the by-hand steps)"
  exit 77
}
PATH=$PATH:/usr/sbin:/sbin # the daemons, for users whose PATH lacks sbin
for c in munged slurmctld slurmd sbatch scontrol squeue scancel sinfo; do
  command -v "$c" > /dev/null || skip "$c not found (Debian: apt-get install slurm-wlm munge)"
done
[ "$(id -u)" = 0 ] || skip "slurmd must run as root to start jobs (run as root, as CI does)"

# Free TCP ports: none bound or in use on this machine (/proc/net/tcp*).
used_ports() {
  local f a
  for f in /proc/net/tcp /proc/net/tcp6; do
    [ -r "$f" ] || continue
    while read -r _ a _; do [[ $a != *:* ]] || echo $((16#${a##*:})); done < "$f"
  done | sort -u
}
free_port() {
  local p used
  used=$(used_ports)
  for _ in $(seq 200); do
    p=$((20000 + RANDOM % 30000))
    grep -qx "$p" <<< "$used" || [ "$p" = "${1:-}" ] || {
      echo "$p"
      return
    }
  done
  return 1
}
up() { # is the node idle, i.e. both daemons answer
  [ "$(sinfo -h -o %T 2>/dev/null)" = idle ]
}

S=$tmp/slurm
mkdir -p "$S/state" "$S/spool" "$S/log" "$S/munge"
chmod 755 "$S" "$S/munge"
head -c 1024 /dev/urandom > "$S/munge/munge.key"
chmod 400 "$S/munge/munge.key"
(cd "$S" && exec munged -F --socket="$S/munge/socket" --key-file="$S/munge/munge.key" \
  --pid-file="$S/munge/munged.pid" --seed-file="$S/munge/seed" \
  > "$S/log/munged.log" 2>&1) &
daemon_pids+=($!)
for _ in $(seq 100); do [ -S "$S/munge/socket" ] && break; sleep 0.1; done
[ -S "$S/munge/socket" ] || skip "munged did not start: $(tail -n 2 "$S/log/munged.log" | tr '\n' ' ')"

# this machine as slurmd sees it (CPUs, sockets, cores, threads, memory)
hw=$(slurmd -C 2>/dev/null | head -n 1 | sed 's/^NodeName=[^ ]* //')
[ -n "$hw" ] || hw="CPUs=$(nproc)"
export SLURM_CONF=$S/slurm.conf
started=0
for attempt in 1 2 3; do
  p1=$(free_port) && p2=$(free_port "$p1") || skip "no free TCP port found"
  cat > "$SLURM_CONF" <<EOF
# single-node cluster of tests/test_slurm.sh (removed with its directory)
ClusterName=lftest
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=$p1
SlurmdPort=$p2
SlurmUser=$(id -un)
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
# own munge socket; cred_expire also sets how long a requeued job waits (+1 s)
AuthInfo=socket=$S/munge/socket,cred_expire=10
StateSaveLocation=$S/state
SlurmdSpoolDir=$S/spool
SlurmctldPidFile=$S/slurmctld.pid
SlurmdPidFile=$S/slurmd.pid
SlurmctldLogFile=$S/log/slurmctld.log
SlurmdLogFile=$S/log/slurmd.log
PlugStackConfig=$S/plugstack.conf
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
MpiDefault=none
SwitchType=switch/none
SchedulerType=sched/builtin
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
KillWait=10
MinJobAge=600
NodeName=$host NodeAddr=127.0.0.1 $hw State=UNKNOWN
PartitionName=lftest Nodes=$host Default=YES MaxTime=INFINITE State=UP
EOF
  : > "$S/plugstack.conf"
  (cd "$S" && exec slurmctld -D -i -f "$SLURM_CONF" > "$S/log/slurmctld.out" 2>&1) &
  ctld=$!
  (cd "$S" && exec slurmd -D -f "$SLURM_CONF" > "$S/log/slurmd.out" 2>&1) &
  sd=$!
  daemon_pids+=("$ctld" "$sd")
  for _ in $(seq 150); do
    up && break
    kill -0 "$ctld" 2>/dev/null && kill -0 "$sd" 2>/dev/null || break
    sleep 0.2
  done
  if up; then
    started=1
    break
  fi
  why=$(cat "$S/log/slurmctld.out" "$S/log/slurmd.out" "$S/log/"*.log 2>/dev/null | grep -i -m 3 'error\|fatal' | tr '\n' ' ')
  stop_pid "$sd"
  stop_pid "$ctld"
  unset 'daemon_pids[2]' 'daemon_pids[1]'
  daemon_pids=("${daemon_pids[@]}")
  say "attempt $attempt: slurmctld/slurmd on ports $p1/$p2 did not come up: $why"
done
[ $started = 1 ] || skip "slurmctld and slurmd did not come up (logs: $why)"
say "single-node Slurm up: $host, $hw, ports $p1/$p2, conf $SLURM_CONF"

# cost: 4096 samples a pixel (1024 with LF_QUICK, for sanitizer builds), so
# each task takes seconds on one thread and is requeued well before it ends
spp=4096
[ -z "${LF_QUICK:-}" ] || spp=1024
"$bin/lfrender" "$tmp/s.pbrt" -o "$tmp/ref.exr" --seed 4 --spp "$spp" --quiet

# submit from another directory, with relative paths and an empty environment
# (only PATH and SLURM_CONF; sanitizer options when set): nothing from here
# may leak into the jobs except through the script's arguments
envs=(HOME=/ PATH=/usr/local/bin:/usr/bin:/bin SLURM_CONF="$SLURM_CONF")
[ "$bin" -ef "$root/build/bin" ] || envs[1]=PATH=$bin:/usr/local/bin:/usr/bin:/bin # else the script finds the checkout's build
for v in ASAN_OPTIONS UBSAN_OPTIONS LSAN_OPTIONS; do [ -z "${!v:-}" ] || envs+=("$v=${!v}"); done
mkdir -p "$tmp/submit" "$tmp/cluster"
submit() { # OUT TASKS [options]: submits from $tmp/submit; sets $array and $merge
  local out=$1
  shift
  (cd "$tmp/submit" && env -i "${envs[@]}" bash "$script" submit ../s.pbrt "../cluster/$out" "$@") > "$tmp/submit.out" ||
    fail "submit failed: $(cat "$tmp/submit.out")"
  cat "$tmp/submit.out"
  array='' merge=''
  read -r array merge < <(sed -n 's/^submitted array job \([0-9]*\) .* merge job \([0-9]*\)$/\1 \2/p' "$tmp/submit.out")
  [ -n "$merge" ] || fail "submit did not report its jobs"
}
state() { scontrol -o show job "$1" | grep -o 'JobState=[A-Z_]*' | head -n 1 | cut -d= -f2; }
wait_end() { # JOB: its final state (a merge job must never wait forever)
  local s
  for _ in $(seq 1500); do
    s=$(state "$1")
    case $s in COMPLETED | FAILED | CANCELLED | TIMEOUT | NODE_FAIL | OUT_OF_MEMORY | PREEMPTED | BOOT_FAIL | DEADLINE)
      echo "$s"
      return
      ;;
    esac
    ! scontrol -o show job "$1" | grep -q 'Reason=DependencyNeverSatisfied' || fail "job $1 stuck on DependencyNeverSatisfied"
    sleep 0.2
  done
  fail "job $1 still $s after 300 s"
}
tiles_done() { # CHECKPOINT: finished tiles (16x16) it lists
  local hex n=0 k
  hex=$(iinfo -v "$1" 2>/dev/null | sed -n 's/^ *lensfield:done_tiles: "\(.*\)"/\1/p')
  for ((k = 0; k < ${#hex}; k++)); do
    for b in 1 2 4 8; do (((16#${hex:k:1} & b) == 0)) || n=$((n + 1)); done
  done
  echo $n
}
# Catch tasks mid-render, however loaded the machine: once each task's
# checkpoint exists (a cheap test; the task is unfinished, as the checkpoint
# goes when it ends), stop its processes (SIGSTOP to the pids `scontrol
# listpids` gives) and read the checkpoint at leisure; if it lists no
# finished tile yet, let the task run a little longer and look again. The
# tasks are left stopped: Slurm's requeue or cancel sends SIGCONT and
# SIGTERM (SIGKILL KillWait later), and they end with that checkpoint or one
# with a few more tiles. (scontrol suspend would do, but Slurm then gives
# the suspended task's CPU to another task.)
job_pids() { # JOB: its processes on this node
  local id
  id=$(scontrol -o show job "$1" | grep -o '^JobId=[0-9]*' | cut -d= -f2)
  [ -z "$id" ] || scontrol listpids "$id" 2>/dev/null | awk '$1 ~ /^[0-9]+$/ && $1 > 1 { print $1 }'
}
stop_mid_render() { # JOB CHECKPOINT [JOB CHECKPOINT...]
  local args=("$@") j k n ok pids
  for ((n = 0; n < 1200; n++)); do
    ok=1
    for ((j = 1; j < ${#args[@]}; j += 2)); do [ -f "${args[j]}" ] || ok=0; done
    [ $ok = 0 ] || break
    if ((n % 20 == 19)); then
      for ((j = 0; j < ${#args[@]}; j += 2)); do
        case $(state "${args[j]}") in PENDING | RUNNING | CONFIGURING) ;; *) fail "${args[j]} ended before its first checkpoint (too fast a render?)" ;; esac
      done
    fi
    sleep 0.05
  done
  [ $ok = 1 ] || fail "no checkpoint from ${args[*]} within 60 s"
  for ((n = 0; n < 50; n++)); do
    for ((j = 0; j < ${#args[@]}; j += 2)); do
      pids=$(job_pids "${args[j]}")
      [ -n "$pids" ] || fail "${args[j]} has no processes (ended already? too fast a render?)"
      kill -STOP $pids
    done
    ok=1
    for ((j = 1; j < ${#args[@]}; j += 2)); do
      [ -f "${args[j]}" ] || fail "${args[j]} vanished: the task ended before it could be stopped"
      k=$(tiles_done "${args[j]}")
      [ "$k" -ge 1 ] || ok=0
    done
    [ $ok = 0 ] || return 0
    for ((j = 0; j < ${#args[@]}; j += 2)); do kill -CONT $(job_pids "${args[j]}"); done
    sleep 0.3
  done
  fail "checkpoints of ${args[*]} list no finished tile after 50 looks"
}

# 4 tasks; task 1 requeued once its checkpoint holds a finished tile
submit out.exr 4 --time 10 --partition lftest --sbatch --comment=lftest --checkpoint-every 0.2 --seed 4 --spp "$spp"
P=$tmp/cluster/out.exr.parts
scontrol -o show job "${array}_0" | grep -q 'TimeLimit=00:10:00 .*Partition=lftest\|Partition=lftest .*TimeLimit=00:10:00' ||
  fail "--time/--partition did not reach sbatch: $(scontrol -o show job "${array}_0")"
scontrol -o show job "$merge" | grep -q 'Comment=lftest' || fail "--sbatch did not reach the merge job"
if (cd "$tmp/submit" && env -i "${envs[@]}" bash "$script" submit ../s.pbrt ../cluster/out.exr 4) 2> "$tmp/again.err"; then
  fail "a second submit to an output still being rendered was accepted"
fi
grep -q "still queued or running (array job $array, merge job $merge)" "$tmp/again.err" || fail "second submit: $(cat "$tmp/again.err")"
stop_mid_render "${array}_1" "$P/part-1.exr.checkpoint.exr"
scontrol requeue "${array}_1"
say "requeued task ${array}_1 mid-render (stopped with $(tiles_done "$P/part-1.exr.checkpoint.exr") of 6 tiles done)"
# while it waits to run again, status shows its progress from the checkpoint
# (final once the task's processes are gone: PENDING, no longer COMPLETING)
for _ in $(seq 300); do
  [ "$(state "${array}_1")" != PENDING ] || break
  sleep 0.1
done
"$script" status "$tmp/cluster/out.exr" > "$tmp/status1"
cat "$tmp/status1"
line=$(grep '^part 1 ' "$tmp/status1")
[[ $line =~ PENDING.*\ ([0-9]+)%\ +([0-9]+)\ of\ 6\ tiles\ at\ the\ last\ checkpoint.*requeued\ once ]] ||
  fail "status of the requeued task: $line"
k=${BASH_REMATCH[2]}
[ "$k" -ge 1 ] && [ "$k" -lt 6 ] || fail "requeued task's checkpoint has $k of 6 tiles"
[ "$k" = "$(tiles_done "$P/part-1.exr.checkpoint.exr")" ] && [ "${BASH_REMATCH[1]}" = $((100 * k / 6)) ] ||
  fail "status progress does not match the checkpoint: $line"
s=$(wait_end "$merge")
[ "$s" = COMPLETED ] || fail "merge job $merge ended $s: $(cat "$P/merge.log" 2>/dev/null)"
identical "$tmp/ref.exr" "$tmp/cluster/out.exr"
grep -q "attempt 2" "$P/task-1.log" || fail "task 1 did not run twice: $(cat "$P/task-1.log")"
grep -q "resuming from $P/part-1.exr.checkpoint.exr: $k of 6 tiles done" "$P/task-1.log" ||
  fail "task 1 did not resume from its checkpoint ($k of 6 tiles): $(cat "$P/task-1.log")"
"$script" status "$tmp/cluster/out.exr" > "$tmp/status2"
cat "$tmp/status2"
[ "$(grep -c '^part [0-3] *COMPLETED *100%' "$tmp/status2")" = 4 ] || fail "status after the merge"
grep -q '^part 1 .*requeued once' "$tmp/status2" || fail "status does not show the requeue"
grep -q '^merge *COMPLETED' "$tmp/status2" || fail "status does not show the merge"
sed 's/^/  task-1.log: /' "$P/task-1.log"
passed=$((passed + 1))
say "array of 4 tasks, task 1 requeued with $k of 6 tiles done and resumed: merged image identical"

# cancelled mid-render (as a time limit stops tasks), then the same submit
# again: the merge of the cancelled run fails, the new tasks resume
submit again.exr 2 --checkpoint-every 0.2 --seed 4 --spp "$spp"
A=$tmp/cluster/again.exr.parts
stop_mid_render "${array}_0" "$A/part-0.exr.checkpoint.exr" "${array}_1" "$A/part-1.exr.checkpoint.exr"
scancel "$array"
s=$(wait_end "$merge")
[ "$s" = FAILED ] || fail "merge after cancelled tasks ended $s, not FAILED"
grep -q "part 0 is missing: task 0 (job ${array}_0) ended CANCELLED" "$A/merge.log" || fail "merge message: $(cat "$A/merge.log")"
k0=$(tiles_done "$A/part-0.exr.checkpoint.exr") k1=$(tiles_done "$A/part-1.exr.checkpoint.exr")
submit again.exr 2 --checkpoint-every 0.2 --seed 4 --spp "$spp"
grep -q "2 resuming from their checkpoints" "$tmp/submit.out" || fail "resubmission does not resume"
s=$(wait_end "$merge")
[ "$s" = COMPLETED ] || fail "merge of the resubmission ended $s: $(cat "$A/merge.log" 2>/dev/null)"
grep -q "resuming from $A/part-0.exr.checkpoint.exr: $k0 of 12 tiles done" "$A/task-0.log" &&
  grep -q "resuming from $A/part-1.exr.checkpoint.exr: $k1 of 12 tiles done" "$A/task-1.log" ||
  fail "resubmitted tasks did not resume ($k0, $k1 of 12 tiles): $(cat "$A/task-0.log" "$A/task-1.log")"
identical "$tmp/ref.exr" "$tmp/cluster/again.exr"
passed=$((passed + 1))
say "cancelled with $k0 and $k1 of 12 tiles done, resubmitted, resumed: merged image identical"

# a task that fails: its part cannot be written (a directory is in the way)
mkdir -p "$tmp/cluster/bad.exr.parts/part-1.exr"
submit bad.exr 2 --seed 4 --spp 4
s=$(wait_end "$merge")
[ "$s" = FAILED ] || fail "merge after a failed task ended $s, not FAILED"
[ "$(state "${array}_1")" = FAILED ] || fail "task ${array}_1 did not fail: $(state "${array}_1")"
B=$tmp/cluster/bad.exr.parts
grep -q "part 1 is missing: task 1 (job ${array}_1) ended FAILED (exit code 1:0); $B/part-1.exr not written; see $B/task-1.log" \
  "$B/merge.log" || fail "merge message: $(cat "$B/merge.log")"
[ ! -e "$tmp/cluster/bad.exr" ] || fail "a failed merge wrote its output"
"$script" status "$tmp/cluster/bad.exr" > "$tmp/status3"
cat "$tmp/status3"
grep -q '^part 1 *FAILED .*exit code 1:0.*log '"$B/task-1.log" "$tmp/status3" || fail "status of the failed task"
grep -q "^merge *FAILED *log $B/merge.log" "$tmp/status3" || fail "status of the failed merge"
sed 's/^/  merge.log: /' "$B/merge.log"
passed=$((passed + 1))
say "a failed task: the merge job failed naming part 1 and $B/task-1.log"
echo "$passed passed, 0 failed"
