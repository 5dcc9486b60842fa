#!/usr/bin/env bash
# Evaluation-only models: the ablations of docs/results.md and the λG/λC sweep. Not shipped.
# Usage: bash scripts/train_ablations.sh [extra training.learning.train flags, e.g. --threads 1]
set -euo pipefail
cd "$(dirname "$0")/.."
PY=.venv/bin/python
for m in follower_small follower_ccm_large follower_no_gan follower_no_intention_noise \
         follower_end_to_end follower_end_to_end_no_ss; do
  $PY -m training.learning.train --model "$m" "$@"
done
for g in 0.1 1; do   # λC is 10; λG 0 and 0.01 are follower_no_gan and follower
  $PY -m training.learning.train --model follower --lambda-generator "$g" --runs "runs/sweep/lg$g" "$@"
done
