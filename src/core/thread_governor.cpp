#include "cvo_odometry/core/thread_governor.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>
#include <vector>

namespace cvo {

void ThreadGovernorOptions::validate() const {
  if (window < 1) throw std::invalid_argument("thread governor window must be >= 1");
  if (!(min_cores > 0.0)) throw std::invalid_argument("thread governor min_cores must be > 0");
  if (first_pause < 1 || max_pause < first_pause) {
    throw std::invalid_argument("thread governor pauses must satisfy 1 <= first_pause (" +
                                std::to_string(first_pause) + ") <= max_pause (" +
                                std::to_string(max_pause) + ")");
  }
}

ThreadGovernor::ThreadGovernor(int threads, const ThreadGovernorOptions& options)
    : threads_(std::max(threads, 1)), options_(options), pause_(options.first_pause) {
  options_.validate();
}

int ThreadGovernor::update(double wall_ms, double cpu_ms) {
  if (threads_ == 1 || !(wall_ms >= 1.0) || !(cpu_ms >= 0.0)) return threads();
  if (reduced_) {
    ++reduced_frames_;
    if (--pause_left_ <= 0) {
      reduced_ = false;
      trying_ = true;
      cores_.clear();
    }
    return threads();
  }
  cores_.push_back(cpu_ms / wall_ms);
  if (static_cast<int>(cores_.size()) > options_.window) cores_.pop_front();
  if (static_cast<int>(cores_.size()) < options_.window) return threads();
  std::vector<double> sorted(cores_.begin(), cores_.end());
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  if (sorted[sorted.size() / 2] >= options_.min_cores) {
    trying_ = false;
    pause_ = options_.first_pause;  // the helpers got their cores: the next fallback starts short
    return threads();
  }
  if (trying_) pause_ = std::min(2 * pause_, options_.max_pause);
  trying_ = false;
  reduced_ = true;
  pause_left_ = pause_;
  ++fallbacks_;
  cores_.clear();
  return threads();
}

}  // namespace cvo
