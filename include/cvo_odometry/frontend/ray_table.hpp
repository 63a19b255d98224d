// The normalised ray (x/z, y/z) through a pixel centre of a camera with distortion, undistorted
// the first time the pixel is asked for and then read from a table: cv::undistortPoints
// iterates per point, and the ~9000 points of a TUM fr1 frame cost 0.8 ms a frame that way,
// while the selected pixels repeat from frame to frame. Each entry is what undistorting that
// pixel alone gives, so the cloud is the same either way.
#pragma once

#include <vector>

#include <opencv2/core.hpp>

#include "cvo_odometry/frontend/pinhole_intrinsics.hpp"

namespace cvo {

class RayTable {
 public:
  // The rays of `pixels` (inside the image of `intrinsics`); the table starts over when the
  // intrinsics differ from the last call's. Without distortion the rays are computed directly.
  std::vector<cv::Point2f> rays(const std::vector<cv::Point>& pixels,
                                const PinholeIntrinsics& intrinsics);

 private:
  PinholeIntrinsics intrinsics_;
  std::vector<cv::Point2f> table_;  // row-major, width x height; NaN x: not asked for yet
};

}  // namespace cvo
