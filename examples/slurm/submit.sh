#!/usr/bin/env bash
# Submits a covtrace render as a job array of N parts and a merge that waits for it:
#
#   examples/slurm/submit.sh N SCENE.ron OUT.exr [covtrace render options...]
#
# Parts go to OUT.parts/ beside OUT.exr (which must not hold parts of an earlier render).
# Prints the two job ids. If a part fails, the merge is cancelled; run that part again on
# its own (render.sbatch's header says how) and merge with merge.sbatch or `covtrace merge`. Extra sbatch options
# (a partition, a time limit) can be given in SBATCH_* variables, e.g.
# SBATCH_PARTITION=gpu, as sbatch reads them.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
n=${1:?usage: submit.sh N SCENE.ron OUT.exr [covtrace render options...]}
scene=${2:?usage: submit.sh N SCENE.ron OUT.exr [covtrace render options...]}
out=${3:?usage: submit.sh N SCENE.ron OUT.exr [covtrace render options...]}
shift 3
case $n in '' | *[!0-9]* | 0) echo "submit.sh: N must be a whole number ≥ 1, got '$n'" >&2; exit 2 ;; esac
case $out in *.exr) ;; *) echo "submit.sh: OUT must end in .exr, got '$out'" >&2; exit 2 ;; esac
parts="${out%.exr}.parts"
# The merge reads every part file in the folder: parts of an earlier render would be mixed in.
if compgen -G "$parts/part-*.exr" > /dev/null; then
    echo "submit.sh: $parts/ already holds part files of an earlier render; remove them (rm $parts/part-*.exr) or choose another OUT" >&2
    exit 2
fi
array=$(sbatch --parsable --array="1-$n" "$here/render.sbatch" "$n" "$scene" "$parts" "$@")
array=${array%%;*}
# If a part fails, the merge is cancelled rather than left pending for ever.
merge=$(sbatch --parsable --dependency="afterok:$array" --kill-on-invalid-dep=yes "$here/merge.sbatch" "$parts" "$out")
merge=${merge%%;*}
echo "parts: job array $array ($n tasks) -> $parts/"
echo "merge: job $merge (after the array) -> $out"
