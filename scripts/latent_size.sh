#!/usr/bin/env bash
# The latent-size study of docs/results.md: ours and CCM at C = 8, 16, 24 code channels (32
# classes each), three seeds at 24, then the validation table (training.learning.validation).
# About 10 x 5 min on this 2-core CPU. Usage: bash scripts/latent_size.sh [extra training.learning.train flags]
set -euo pipefail
cd "$(dirname "$0")/.."
PY=.venv/bin/python
runs=()
for cs in 8:1 16:1 24:1 24:2 24:3; do
  c=${cs%:*}; s=${cs#*:}
  out="runs/latent/c${c}_s${s}"
  for m in follower follower_ccm; do
    $PY -m training.learning.train --model "$m" --channels "$c" --seed "$s" --runs "$out" "$@"
    runs+=("$out/$m")
  done
done
$PY -m training.learning.validation "${runs[@]}"
