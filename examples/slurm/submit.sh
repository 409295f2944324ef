#!/bin/bash
# Submits a sharded `shpb sweep` as a SLURM job array (examples/slurm/sweep.sbatch) and its
# `shpb merge` as a job that starts once every task of the array has succeeded
# (--dependency=afterok:<array job id>). Run from the repository root:
#   examples/slurm/submit.sh              # 4 shards, study-1.h5 ... study-4.h5 -> study.h5
#   SHARDS=16 OUT=runs/big examples/slurm/submit.sh
set -euo pipefail

here=$(dirname "$0")
SHARDS=${SHARDS:-4}
OUT=${OUT:-study}
export OUT   # the tasks inherit the environment (sbatch's default --export=ALL)

# --parsable prints "jobid" or "jobid;cluster".
array=$(sbatch --parsable --array="1-$SHARDS" "$here/sweep.sbatch")
array=${array%%;*}

parts=""
for k in $(seq 1 "$SHARDS"); do
    parts+="$OUT-$k.h5 "
done
merge=$(sbatch --parsable --dependency="afterok:$array" --job-name=shpb-merge \
    --output=shpb-merge-%j.log --wrap="shpb merge ${parts}-o $OUT.h5 --csv $OUT.csv")
merge=${merge%%;*}
echo "submitted the sweep as array job $array ($SHARDS shards) and its merge as job $merge" >&2
