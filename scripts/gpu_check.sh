#!/usr/bin/env bash
# The GPU check, one command for a bare machine with a GPU, the CUDA toolkit, CMake and a C++
# compiler (no ROS, OpenCV or Eigen installed): builds the ROS-free core for this machine's GPU,
# runs the parity tests on device_cpu (the device code on CPU threads) and then on the GPU, runs
# cvo_benchmark (3k, 8k, 15k points, geometric and colour; cpu, cuda and device_cpu rows) and
# prints its table with the GPU target. Budget: 8 minutes.
#
# Usage: scripts/gpu_check.sh [DEPS]
#   DEPS: a folder with Eigen's headers (a copy of /usr/include/eigen3, as DEPS/eigen3 or DEPS
#   itself) and googletest's sources (a copy of /usr/src/googletest, as DEPS/googletest); by
#   default .eigen/ in the checkout (git-ignored) or beside it. Installed Eigen or GoogleTest
#   packages are used when DEPS lacks them.
# Environment: CVO_GPU_BUILD (build folder, default build-gpu), CVO_GPU_ARCH (CUDA architecture,
# default: the GPU's, from nvidia-smi; 90 without one), CVO_BENCH_REPEAT (5), CVO_GPU_BUDGET (480 s).
# Exit status: 0 all passed; 1 a build or test failed; 2 no usable CUDA device (after the
# device_cpu parity tests); 124 the budget ran out.
set -uo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${CVO_GPU_BUILD:-$root/build-gpu}"
repeat="${CVO_BENCH_REPEAT:-5}"
budget="${CVO_GPU_BUDGET:-480}"
start=$SECONDS
export PATH="$PATH:/usr/local/cuda/bin"

say() { printf 'gpu_check: %s\n' "$*"; }
fail() {
  say "FAILED: $*"
  exit 1
}
left() { echo $((budget - (SECONDS - start))); }
# Runs a stage within what is left of the budget (less `reserve` seconds for later stages).
stage() {
  local reserve=$1
  shift
  local limit=$(($(left) - reserve))
  [ "$limit" -gt 10 ] || { say "out of time before: $*"; exit 124; }
  timeout "$limit" "$@"
  local rc=$?
  [ $rc -eq 124 ] && { say "out of time in: $*"; exit 124; }
  return $rc
}

# --- Dependencies: Eigen (headers) and googletest (sources) ---------------------------------
deps="${1:-}"
if [ -z "$deps" ]; then
  for candidate in "$root/.eigen" "$root/../.eigen"; do
    [ -d "$candidate" ] && { deps="$candidate"; break; }
  done
fi
cmake_args=(-DCVO_WITH_ROS=OFF -DCVO_WITH_CUDA=ON -DCVO_WITH_DEVICE_CPU=ON -DCVO_THRUST=CUDA
  -DCMAKE_BUILD_TYPE=Release -DCMAKE_DISABLE_FIND_PACKAGE_OpenCV=ON)
eigen=""
gtest=""
if [ -n "$deps" ]; then
  [ -d "$deps" ] || fail "no folder $deps"
  for candidate in "$deps" "$deps/eigen3" "$deps/eigen" "$deps/include/eigen3"; do
    [ -f "$candidate/Eigen/Core" ] && { eigen="$(cd "$candidate" && pwd)"; break; }
  done
  for candidate in "$deps/googletest" "$deps"; do
    [ -f "$candidate/CMakeLists.txt" ] && [ -d "$candidate/googletest" ] &&
      { gtest="$(cd "$candidate" && pwd)"; break; }
  done
fi
mkdir -p "$build"
if [ -n "$eigen" ]; then
  # A header copy has no CMake package: describe it (Eigen3::Eigen, its version) for find_package.
  config="$build/eigen3-config"
  mkdir -p "$config"
  macros="$eigen/Eigen/src/Core/util/Macros.h"
  version=$(for part in WORLD MAJOR MINOR; do
    sed -n "s/^#define EIGEN_${part}_VERSION \([0-9]*\).*/\1/p" "$macros"
  done | paste -sd.)
  cat >"$config/Eigen3Config.cmake" <<EOF
if(NOT TARGET Eigen3::Eigen)
  add_library(Eigen3::Eigen INTERFACE IMPORTED)
  set_target_properties(Eigen3::Eigen PROPERTIES INTERFACE_INCLUDE_DIRECTORIES "$eigen")
endif()
set(EIGEN3_INCLUDE_DIR "$eigen")
EOF
  cat >"$config/Eigen3ConfigVersion.cmake" <<EOF
set(PACKAGE_VERSION "$version")
if(PACKAGE_FIND_VERSION VERSION_GREATER PACKAGE_VERSION)
  set(PACKAGE_VERSION_COMPATIBLE FALSE)
else()
  set(PACKAGE_VERSION_COMPATIBLE TRUE)
endif()
EOF
  cmake_args+=(-DEigen3_DIR="$config")
  say "Eigen $version from $eigen"
fi
if [ -n "$gtest" ]; then
  # The sources given, even where a GoogleTest package is installed.
  cmake_args+=(-DCVO_GTEST_SOURCE_DIR="$gtest" -DCMAKE_DISABLE_FIND_PACKAGE_GTest=ON)
  say "googletest from $gtest"
fi

# --- The GPU's architecture ------------------------------------------------------------------
arch="${CVO_GPU_ARCH:-}"
gpu=""
if [ -z "$arch" ] && command -v nvidia-smi >/dev/null; then
  gpu=$(nvidia-smi --query-gpu=name,compute_cap --format=csv,noheader 2>/dev/null | head -1)
  arch=$(echo "$gpu" | sed -n 's/.*, *\([0-9]*\)\.\([0-9]*\)$/\1\2/p')
fi
say "GPU: ${gpu:-none found by nvidia-smi}; CUDA architecture ${arch:=90}"
cmake_args+=(-DCMAKE_CUDA_ARCHITECTURES="$arch")

# --- Build -----------------------------------------------------------------------------------
command -v nvcc >/dev/null || fail "nvcc not found (PATH, /usr/local/cuda/bin)"
say "configuring $build"
stage 300 cmake -S "$root" -B "$build" "${cmake_args[@]}" >"$build/configure.log" 2>&1 ||
  { cat "$build/configure.log"; fail "configure (log: $build/configure.log)"; }
grep "cvo_odometry:" "$build/configure.log"
say "building ($(($(left)))s left)"
stage 240 cmake --build "$build" -j"$(nproc)" --target test_cuda_parity cvo_benchmark \
  >"$build/build.log" 2>&1 || { tail -40 "$build/build.log"; fail "build (log: $build/build.log)"; }

# --- Parity tests: device_cpu always, then the GPU -------------------------------------------
parity="$build/test/test_cuda_parity"
summary() { grep -E '^\[  (PASSED|FAILED|SKIPPED) ' "$1"; }
say "parity tests on device_cpu ($(left)s left)"
stage 200 "$parity" --gtest_filter='*device_cpu*:DeviceCpu.*' >"$build/parity_device_cpu.log" 2>&1
rc=$?
summary "$build/parity_device_cpu.log"
[ $rc -eq 0 ] || { grep -B2 -A12 'Failure' "$build/parity_device_cpu.log" | head -60;
  fail "device_cpu parity (log: $build/parity_device_cpu.log)"; }

device=$("$build/bench/cvo_benchmark" --check-cuda)
if [ $? -ne 0 ]; then
  say "$device"
  say "the device_cpu parity tests passed; nothing to run on a GPU ($((SECONDS - start)) s)"
  exit 2
fi
say "$device"
say "parity tests on the GPU ($(left)s left)"
stage 150 "$parity" --gtest_filter='*cuda*' >"$build/parity_cuda.log" 2>&1
rc=$?
summary "$build/parity_cuda.log"
grep -q '^\[  SKIPPED ' "$build/parity_cuda.log" && fail "GPU parity tests skipped"
[ $rc -eq 0 ] || { grep -B2 -A12 'Failure' "$build/parity_cuda.log" | head -60;
  fail "GPU parity (log: $build/parity_cuda.log)"; }

# --- Benchmark -------------------------------------------------------------------------------
say "cvo_benchmark, median of $repeat ($(left)s left)"
stage 5 "$build/bench/cvo_benchmark" --data "$root/test/data/tum_clouds" \
  --backends cpu,cuda,device_cpu --repeat "$repeat" >"$build/benchmark.txt" 2>&1
rc=$?
cat "$build/benchmark.txt"
[ $rc -eq 0 ] || fail "cvo_benchmark"
say "done in $((SECONDS - start)) s"
