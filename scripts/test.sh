#!/usr/bin/env bash
# Runs every test of cvo_odometry: installs what is missing, builds (the CUDA code too when nvcc
# is present), runs the unit tests and rostests, exits non-zero on any failure.
set -euo pipefail
source "$(dirname "$0")/env.sh"
"$CVO_ROOT/scripts/install_deps.sh" full

mkdir -p "$CVO_BUILD"
cmake -S "$CVO_ROOT" -B "$CVO_BUILD" -DCMAKE_BUILD_TYPE=Release >"$CVO_BUILD/configure.log" 2>&1 ||
  { cat "$CVO_BUILD/configure.log"; exit 1; }
grep "cvo_odometry:" "$CVO_BUILD/configure.log" || true
cmake --build "$CVO_BUILD" -j"$(cvo_jobs)" --target all tests
cd "$CVO_BUILD"
ctest --output-on-failure -j"$(cvo_jobs)"
