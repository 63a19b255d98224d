// A Microsoft RGB-D 7-Scenes sequence folder (seq-NN/): frame-NNNNNN.color.png (or .jpg),
// frame-NNNNNN.depth.png (16-bit millimetres, 65535 where there is no depth) and
// frame-NNNNNN.pose.txt (4x4 camera-to-world), at 30 Hz; nominal intrinsics 585, 585, 320, 240.
#pragma once

#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "cvo_odometry/core/trajectory.hpp"
#include "cvo_odometry/frontend/pinhole_intrinsics.hpp"

namespace cvo {

class SevenScenesSequence {
 public:
  static constexpr double kFrameRate = 30.0;
  static constexpr double kDepthScale = 1000.0;  // depth PNG units per metre

  // Throws std::runtime_error naming the folder when it has no frame-000000.color.* and .depth.png.
  explicit SevenScenesSequence(const std::string& folder);

  std::size_t size() const { return colour_paths_.size(); }
  double stamp(std::size_t index) const { return static_cast<double>(index) / kFrameRate; }
  // The colour file's path below the folder (for segmentation images named after it).
  std::string colourName(std::size_t index) const;
  // BGR colour and 16-bit depth (65535 turned into 0, "no depth") of frame `index`.
  void load(std::size_t index, cv::Mat* image, cv::Mat* depth) const;
  // The poses of the frames that have a pose file (world <- camera), stamped like the frames.
  Trajectory groundTruth() const;

 private:
  std::string folder_;
  std::vector<std::string> colour_paths_, depth_paths_;
};

// The published nominal calibration, for `width` x `height` images (scaled from 640x480).
PinholeIntrinsics sevenScenesIntrinsics(int width = 640, int height = 480);

}  // namespace cvo
