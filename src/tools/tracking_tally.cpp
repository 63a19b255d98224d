#include "cvo_odometry/tools/tracking_tally.hpp"

#include <ostream>

namespace cvo {

void TrackingTally::add(const PipelineResult& result) {
  if (result.outcome == FrameOutcome::kSkipped) {
    ++skipped_;
  } else if (result.outcome == FrameOutcome::kStale) {
    ++stale_;
  } else {
    add(result.update.state);
  }
}

void TrackingTally::print(std::ostream& out) const {
  const auto count = [this](TrackingState state) {
    const auto it = counts_.find(state);
    return it == counts_.end() ? std::size_t{0} : it->second;
  };
  out << "tracking: " << count(TrackingState::kTracking) << " tracked, "
      << count(TrackingState::kRecovered) << " recovered, " << count(TrackingState::kLost)
      << " lost, " << count(TrackingState::kReset) << " resets, "
      << count(TrackingState::kFirstFrame) << " first frames, " << skipped_ << " skipped, "
      << stale_ << " stale\n";
}

}  // namespace cvo
