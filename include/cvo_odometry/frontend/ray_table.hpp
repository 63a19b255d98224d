// The normalised ray (x/z, y/z) through every pixel centre of a camera with distortion,
// undistorted once and then read by pixel: cv::undistortPoints iterates per point, and the
// ~9000 points of a TUM fr1 frame cost 0.8 ms a frame that way. Each table entry is what
// undistorting that pixel alone gives, so the cloud is the same either way.
#pragma once

#include <vector>

#include <opencv2/core.hpp>

#include "cvo_odometry/frontend/pinhole_intrinsics.hpp"

namespace cvo {

class RayTable {
 public:
  // The rays of `pixels` (inside the image of `intrinsics`); the table is (re)built when the
  // intrinsics differ from the last call's. Without distortion the rays are computed directly.
  std::vector<cv::Point2f> rays(const std::vector<cv::Point>& pixels,
                                const PinholeIntrinsics& intrinsics);

 private:
  PinholeIntrinsics intrinsics_;
  std::vector<cv::Point2f> table_;  // row-major, width x height
};

}  // namespace cvo
