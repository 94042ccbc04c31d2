#!/usr/bin/env bash
# Set up, then run the whole suite through ctest under a virtual X display, then the unit tests and
# the bad-input matrix once more under ASan+UBSan.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cd build
# -noreset: Xvfb otherwise resets when its last client leaves and drops a client connecting meanwhile
# ("bad X server connection", seen once in CI).
xvfb-run -a -s "-screen 0 1280x1024x24 -noreset" ctest --output-on-failure -j1
cd ..
bash scripts/run_sanitizers.sh
