#!/usr/bin/env bash
# Runs the job array's body for every task id as Slurm would (no scheduler needed), merges,
# and checks that the run files and manifest.json equal one process's, byte for byte.
#   examples/slurm/check.sh [PLAN] [TASKS]
set -euo pipefail
cd "$(dirname "$0")/../.."
PLAN=${1:-demo}
N=${2:-3}
export RAILFORCE=${RAILFORCE:-$PWD/target/release/railforce}
export RAILFORCE_GENERATE_ARGS="--settle 1"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
for i in $(seq 1 "$N"); do
  SLURM_ARRAY_TASK_ID=$i SLURM_ARRAY_TASK_COUNT=$N SLURM_CPUS_PER_TASK=1 \
    bash examples/slurm/generate.sbatch "$PLAN" "$tmp/array" >/dev/null 2>&1
done
"$RAILFORCE" generate --out "$tmp/array" --merge >/dev/null
"$RAILFORCE" generate --plan "$PLAN" --out "$tmp/single" --settle 1 >/dev/null 2>&1
for f in "$tmp/single"/*; do
  cmp "$f" "$tmp/array/$(basename "$f")"
done
echo "slurm array of $N tasks: $(ls "$tmp/single" | wc -l) files equal to one process's, byte for byte"
