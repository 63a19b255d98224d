// Frame-to-frame odometry over CVO: each new cloud is registered to the previous one. The first
// registration of a sequence starts from identity with the first-frame lengthscale; later ones
// from the previous motion, scaled to the new frame interval (constant velocity).
#pragma once

#include <memory>
#include <optional>

#include <Eigen/Geometry>

#include "cvo_odometry/core/cvo_registration.hpp"

namespace cvo {

struct OdometryUpdate {
  bool first_frame = false;  // the first cloud: no registration, pose = start
  double stamp = 0.0;
  double dt = 0.0;                                           // seconds since the previous frame
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();    // start <- current
  Eigen::Isometry3d motion = Eigen::Isometry3d::Identity();  // previous <- current
  RegistrationReport report;
};

class FrameToFrameOdometry {
 public:
  explicit FrameToFrameOdometry(const CvoParams& params,
                                std::unique_ptr<RegistrationBackend> backend = nullptr);

  // Throws std::invalid_argument if `stamp` is not after the previous frame's (call reset()
  // first for a new sequence), or for clouds the registration rejects.
  OdometryUpdate process(double stamp, LabeledCloud cloud);
  void reset();

  CvoRegistration& registration() { return registration_; }
  bool hasPrevious() const { return previous_.has_value(); }
  const LabeledCloud* previousCloud() const { return previous_ ? &*previous_ : nullptr; }

 private:
  CvoRegistration registration_;
  std::optional<LabeledCloud> previous_;
  double previous_stamp_ = 0.0;
  Eigen::Isometry3d pose_ = Eigen::Isometry3d::Identity();
  std::optional<Eigen::Isometry3d> last_motion_;
  double last_dt_ = 0.0;
};

}  // namespace cvo
