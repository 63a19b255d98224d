#include "cvo_odometry/tools/stage_timer.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <ostream>

namespace cvo {

double StageTimer::percentile(const std::string& stage, double q) const {
  auto it = samples_.find(stage);
  if (it == samples_.end() || it->second.empty()) return 0.0;
  std::vector<double> v = it->second;
  std::sort(v.begin(), v.end());
  const auto k = static_cast<std::size_t>(std::lround(q * (v.size() - 1)));
  return v[std::min(k, v.size() - 1)];
}

void StageTimer::print(std::ostream& out) const {
  out << std::fixed << std::setprecision(2) << "timing (ms per frame):  median     p95\n";
  for (const auto& [stage, v] : samples_) {
    out << "  " << std::left << std::setw(20) << stage << std::right << std::setw(8)
        << percentile(stage, 0.5) << std::setw(8) << percentile(stage, 0.95) << "\n";
  }
}

}  // namespace cvo
