#!/usr/bin/env bash
# Runs every test of cvo_odometry: installs what is missing, builds (the CUDA code too when nvcc
# is present), runs the unit tests and rostests, then the checking build (clang with
# AddressSanitizer + UndefinedBehaviorSanitizer: unit tests, the runner on the fixture, bounded
# fuzzing; scripts/test_sanitizers.sh). Exits non-zero on any failure.
# CVO_SKIP_SANITIZERS=1 skips the checking build (a quicker local loop).
set -euo pipefail
source "$(dirname "$0")/env.sh"
cvo_configure
cmake --build "$CVO_BUILD" -j"$(cvo_jobs)" --target all tests
(cd "$CVO_BUILD" && ctest --output-on-failure -j"$(cvo_jobs)") | tee "$CVO_BUILD/ctest.log"
cvo_parity_summary "$CVO_BUILD/ctest.log"
if [ "${CVO_SKIP_SANITIZERS:-0}" != 1 ]; then
  "$CVO_ROOT/scripts/test_sanitizers.sh"
fi
