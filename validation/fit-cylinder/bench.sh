#!/bin/sh
# The benchmark of issue 44 (validation/fit-cylinder/BENCH.md): a four-parameter Johnson–Cook fit
# of one simulated copper record at the default settings (standard fidelity, 16 walkers, 200
# steps, least squares and predictive band as `shpb fit` does them) on 2 worker threads, timed
# from outside by farm-bench (median of RUNS runs). Run from the repository root after
# `make build`:  sh validation/fit-cylinder/bench.sh [RUNS]
set -e
RUNS=${1:-3}
SHPB=${SHPB:-target/release/shpb}
DIR=$(mktemp -d)
"$SHPB" run scenes/shpb-cylinder-copper.toml -o "$DIR/rec.h5" --no-bands >/dev/null
farm-bench -n "$RUNS" --warmup 0 --timeout 3600 -- sh -c "exec $SHPB fit \
  scenes/shpb-cylinder-copper.toml --record $DIR/rec.h5 \
  --free specimen.johnson_cook.a_pa=40e6:160e6 --free specimen.johnson_cook.b_pa=100e6:500e6 \
  --free specimen.johnson_cook.n=0.1:0.7 --free specimen.johnson_cook.c=0:0.1 \
  -j 2 --json >>$DIR/fit.json 2>&1"
echo "fit output (with its \"evaluations\" = forward runs): $DIR/fit.json"
