#include "cvo_odometry/tools/tracking_tally.hpp"

#include <ostream>

namespace cvo {

void TrackingTally::print(std::ostream& out) const {
  const auto count = [this](TrackingState state) {
    const auto it = counts_.find(state);
    return it == counts_.end() ? std::size_t{0} : it->second;
  };
  out << "tracking: " << count(TrackingState::kTracking) << " tracked, "
      << count(TrackingState::kRecovered) << " recovered, " << count(TrackingState::kLost)
      << " lost, " << count(TrackingState::kReset) << " resets, "
      << count(TrackingState::kFirstFrame) << " first frames\n";
}

}  // namespace cvo
