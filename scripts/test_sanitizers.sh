#!/usr/bin/env bash
# The checking build: clang with AddressSanitizer + UndefinedBehaviorSanitizer, ROS-free (core,
# front end, tools), then its unit tests, the runner end to end on the fixture, and the fuzz
# targets: the kept regressions, the committed corpus, then a fixed number of inputs from a fixed
# seed (CVO_FUZZ_RUNS to change every target's count, CVO_FUZZ_SEED the seed; the same result
# for a given commit on any machine). Any report fails the run.
# The device code runs here too (device_cpu, with clang's OpenMP and the system's Thrust,
# libthrust-dev: the other Thrust than the main build's CUDA toolkit one when nvcc is present).
set -euo pipefail
source "$(dirname "$0")/env.sh"
"$CVO_ROOT/scripts/install_deps.sh" sanitize
build="${CVO_SANITIZE_BUILD:-$CVO_ROOT/build-sanitize}"
mkdir -p "$build"
CC=clang CXX=clang++ cmake -S "$CVO_ROOT" -B "$build" -DCVO_WITH_ROS=OFF -DCVO_WITH_CUDA=OFF \
  -DCVO_WITH_DEVICE_CPU=ON -DCVO_THRUST=SYSTEM \
  -DCVO_SANITIZE=ON -DCVO_BUILD_FUZZERS=ON -DCVO_FUZZ_RUNS="${CVO_FUZZ_RUNS:-}" \
  -DCVO_FUZZ_SEED="${CVO_FUZZ_SEED:-1}" \
  -DCMAKE_BUILD_TYPE=None -DCMAKE_CXX_FLAGS="-O2 -g1" >"$build/configure.log" 2>&1 ||
  { cat "$build/configure.log"; exit 1; }
grep "cvo_odometry:" "$build/configure.log" || true
cmake --build "$build" -j"$(cvo_jobs)" --target all tests
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=1:strict_string_checks=1"
# Thrust's null-pointer dispatch idiom only (see the file).
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1:suppressions=$CVO_ROOT/cmake/thrust_ubsan.supp"
cd "$build"
ctest --output-on-failure -j"$(cvo_jobs)" | tee "$build/ctest.log"
cvo_parity_summary "$build/ctest.log"
