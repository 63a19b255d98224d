#pragma once

#include <string>
#include <vector>

namespace cvo {

// Rectified pinhole camera (from camera_info's P, or a dataset's calibration).
struct PinholeIntrinsics {
  double fx = 0.0, fy = 0.0, cx = 0.0, cy = 0.0;
  int width = 0, height = 0;
  // plumb_bob k1 k2 p1 p2 k3 of an unrectified image (TUM fr1/fr2); empty for rectified images.
  std::vector<double> distortion;

  // Throws std::invalid_argument naming what makes no sense (non-positive or non-finite focal
  // length, principal point far outside the image, zero size, a distortion coefficient count
  // no model has, non-finite coefficients).
  void validate() const;

  bool operator==(const PinholeIntrinsics& other) const {
    return fx == other.fx && fy == other.fy && cx == other.cx && cy == other.cy &&
           width == other.width && height == other.height && distortion == other.distortion;
  }
};

}  // namespace cvo
