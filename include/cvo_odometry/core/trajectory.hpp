// A time-stamped sequence of poses (world <- body), the unit of trajectory I/O and evaluation.
#pragma once

#include <vector>

#include <Eigen/Geometry>

namespace cvo {

struct StampedPose {
  double stamp = 0.0;  // seconds
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
};

class Trajectory {
 public:
  Trajectory() = default;
  explicit Trajectory(std::vector<StampedPose> poses) : poses_(std::move(poses)) {}

  void append(double stamp, const Eigen::Isometry3d& pose) { poses_.push_back({stamp, pose}); }
  std::size_t size() const { return poses_.size(); }
  bool empty() const { return poses_.empty(); }
  const StampedPose& operator[](std::size_t i) const { return poses_[i]; }
  const std::vector<StampedPose>& poses() const { return poses_; }

  bool isTimeOrdered() const;
  // Pose at `stamp` by linear interpolation of translation and slerp of rotation between the two
  // bracketing samples; false when `stamp` is outside the trajectory or a bracketing sample is
  // farther than `max_gap` seconds away.
  bool interpolate(double stamp, double max_gap, Eigen::Isometry3d* pose) const;
  // Index of the sample nearest to `stamp` within `max_gap`, or -1.
  long nearest(double stamp, double max_gap) const;
  // Cumulative path length at every sample (metres).
  std::vector<double> pathLengths() const;

 private:
  std::vector<StampedPose> poses_;
};

}  // namespace cvo
