#!/usr/bin/env bash
# Runs every test: the C++ tests (built by scripts/setup.sh in build/py) and the Python tests.
# Fails if either fails. Shared glTF scenes: $RTSIM_SCENES, default ../shared/scenes.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

PYTHON="${PYTHON:-python}"
if [ -z "${RTSIM_SCENES:-}" ] && [ -d ../shared/scenes ]; then
  RTSIM_SCENES="$(cd ../shared/scenes && pwd)"
  export RTSIM_SCENES
fi
if [ ! -d build/py ]; then
  echo "test: build/py is missing; run 'bash scripts/setup.sh' first" >&2
  exit 1
fi

status=0
echo "== C++ tests (ctest)"
ctest --test-dir build/py --output-on-failure -j2 || status=1
echo "== Python tests (pytest)"
# One pytest worker per core (pytest-xdist, installed by setup.sh): the suite is CPU-bound.
xdist=()
if "$PYTHON" -c "import xdist" 2>/dev/null; then
  xdist=(-n "${PYTEST_WORKERS:-auto}")
fi
"$PYTHON" -m pytest tests/python -q "${xdist[@]}" || status=1

if [ "$status" -ne 0 ]; then
  echo "test: FAILED" >&2
else
  echo "test: all passed"
fi
exit "$status"
