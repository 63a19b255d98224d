// How many threads the CPU stages of the next frame use, from the cores the last frames got.
// Idle, a frame with two or more threads keeps more than one core busy. On cores shared with
// other processes (a robot's planner, a busy loop) the helper threads often wait for a time
// slice, and the end of every parallel loop waits for the block a descheduled helper holds: one
// thread is then faster than two (bench/load_time.sh). The process cannot choose where the
// scheduler puts it, but it sees what it gets: a frame's CPU time (all threads) over its wall
// time. While the median of the last frames' cores stays below min_cores the governor runs one
// thread for a pause of frames, then tries all threads again; a try that finds no more cores
// doubles the pause (up to max_pause), one that does ends the fallback.
#pragma once

#include <deque>

namespace cvo {

struct ThreadGovernorOptions {
  int window = 5;           // frames judged together (the median of their cores)
  double min_cores = 1.15;  // below: the helpers are not getting a core of their own
  int first_pause = 20;     // frames on one thread before all threads are tried again
  int max_pause = 320;      // the pause doubles after each try that finds no more cores

  void validate() const;  // throws std::invalid_argument naming the bad field
};

class ThreadGovernor {
 public:
  // `threads`: what the settings ask for (resolved, >= 1); with 1 there is nothing to decide.
  explicit ThreadGovernor(int threads, const ThreadGovernorOptions& options = {});

  // One processed frame: its wall time and the process's CPU time over it (ms), run with
  // threads() threads. Returns the threads for the next frame. Frames too short to measure
  // (under 1 ms of wall time) are not judged.
  int update(double wall_ms, double cpu_ms);

  int threads() const { return reduced_ ? 1 : threads_; }
  bool reduced() const { return reduced_; }
  long reducedFrames() const { return reduced_frames_; }  // frames run on one thread so far
  long fallbacks() const { return fallbacks_; }           // times it fell back to one thread

 private:
  int threads_;
  ThreadGovernorOptions options_;
  std::deque<double> cores_;  // the last frames' cores, with all threads
  bool reduced_ = false;
  bool trying_ = false;  // all threads again after a pause, not yet judged
  int pause_;
  int pause_left_ = 0;
  long reduced_frames_ = 0;
  long fallbacks_ = 0;
};

}  // namespace cvo
