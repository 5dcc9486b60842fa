#!/usr/bin/env bash
# Retrain the shipped models with the documented command, export them beside the shipped ones
# and compare both evaluations (training.evaluation.check_retrain: tolerances and what they rest on).
# About 17 min of training plus two evaluations on the 2-core machine; not run in CI.
#   bash scripts/check_retrain.sh [DATA]      (DATA defaults like every command: DUET_DATA, data/cmu-salsa, ../shared/...)
set -euo pipefail
cd "$(dirname "$0")/.."
PY=.venv/bin/python
DATA=${1:-$($PY -c "from training.data.folders import default_data; print(default_data())")}
$PY -m training.data.prepare --data "$DATA" --prepared runs/retrain_data
$PY -m training.learning.train --all --threads 1 --prepared runs/retrain_data --runs runs/retrain
$PY -m training.learning.export --runs runs/retrain --prepared runs/retrain_data --data "$DATA" \
    --models runs/retrain_models --fp32 runs/retrain_fp32
$PY -m training.evaluation.check_retrain --data "$DATA" --shipped public/models --retrain runs/retrain_models
