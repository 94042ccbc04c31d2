#!/usr/bin/env bash
# Set up, then run the whole suite through ctest under a virtual X display, then the unit tests and
# the bad-input matrix once more under ASan+UBSan.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cd build
xvfb-run -a ctest --output-on-failure -j1
cd ..
bash scripts/run_sanitizers.sh
