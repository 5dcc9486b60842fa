#!/usr/bin/env bash
# Regenerates the numbers of docs/results.md ("The paper's tables on this data") and their plots (runs/plots/) from the shipped models plus the
# evaluation-only models: the ablations of that table and the λG sweep, each trained first unless finished (not shipped).
#   bash scripts/evaluate_all.sh [DATA] [extra training.learning.train flags, e.g. --threads 1]
#   (DATA defaults to $DUET_DATA, data/cmu-salsa or ../shared/data/cmu-salsa)
set -euo pipefail
cd "$(dirname "$0")/.."
PY=.venv/bin/python
DATA=${1:-$($PY -c "from training.data.folders import default_data; print(default_data())")}
shift || true
MODELS=runs/eval_models
rm -rf "$MODELS" && mkdir -p "$MODELS"
finished() {   # a run whose training reached the end (export refuses the others)
  [ -f "$1/checkpoint.pt" ] && $PY -c "import sys; from training.learning.runs import load_checkpoint; sys.exit(load_checkpoint('$1/checkpoint.pt')['stage'] != 'done')"
}

# The ablations (λC is 10; λG 0 and 0.01 are follower_no_gan and follower), trained where not finished.
for m in follower_small follower_ccm_large follower_no_gan follower_no_intention_noise \
         follower_end_to_end follower_end_to_end_no_ss; do
  finished "runs/models/$m" || $PY -m training.learning.train --model "$m" "$@"
done
for g in 0.1 1; do
  finished "runs/sweep/lg$g/follower" || $PY -m training.learning.train --model follower --lambda-generator "$g" --runs "runs/sweep/lg$g" "$@"
done

# Every finished follower variant, exported like the shipped ones (the manifest comes along).
names=()
for m in follower follower_ccm leader follower_small follower_ccm_large follower_no_gan \
         follower_no_intention_noise follower_end_to_end follower_end_to_end_no_ss; do
  if finished "runs/models/$m"; then names+=(--model "$m"); fi
done
$PY -m training.learning.export "${names[@]}" --models "$MODELS" --fp32 runs/eval_fp32 --data "$DATA"
# The λG sweep lives in runs/sweep/lgG/follower: export each under its own name.
for dir in runs/sweep/lg*; do
  finished "$dir/follower" || continue
  g=$(basename "$dir")
  $PY -m training.learning.export --runs "$dir" --model follower --models "runs/sweep_export/$g" --fp32 "runs/sweep_export/$g/fp32" --data "$DATA"
  cp "runs/sweep_export/$g/follower.onnx" "$MODELS/follower_$g.onnx"
  # Its evaluation file under the same name (both carry the same training fingerprint).
  cp "runs/sweep_export/$g/eval/follower.output_encoder.onnx" "$MODELS/eval/follower_$g.output_encoder.onnx"
done

$PY -m training.evaluation.evaluate --data "$DATA" --takes 02,13 --models "$MODELS" --out runs/eval_all \
    --seeds 0,1,2 --temperatures 0.5,1 --quiet
$PY -m training.evaluation.plots --out runs/plots --eval runs/eval_all/metrics.json   # the figures: runs/plots/*.png (git-ignored)
