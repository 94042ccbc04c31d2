#!/usr/bin/env bash
# Set up, then run the whole suite through ctest under a virtual X display.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cd build
xvfb-run -a ctest --output-on-failure -j1
