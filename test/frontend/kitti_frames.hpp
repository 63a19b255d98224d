// Test helpers for the KITTI data of test/data: a stereo cloud of frame k of a sequence through
// a given front end, and the calibration published with kitti_stereo_pair.
#pragma once

#include <cmath>
#include <string>

#include "cvo_odometry/core/cvo_registration.hpp"
#include "cvo_odometry/core/trajectory_io.hpp"
#include "cvo_odometry/frontend/kitti_sequence.hpp"
#include "cvo_odometry/frontend/stereo_cloud_builder.hpp"

namespace cvo_test {

// Calibration published with kitti_stereo_pair (KITTI odometry 00-02 geometry).
inline cvo::PinholeIntrinsics pairIntrinsics() {
  cvo::PinholeIntrinsics K;
  K.fx = K.fy = 718.856;
  K.cx = 607.1928;
  K.cy = 185.2157;
  K.width = 1241;
  K.height = 376;
  return K;
}
constexpr double kPairBaseline = 0.537;

// Frame k of a sequence as the stereo front end takes it.
inline cvo::StereoFrame kittiFrame(const cvo::KittiSequence& sequence, std::size_t k) {
  cvo::StereoFrame f;
  sequence.load(k, &f.left, &f.right, nullptr);
  f.intrinsics = sequence.calibration().left;
  f.baseline = sequence.calibration().baseline;
  return f;
}

inline cvo::LabeledCloud kittiCloud(const cvo::KittiSequence& sequence,
                                    cvo::StereoCloudBuilder& builder, std::size_t k) {
  return builder.build(kittiFrame(sequence, k));
}

// Clouds of frames 0 and 1 of the sequence in `folder` through `builder`, registered on the CPU
// with `params` from the identity: the result's error against the ground truth's motion.
struct RegistrationError {
  bool converged = false;
  std::string message;
  double translation_m = 0.0;
  double rotation_deg = 0.0;
  double step_m = 0.0;  // the ground truth's translation
};
inline RegistrationError firstStepError(const std::string& folder, cvo::StereoCloudBuilder& builder,
                                        cvo::CvoParams params) {
  const cvo::KittiSequence sequence(folder);
  const auto target = kittiCloud(sequence, builder, 0);
  const auto source = kittiCloud(sequence, builder, 1);
  const auto gt = cvo::readKittiTrajectory(folder + "/poses.txt");
  const Eigen::Isometry3d truth = gt[0].pose.inverse() * gt[1].pose;
  params.backend = cvo::BackendChoice::kCpu;
  cvo::CvoRegistration registration(params);
  const auto result = registration.align(target, source, Eigen::Isometry3d::Identity(), true);
  const Eigen::Isometry3d error = truth.inverse() * result.transform;
  return {result.report.converged, result.report.message, error.translation().norm(),
          Eigen::AngleAxisd(error.rotation()).angle() * 180.0 / M_PI, truth.translation().norm()};
}

}  // namespace cvo_test
