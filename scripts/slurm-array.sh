#!/usr/bin/env bash
# A Slurm (or LSF, or any) job array over tofprobe's shards, without Python
# (docs/distributed.md). One task per array index; each writes its own set:
#
#   N=16
#   jid=$(sbatch --parsable --array=0-$((N-1)) scripts/slurm-array.sh simulate CONFIG OUT)
#   sbatch --dependency=afterok:$jid scripts/slurm-array.sh merge OUT $N
#       → OUT/array: the set `tofprobe simulate CONFIG --out OUT/array` writes
#   sbatch --array=0-$((N-1)) scripts/slurm-array.sh cosim 1000 OUT
#       → OUT/cosim-i-of-N.xml: share i of the 1000-configuration soak, JUnit each
#
# Task i of n comes from $SLURM_ARRAY_TASK_ID / $SLURM_ARRAY_TASK_COUNT (LSF: set them from
# $LSB_JOBINDEX − 1 and the array's size). Threads: rayon uses $SLURM_CPUS_PER_TASK.
# The binary: $TOFPROBE, default `tofprobe` on PATH.
#SBATCH --job-name=tofprobe
#SBATCH --cpus-per-task=4
#SBATCH --mem=4G
#SBATCH --time=02:00:00
set -euo pipefail
tofprobe="${TOFPROBE:-tofprobe}"
export RAYON_NUM_THREADS="${SLURM_CPUS_PER_TASK:-${RAYON_NUM_THREADS:-1}}"
task() {
  i="${SLURM_ARRAY_TASK_ID:?not in a job array: set SLURM_ARRAY_TASK_ID (0-based)}"
  n="${SLURM_ARRAY_TASK_COUNT:?not in a job array: set SLURM_ARRAY_TASK_COUNT}"
}
case "${1:-}" in
  simulate)
    [ $# -eq 3 ] || { echo "usage: $0 simulate CONFIG OUT" >&2; exit 2; }
    task
    mkdir -p "$3"
    exec "$tofprobe" simulate "$2" --out "$3/tile-$i-of-$n" --shard "$i/$n"
    ;;
  merge)
    [ $# -eq 3 ] || { echo "usage: $0 merge OUT N" >&2; exit 2; }
    sets=()
    for ((k = 0; k < $3; k++)); do sets+=("$2/tile-$k-of-$3"); done
    exec "$tofprobe" merge "${sets[@]}" --out "$2/array"
    ;;
  cosim)
    [ $# -eq 3 ] || { echo "usage: $0 cosim N OUT" >&2; exit 2; }
    task
    mkdir -p "$3"
    exec "$tofprobe" cosim --random "$2" --shard "$i/$n" --out "$3/cosim-work-$i" \
      --junit "$3/cosim-$i-of-$n.xml"
    ;;
  *)
    echo "usage: $0 simulate CONFIG OUT | merge OUT N | cosim N OUT" >&2
    exit 2
    ;;
esac
