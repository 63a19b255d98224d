// A KITTI odometry sequence folder: calib.txt (P0..P3), times.txt, image_0/image_1 (grey) or
// image_2/image_3 (colour), and optionally a folder of segmentation images with the same names.
#pragma once

#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "cvo_odometry/frontend/pinhole_intrinsics.hpp"

namespace cvo {

struct KittiStereoCalibration {
  PinholeIntrinsics left;  // rectified: no distortion
  double baseline = 0.0;   // metres, from the projection matrices' x offsets
};

class KittiSequence {
 public:
  // `left_camera`: 0 (grey pair image_0/1) or 2 (colour pair image_2/3). Throws
  // std::runtime_error / FormatError naming the file for a missing or malformed listing.
  explicit KittiSequence(const std::string& folder, int left_camera = 0,
                         const std::string& segmentation_folder = "");

  std::size_t size() const { return stamps_.size(); }
  const std::vector<double>& stamps() const { return stamps_; }
  const KittiStereoCalibration& calibration() const { return calibration_; }
  // Left and right images of frame `index`, and its segmentation when a folder was given.
  void load(std::size_t index, cv::Mat* left, cv::Mat* right, cv::Mat* segmentation) const;
  std::string imageName(std::size_t index) const;

 private:
  std::string folder_;
  std::string left_dir_, right_dir_, segmentation_dir_;
  std::vector<double> stamps_;
  KittiStereoCalibration calibration_;
};

// Reads P<left>/P<left+1> of a KITTI calib.txt; image size from `width` x `height`.
KittiStereoCalibration readKittiCalibration(const std::string& calib_path, int left_camera,
                                            int width, int height);

}  // namespace cvo
