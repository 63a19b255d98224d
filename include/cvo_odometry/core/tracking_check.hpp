// Is a frame-to-frame registration to be trusted? The judgement FrameToFrameOdometry applies to
// every registration, callable alone for tools and tests.
#pragma once

#include <cstddef>
#include <string>

#include <Eigen/Geometry>

#include "cvo_odometry/core/cvo_params.hpp"
#include "cvo_odometry/core/registration_report.hpp"

namespace cvo {

struct TrackingCheck {
  bool good = true;
  std::string problems;  // "; "-separated reasons when not good
};

// Too few points in either cloud (before registering).
TrackingCheck checkPointCounts(std::size_t target_points, std::size_t source_points,
                               const CvoParams& params);

// A registration result: converged, cosine >= min_cosine, and `motion` (target <- source) over
// `dt` seconds within max_linear_speed and max_angular_speed.
TrackingCheck checkRegistration(const RegistrationReport& report, double cosine,
                                const Eigen::Isometry3d& motion, double dt,
                                const CvoParams& params);

}  // namespace cvo
