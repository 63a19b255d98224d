#include "cvo_odometry/core/frame_to_frame_odometry.hpp"

#include <stdexcept>
#include <string>

#include "cvo_odometry/core/lie_group.hpp"

namespace cvo {

FrameToFrameOdometry::FrameToFrameOdometry(const CvoParams& params,
                                           std::unique_ptr<RegistrationBackend> backend)
    : registration_(params, std::move(backend)) {}

void FrameToFrameOdometry::reset() {
  previous_.reset();
  last_motion_.reset();
  pose_.setIdentity();
  last_dt_ = 0.0;
}

OdometryUpdate FrameToFrameOdometry::process(double stamp, LabeledCloud cloud) {
  OdometryUpdate update;
  update.stamp = stamp;
  if (!previous_) {
    update.first_frame = true;
    update.pose = pose_;
    previous_ = std::move(cloud);
    previous_stamp_ = stamp;
    return update;
  }
  if (!(stamp > previous_stamp_)) {
    throw std::invalid_argument("frame time " + std::to_string(stamp) +
                                " is not after the previous frame's " +
                                std::to_string(previous_stamp_) + "; reset the odometry first");
  }
  update.dt = stamp - previous_stamp_;
  Eigen::Isometry3d guess = Eigen::Isometry3d::Identity();
  const bool first_registration = !last_motion_.has_value();
  if (!first_registration) {
    guess = lie::expSE3(lie::logSE3(*last_motion_) * (update.dt / last_dt_));
  }
  const RegistrationResult result =
      registration_.align(*previous_, cloud, guess, first_registration);
  update.report = result.report;
  update.motion = result.transform;
  pose_ = lie::orthonormalized(pose_ * result.transform);
  update.pose = pose_;
  last_motion_ = result.transform;
  last_dt_ = update.dt;
  previous_ = std::move(cloud);
  previous_stamp_ = stamp;
  return update;
}

}  // namespace cvo
