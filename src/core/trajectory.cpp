#include "cvo_odometry/core/trajectory.hpp"

#include <algorithm>
#include <cmath>

namespace cvo {

bool Trajectory::isTimeOrdered() const {
  for (std::size_t i = 1; i < poses_.size(); ++i) {
    if (!(poses_[i].stamp > poses_[i - 1].stamp)) return false;
  }
  return true;
}

bool Trajectory::interpolate(double stamp, double max_gap, Eigen::Isometry3d* pose) const {
  if (poses_.empty()) return false;
  auto upper = std::lower_bound(poses_.begin(), poses_.end(), stamp,
                                [](const StampedPose& p, double s) { return p.stamp < s; });
  if (upper != poses_.end() && upper->stamp == stamp) {
    *pose = upper->pose;
    return true;
  }
  if (upper == poses_.begin() || upper == poses_.end()) return false;
  const StampedPose& b = *upper;
  const StampedPose& a = *(upper - 1);
  if (stamp - a.stamp > max_gap || b.stamp - stamp > max_gap) return false;
  const double f = (stamp - a.stamp) / (b.stamp - a.stamp);
  const Eigen::Quaterniond qa(a.pose.linear()), qb(b.pose.linear());
  pose->setIdentity();
  pose->linear() = qa.slerp(f, qb).toRotationMatrix();
  pose->translation() = (1.0 - f) * a.pose.translation() + f * b.pose.translation();
  return true;
}

long Trajectory::nearest(double stamp, double max_gap) const {
  long best = -1;
  double best_gap = max_gap;
  auto upper = std::lower_bound(poses_.begin(), poses_.end(), stamp,
                                [](const StampedPose& p, double s) { return p.stamp < s; });
  for (auto it : {upper - 1, upper}) {
    if (it < poses_.begin() || it >= poses_.end()) continue;
    const double gap = std::abs(it->stamp - stamp);
    if (gap <= best_gap) {
      best_gap = gap;
      best = static_cast<long>(it - poses_.begin());
    }
  }
  return best;
}

std::vector<double> Trajectory::pathLengths() const {
  std::vector<double> lengths(poses_.size(), 0.0);
  for (std::size_t i = 1; i < poses_.size(); ++i) {
    lengths[i] =
        lengths[i - 1] + (poses_[i].pose.translation() - poses_[i - 1].pose.translation()).norm();
  }
  return lengths;
}

}  // namespace cvo
