#!/usr/bin/env bash
# The Slurm job script: its task and merge steps run by hand (as Slurm would
# run them) must reproduce the single-machine render bit for bit; on a
# machine with a working single-node Slurm (sinfo answers) the real
# submission is tested too, otherwise that part is skipped with a message.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
bin=${1:?usage: test_slurm.sh BUILD_BIN_DIR}
export LFRENDER=$bin/lfrender
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cat > "$tmp/s.pbrt" <<'SCENE'
LookAt 0 1 -5 0 0.5 0 0 1 0
Camera "perspective" "float fov" [40]
Film "rgb" "integer xresolution" [64] "integer yresolution" [48] "bool savefp16" false
Sampler "zsobol" "integer pixelsamples" [16]
WorldBegin
LightSource "infinite" "rgb L" [0.5 0.6 0.7]
Material "diffuse"
Shape "bilinearmesh" "point3 P" [-5 0 -5 5 0 -5 -5 0 5 5 0 5]
Translate 0 0.5 0
Shape "sphere" "float radius" [0.5]
SCENE
"$LFRENDER" "$tmp/s.pbrt" -o "$tmp/ref.exr" --seed 4 --quiet
for i in 0 1 2; do
  SLURM_ARRAY_TASK_ID=$i "$root/tools/slurm/lfrender-slurm.sh" task "$tmp/s.pbrt" "$tmp/out.exr" 3 --seed 4
done
"$root/tools/slurm/lfrender-slurm.sh" merge "$tmp/out.exr" 3
idiff -fail 0 -warn 0 "$tmp/ref.exr" "$tmp/out.exr" > /dev/null
passed=1
if command -v sbatch > /dev/null && sinfo > /dev/null 2>&1; then
  "$root/tools/slurm/lfrender-slurm.sh" submit "$tmp/s.pbrt" "$tmp/cl.exr" 3 --seed 4
  for _ in $(seq 600); do [ -f "$tmp/cl.exr" ] && break; sleep 1; done
  idiff -fail 0 -warn 0 "$tmp/ref.exr" "$tmp/cl.exr" > /dev/null
  passed=2
else
  echo "skipped: no working Slurm here (sbatch/sinfo); the task and merge steps were run by hand"
fi
echo "$passed passed, 0 failed"
