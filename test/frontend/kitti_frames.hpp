// Test helpers for the KITTI data of test/data: a stereo cloud of frame k of a sequence through
// a given front end, and the calibration published with kitti_stereo_pair.
#pragma once

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

}  // namespace cvo_test
