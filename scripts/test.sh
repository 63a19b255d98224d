#!/usr/bin/env bash
# Runs every test of cvo_odometry: installs what is missing, builds (the CUDA code too when nvcc
# is present), runs the unit tests and rostests, exits non-zero on any failure.
set -euo pipefail
source "$(dirname "$0")/env.sh"
cvo_configure
cmake --build "$CVO_BUILD" -j"$(cvo_jobs)" --target all tests
cd "$CVO_BUILD"
ctest --output-on-failure -j"$(cvo_jobs)"
