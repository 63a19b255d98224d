# Sourced by bench/peer_table.sh and bench/frame_time.sh (after scripts/env.sh): one build of
# ours and the peers, so both scripts time the same binaries.
# peer_build: installs the peers' packages (scripts/install_deps.sh peers), builds
# cvo_run_sequence, cvo_evaluate and cvo_peers with -DCVO_BUILD_PEERS=ON in build/peers (log:
# build/peers/build.log, its tail shown on failure) and sets runner, peers and evaluate to them.
# shellcheck shell=bash

peer_build() {
  # Its messages to stderr: the callers' standard output is a generated table.
  "$CVO_ROOT/scripts/install_deps.sh" peers >&2
  local build="$CVO_ROOT/build/peers"
  mkdir -p "$build"
  # Release and no ROS: the timings are of the optimised tools, not of a debug or ROS build.
  { cmake -S "$CVO_ROOT" -B "$build" -DCMAKE_BUILD_TYPE=Release -DCVO_WITH_ROS=OFF \
      -DCVO_BUILD_TESTS=OFF -DCVO_BUILD_PEERS=ON &&
    cmake --build "$build" -j"$(cvo_jobs)" --target cvo_peers cvo_run_sequence cvo_evaluate; } \
    >"$build/build.log" 2>&1 || { tail -30 "$build/build.log" >&2; return 1; }
  _peer_bin() { find "$build" -name "$1" -type f -perm -u+x | head -1; }
  runner=$(_peer_bin cvo_run_sequence)
  peers=$(_peer_bin cvo_peers)
  evaluate=$(_peer_bin cvo_evaluate)
  # shellcheck disable=SC2034  # read by the scripts that source this file
  open3d_peers="$CVO_ROOT/bench/peers/open3d_peers.py"
  local tool
  for tool in "$runner" "$peers" "$evaluate"; do
    [ -x "$tool" ] || { echo "peer_build: a tool is missing in $build" >&2; return 1; }
  done
}
