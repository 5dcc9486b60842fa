#!/usr/bin/env bash
# The partner terms' rows of docs/results.md ("Partner dancing"): trains the follower variants
# that switch one training term off or change its weight (skipping those already trained),
# exports them beside the shipped follower, CCM and leader, and measures them against the
# recording: interaction (training.evaluation.interaction) and Table 1's metrics (training.evaluation.evaluate).
#   bash scripts/partner_terms.sh [DATA]   (DATA defaults to $DUET_DATA, data/cmu-salsa or ../shared/data/cmu-salsa)
set -euo pipefail
cd "$(dirname "$0")/.."
PY=.venv/bin/python
DATA=${1:-$($PY -c "from training.data.folders import default_data; print(default_data())")}
ROWS=(follower_no_partner_terms follower_no_penetration follower_no_foot_contact follower_no_interaction
      follower_recorded_contact_30 follower_decoded_contact_5 follower_decoded_contact_10
      follower_decoded_contact_30 follower_decoded_contact_30_penetration_100)
for m in follower follower_ccm leader "${ROWS[@]}"; do
  [ -f "runs/models/$m/checkpoint.pt" ] || $PY -m training.learning.train --model "$m" --threads 1
done
MODELS=runs/partner_models
rm -rf "$MODELS"
names=(--model follower --model follower_ccm --model leader)
for m in "${ROWS[@]}"; do names+=(--model "$m"); done
$PY -m training.learning.export "${names[@]}" --models "$MODELS" --fp32 runs/partner_fp32 --data "$DATA"
methods=$(IFS=,; echo "ours,ccm,motion_matching,${ROWS[*]}")
$PY -m training.evaluation.interaction --data "$DATA" --takes 02,13 --models "$MODELS" --methods "$methods" \
    --out runs/partner_interaction --quiet
$PY -m training.evaluation.evaluate --data "$DATA" --takes 02,13 --models "$MODELS" --methods "$methods" \
    --conditions '' --out runs/partner_eval --quiet
