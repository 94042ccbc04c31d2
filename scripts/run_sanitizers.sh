#!/usr/bin/env bash
# The unit tests and the bad-input matrix under AddressSanitizer and UndefinedBehaviorSanitizer, in
# build-sanitize/ (the filters module and the core are instrumented; ParaView's libraries are not).
# Expects the packages of scripts/setup.sh. Any sanitizer report fails the run.
set -euo pipefail
cd "$(dirname "$0")/.."
flags="-fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer -O1 -g"
cmake -S . -B build-sanitize -DCMAKE_BUILD_TYPE=RelWithDebInfo -DFEATUREMESH_XML_DOCUMENTATION=OFF \
  -DCMAKE_CXX_FLAGS="$flags" -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined" \
  -DCMAKE_SHARED_LINKER_FLAGS="-fsanitize=address,undefined" > build-sanitize.log
cmake --build build-sanitize -j"$(nproc)" --target FeatureMeshCoreTests FeatureMeshBadInputTests >> build-sanitize.log
cd build-sanitize
# Leak checking is off: ParaView's libraries keep singletons alive at exit.
export ASAN_OPTIONS=detect_leaks=0:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
ctest --output-on-failure -j"$(nproc)" -L "unit|badinput"
