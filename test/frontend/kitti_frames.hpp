// Test helper: a stereo cloud of frame k of a KITTI sequence through a given front end.
#pragma once

#include "cvo_odometry/frontend/kitti_sequence.hpp"
#include "cvo_odometry/frontend/stereo_cloud_builder.hpp"

namespace cvo_test {

inline cvo::LabeledCloud kittiCloud(const cvo::KittiSequence& sequence,
                                    cvo::StereoCloudBuilder& builder, std::size_t k) {
  cvo::StereoFrame f;
  sequence.load(k, &f.left, &f.right, nullptr);
  f.intrinsics = sequence.calibration().left;
  f.baseline = sequence.calibration().baseline;
  return builder.build(f);
}

}  // namespace cvo_test
