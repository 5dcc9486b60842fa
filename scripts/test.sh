#!/usr/bin/env bash
# `npm test`: every test of the project, also on a machine that has never seen it (Debian with
# node and python3). Setup first, each step only when it is needed:
#   1. Chromium for the end-to-end tests (Debian's package; as root it is installed, otherwise one
#      line says what to install and the other tests still run),
#   2. node modules (npm ci from package-lock.json),
#   3. the Python venv .venv from training/requirements.txt (torch brings CUDA wheels: ~5.8 GB).
# Then pytest (it also checks the fixtures the TypeScript tests read), vitest (feature math) and
# the Chromium end-to-end tests. A summary names every part that failed or could not run, and
# the exit status is non-zero if any did.
#
#   bash scripts/test.sh --dry-run    says what setup would install and which tests would run;
#                                     installs and runs nothing
# Environment: CHROMIUM=/path/to/chromium uses that browser; PYTEST_ADDOPTS is passed to pytest
# (a filter that selects no test is then not an error).
set -uo pipefail
cd "$(dirname "$0")/.."
export DEBIAN_FRONTEND=noninteractive

dry=0
case "${1:-}" in
  --dry-run) dry=1 ;;
  "") ;;
  *) echo "usage: bash scripts/test.sh [--dry-run]" >&2; exit 2 ;;
esac

missing=()   # what is not installed and could not be: those tests did not run
failed=()    # tests or setup steps that ran and failed
start=$SECONDS

say() { echo "== $*"; }
# Run a setup command, or only print it in a dry run.
setup() {
  if [ $dry = 1 ]; then echo "   would run: $*"; return 0; fi
  "$@"
}
is_root() { [ "$(id -u)" = 0 ]; }

# ---------------------------------------------------------------- system packages (Debian)
# The end-to-end harness (tests/e2e/harness.mjs) launches $CHROMIUM, default /usr/bin/chromium.
find_chromium() {
  if [ -n "${CHROMIUM:-}" ]; then
    [ -x "$CHROMIUM" ]
    return
  fi
  local found
  found=$(command -v chromium || command -v chromium-browser) || return 1
  export CHROMIUM="$found"
}
venv_works() { python3 -c 'import venv, ensurepip' 2>/dev/null; }

if ! command -v python3 >/dev/null 2>&1; then
  echo "missing: python3 (the training code and its tests are Python): install it, e.g. apt-get install -y python3 python3-venv"
  missing+=("python3")
fi

apt_packages=()
find_chromium || apt_packages+=(chromium fonts-liberation)
if command -v python3 >/dev/null 2>&1 && ! venv_works; then apt_packages+=(python3-venv); fi

if [ ${#apt_packages[@]} -gt 0 ]; then
  if is_root && command -v apt-get >/dev/null 2>&1; then
    say "installing ${apt_packages[*]} from Debian's packages (chromium with its libraries takes" \
        "about 530 MB on disk, about 70 s; apt's output goes to /tmp/duet-apt.log)"
    if [ $dry = 1 ]; then
      echo "   would run: apt-get update && apt-get install -y ${apt_packages[*]}"
      export CHROMIUM="${CHROMIUM:-/usr/bin/chromium}"   # what the install would give
    elif ! { apt-get update -qq && apt-get install -y -qq "${apt_packages[@]}"; } >/tmp/duet-apt.log 2>&1; then
      tail -n 5 /tmp/duet-apt.log
      failed+=("apt-get install ${apt_packages[*]}")
    fi
  fi
  if [ $dry = 0 ] || ! is_root; then
    if ! find_chromium; then
      if [ -n "${CHROMIUM:-}" ]; then
        echo "missing: Chromium at CHROMIUM=$CHROMIUM (the end-to-end tests drive the page in it): point CHROMIUM at a Chromium binary, or unset it to use Debian's chromium"
      else
        echo "missing: chromium (the end-to-end tests drive the page in it): as root run 'apt-get update && apt-get install -y chromium fonts-liberation', or set CHROMIUM=/path/to/chromium"
      fi
      missing+=("chromium (end-to-end tests not run)")
    fi
    if command -v python3 >/dev/null 2>&1 && ! venv_works; then
      echo "missing: python3-venv (the Python tests run in .venv): as root run 'apt-get install -y python3-venv'"
      missing+=("python3-venv (Python tests not run)")
    fi
  fi
fi

# ---------------------------------------------------------------- node modules
node_modules_ready() {
  [ -x node_modules/.bin/vitest ] && [ -d node_modules/playwright-core ] \
    && [ -d node_modules/onnxruntime-web ] && [ -d node_modules/vite ]
}
if ! node_modules_ready; then
  if [ -d node_modules ]; then
    say "node modules incomplete: npm install (about 270 MB)"
    setup npm install --no-audit --no-fund || failed+=("npm install")
  else
    say "no node_modules: npm ci (about 270 MB, about 15 s)"
    setup npm ci --no-audit --no-fund || failed+=("npm ci")
  fi
fi

# ---------------------------------------------------------------- Python venv
# --no-cache-dir: pip would otherwise keep a second copy of the downloaded wheels (several GB)
# in ~/.cache/pip. .venv/.requirements.sha256 records which training/requirements.txt was
# installed, so an edit of that file installs again; a venv made before the record existed is
# adopted when it imports.
requirements_sha=$(sha256sum training/requirements.txt | cut -d' ' -f1)
stamp=.venv/.requirements.sha256
python_ready=1
venv_imports() {
  .venv/bin/python -c 'import torch, onnx, onnxruntime, onnxscript, numpy, tqdm, matplotlib, sklearn, pytest' 2>/dev/null
}
if [[ " ${missing[*]} " == *python3* ]]; then   # python3 or python3-venv
  python_ready=0
elif [ ! -x .venv/bin/python ]; then
  say "creating .venv from training/requirements.txt: torch from PyPI brings its CUDA libraries," \
      "so this downloads several GB and .venv takes about 5.8 GB on disk (about 2 min on a fast link)"
  setup python3 -m venv .venv && setup .venv/bin/python -m pip install --quiet --upgrade pip \
    && setup .venv/bin/pip install --quiet --no-cache-dir -r training/requirements.txt \
    && { [ $dry = 1 ] || echo "$requirements_sha" > "$stamp"; } \
    || { failed+=("creating .venv"); python_ready=0; }
elif [ "$(cat "$stamp" 2>/dev/null)" != "$requirements_sha" ]; then
  if [ ! -f "$stamp" ] && venv_imports; then
    [ $dry = 1 ] || echo "$requirements_sha" > "$stamp"
  else
    say "training/requirements.txt changed or .venv is incomplete: pip install -r training/requirements.txt" \
        "(without torch yet: several GB to download, 5.8 GB on disk)"
    setup .venv/bin/pip install --quiet --no-cache-dir -r training/requirements.txt \
      && { [ $dry = 1 ] || echo "$requirements_sha" > "$stamp"; } \
      || { failed+=("pip install -r training/requirements.txt"); python_ready=0; }
  fi
fi
setup_seconds=$((SECONDS - start))

# ---------------------------------------------------------------- tests
timings=()
timed() {  # timed NAME command...: run a test part, record its wall time and result
  local name=$1 t0=$SECONDS rc
  shift
  if [ $dry = 1 ]; then echo "   would run: $*"; return 0; fi
  "$@"
  rc=$?
  timings+=("$name $((SECONDS - t0)) s")
  return $rc
}

say "pytest (tests/python)"
pytest_log=$(mktemp)
if [ $python_ready = 1 ]; then
  # -rs: one line per skipped test saying what it needs (the CMU takes: docs/data.md); the
  # summary below repeats pytest's counts and those lines.
  timed pytest bash -c '.venv/bin/python -m pytest -q -rs --durations=10 tests/python 2>&1 | tee "$1"; exit "${PIPESTATUS[0]}"' _ "$pytest_log"
  rc=$?
  if [ $rc = 5 ]; then
    # pytest's 5 means "no test collected". The repository always has Python tests, so without
    # a filter that is a broken collection, not a pass; with a filter it just matched nothing.
    if [ -n "${PYTEST_ADDOPTS:-}" ]; then
      echo "pytest: no test matched PYTEST_ADDOPTS='$PYTEST_ADDOPTS' (exit 5, not counted as a failure)"
    else
      echo "pytest: no test collected from tests/python (exit 5): counted as a failure"
      failed+=("pytest (collected no tests)")
    fi
  elif [ $rc != 0 ]; then
    failed+=("pytest")
  fi
else
  echo "   skipped: no working .venv"
fi

say "vitest (tests/web)"
if node_modules_ready || [ $dry = 1 ]; then
  timed vitest npm run --silent test:web || failed+=("vitest")
else
  echo "   skipped: node modules missing"
  missing+=("node modules (vitest and end-to-end tests not run)")
fi

# The browser tests file by file (as `npm run test:e2e` runs them, one at a time), so that the
# summary can say where their time goes and which files failed. What every file would make again
# is made once (tests/e2e/harness.mjs): the built site in dist (DUET_BUILT) and one warm Vite dev
# server (DUET_DEV_URL, tests/e2e/devserver.mjs). A file run alone makes its own.
e2e_times=()
e2e_failed=()
dev_pid=
stop_dev_server() {
  if [ -n "$dev_pid" ]; then kill "$dev_pid" 2>/dev/null; wait "$dev_pid" 2>/dev/null; dev_pid=; fi
}
trap stop_dev_server EXIT
run_e2e() {
  local file name t0=$SECONDS url_file
  if node node_modules/vite/bin/vite.js build --outDir dist --emptyOutDir --logLevel warn; then
    export DUET_BUILT=dist
  else
    echo "vite build failed: each browser test file that needs the built site builds it itself"
  fi
  url_file=$(mktemp)
  DUET_DEV_URL= node tests/e2e/devserver.mjs >"$url_file" &
  dev_pid=$!
  while kill -0 "$dev_pid" 2>/dev/null && ! grep -q '^http' "$url_file"; do sleep 0.5; done
  if grep -q '^http' "$url_file"; then
    export DUET_DEV_URL=$(head -n 1 "$url_file")
  else
    echo "the shared dev server did not start: each browser test file starts its own"
    stop_dev_server
  fi
  rm -f "$url_file"
  e2e_times+=("build-and-dev-server $((SECONDS - t0))")
  for file in tests/e2e/*.test.mjs; do
    name=$(basename "$file" .test.mjs)
    t0=$SECONDS
    node --test "$file" || e2e_failed+=("$name")
    e2e_times+=("$name $((SECONDS - t0))")
  done
  stop_dev_server
  unset DUET_BUILT DUET_DEV_URL
  [ ${#e2e_failed[@]} = 0 ]
}
say "end-to-end (Chromium, tests/e2e)"
if [[ " ${missing[*]} " == *chromium* ]]; then
  echo "   skipped: chromium missing"
elif ! node_modules_ready && [ $dry = 0 ]; then
  echo "   skipped: node modules missing"
else
  timed e2e run_e2e || failed+=("end-to-end (${e2e_failed[*]})")
fi

# ---------------------------------------------------------------- summary
echo
[ $dry = 1 ] && say "dry run: nothing was installed or run" && echo "   CHROMIUM=${CHROMIUM:-}"
join() { local out="" item; for item in "$@"; do out+="${out:+, }$item"; done; echo "$out"; }
say "wall time: setup ${setup_seconds} s${timings[*]:+, $(join "${timings[@]}")}; total $((SECONDS - start)) s"
# pytest's last line ("300 passed, 2 skipped in ...") and what each skipped test needs.
counts=$(grep -E '^[0-9]+ (passed|failed|skipped|error)' "$pytest_log" | tail -n 1 | sed 's/ in [0-9.]*s.*//')
[ -n "$counts" ] && say "pytest: $counts"
grep -E '^SKIPPED' "$pytest_log" | sed 's/^/   /'
rm -f "$pytest_log"
if [ ${#e2e_times[@]} -gt 0 ]; then
  # Each browser test file's seconds, longest first.
  say "end-to-end by file (s): $(printf '%s\n' "${e2e_times[@]}" | sort -k2 -n -r | tr '\n' ' ' | sed 's/ $//; s/\([0-9]\) \([a-z]\)/\1, \2/g')"
fi
status=0
if [ ${#failed[@]} -gt 0 ]; then
  echo "FAILED: $(join "${failed[@]}")"
  status=1
fi
if [ ${#missing[@]} -gt 0 ]; then
  echo "MISSING (install it, then run npm test again): $(join "${missing[@]}")"
  status=1
fi
[ $status = 0 ] && [ $dry = 0 ] && echo "all tests passed"
exit $status
