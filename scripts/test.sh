#!/usr/bin/env bash
# `npm test`: every test of the project. Python (pytest) first, since it also checks the
# fixtures the TypeScript tests read, then vitest (feature math), then the browser end-to-end tests.
set -euo pipefail
cd "$(dirname "$0")/.."

if [ ! -x .venv/bin/python ] || ! .venv/bin/python -c "import torch, onnxruntime, pytest" 2>/dev/null; then
  echo "== creating .venv from training/requirements.txt"
  python3 -m venv .venv
  .venv/bin/pip install --quiet --upgrade pip
  .venv/bin/pip install --quiet -r training/requirements.txt
fi

status=0
echo "== pytest"
.venv/bin/python -m pytest -q tests/python || status=1
echo "== vitest"
npx vitest run || status=1
echo "== end-to-end (Chromium)"
npm run --silent test:e2e || status=1
exit $status
