#!/usr/bin/env bash
# Submits a covtrace render as a job array of N parts and a merge that waits for it:
#
#   examples/slurm/submit.sh N SCENE.ron OUT.exr [covtrace render options...]
#
# Parts go to OUT.parts/ beside OUT.exr. Prints the two job ids. Extra sbatch options
# (a partition, a time limit) can be given in SBATCH_* variables, e.g.
# SBATCH_PARTITION=gpu, as sbatch reads them.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
n=${1:?usage: submit.sh N SCENE.ron OUT.exr [covtrace render options...]}
scene=${2:?usage: submit.sh N SCENE.ron OUT.exr [covtrace render options...]}
out=${3:?usage: submit.sh N SCENE.ron OUT.exr [covtrace render options...]}
shift 3
case $n in '' | *[!0-9]* | 0) echo "submit.sh: N must be a whole number ≥ 1, got '$n'" >&2; exit 2 ;; esac
parts="${out%.exr}.parts"
array=$(sbatch --parsable --array="1-$n" "$here/render.sbatch" "$scene" "$parts" "$@")
array=${array%%;*}
merge=$(sbatch --parsable --dependency="afterok:$array" "$here/merge.sbatch" "$parts" "$out")
merge=${merge%%;*}
echo "parts: job array $array ($n tasks) -> $parts/"
echo "merge: job $merge (after the array) -> $out"
