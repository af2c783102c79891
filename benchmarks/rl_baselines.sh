#!/usr/bin/env bash
# The PPO baseline table's runs (benchmarks/rl_table.py reads them), one after another.
# Each run is stored in benchmarks/data/rl/ppo/<task>-s<seed>/ and checkpointed every
# 25k env steps: run this script again after an interruption and every run resumes
# where its last checkpoint left it (finished runs are skipped). ~1 h per 500k-step run
# on 2 shared cores.
#
#   nohup bash benchmarks/rl_baselines.sh > benchmarks/data/rl/ppo/log.txt 2>&1 &
set -euo pipefail
cd "$(dirname "$0")/.."
BUDGET=${BUDGET:-500000}
# a run is task:seed, or task:seed:sensing for the sensing observation (the -Sensing-v0 ids),
# or task:seed:sensing:shaped to train on the task's dense guidance too (rl_ppo.py --shaping)
RUNS=${RUNS:-"flat:0 flat:1 flat:2 wall:0 rough:0 gap:0 incline:0 push:0 carry:0 swim:0 push:0:sensing carry:0:sensing gap:0:sensing"}
for run in $RUNS; do
  IFS=: read -r task seed observe shaped <<< "$run"
  observe=${observe:-blind}
  if [ "$observe" = sensing ]; then
    dir=benchmarks/data/rl/ppo/$task-sensing${shaped:+-shaped}-s$seed
  else
    dir=benchmarks/data/rl/ppo/$task${shaped:+-shaped}-s$seed
  fi
  if [ -f "$dir/run.json" ] && grep -q '"finished": true' "$dir/run.json"; then
    echo "$dir: finished"
    continue
  fi
  echo "$(date -u +%FT%TZ) $dir: start/resume"
  python benchmarks/rl_ppo.py --task "$task" --seed "$seed" --timesteps "$BUDGET" --run-dir "$dir" \
    --observe "$observe" ${shaped:+--shaping}
done
