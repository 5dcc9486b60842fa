#!/usr/bin/env bash
# docs/results.md, "Proximity augmentation": the shipped followers (trained with the partner
# moved closer in a quarter of the samples) against the same recipes also trained on the tempo
# copies, without proximity, and the hands-only interaction variant, all with the shipped leader;
# trains what is missing, exports them side by side and measures interaction (8 steered duets
# each) and Table 1's metrics.
#   bash scripts/proximity.sh [DATA]   (then: .venv/bin/python scripts/partner_tables.py runs/proximity_interaction/interaction.json runs/proximity_eval/metrics.json)
set -euo pipefail
cd "$(dirname "$0")/.."
PY=.venv/bin/python
DATA=${1:-$($PY -c "from training.data.folders import default_data; print(default_data())")}
ROWS=(follower_tempo follower_ccm_tempo follower_no_proximity follower_ccm_no_proximity
      follower_interaction_hands_only)
for m in follower follower_ccm leader "${ROWS[@]}"; do
  [ -f "runs/models/$m/history.json" ] || $PY -m training.learning.train --model "$m" --threads 1
done
MODELS=runs/proximity_models
rm -rf "$MODELS"
names=(--model follower --model follower_ccm --model leader)
for m in "${ROWS[@]}"; do names+=(--model "$m"); done
$PY -m training.learning.export "${names[@]}" --models "$MODELS" --fp32 runs/proximity_fp32 --data "$DATA"
methods=$(IFS=,; echo "ours,ccm,${ROWS[*]}")
$PY -m training.evaluation.interaction --data "$DATA" --takes 02,13 --models "$MODELS" --methods "$methods" \
    --seeds 8 --out runs/proximity_interaction --quiet
$PY -m training.evaluation.evaluate --data "$DATA" --takes 02,13 --models "$MODELS" --methods "$methods" \
    --conditions '' --out runs/proximity_eval --quiet
