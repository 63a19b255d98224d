// A TUM RGB-D dataset folder: associations.txt (rgb_stamp rgb_file depth_stamp depth_file), or
// rgb.txt and depth.txt associated here by nearest stamp within max_gap.
#pragma once

#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "cvo_odometry/frontend/pinhole_intrinsics.hpp"

namespace cvo {

struct TumFramePaths {
  double rgb_stamp = 0.0;
  double depth_stamp = 0.0;
  std::string rgb_path;
  std::string depth_path;
  std::string rgb_listed;  // the colour file as the listing names it (below the folder)
};

class TumSequence {
 public:
  // Throws std::runtime_error / FormatError naming the file and line for malformed listings.
  explicit TumSequence(const std::string& folder, double max_gap = 0.02);

  const std::vector<TumFramePaths>& frames() const { return frames_; }
  const std::string& folder() const { return folder_; }
  // Colour (BGR) and 16-bit depth of frame `index`; throws if a file is missing or unreadable.
  void load(std::size_t index, cv::Mat* image, cv::Mat* depth) const;

 private:
  std::string folder_;
  std::vector<TumFramePaths> frames_;
};

// Published calibrations of the TUM cameras ("fr1", "fr2", "fr3") or
// "fx,fy,cx,cy[,k1,k2,p1,p2,k3]".
PinholeIntrinsics tumIntrinsics(const std::string& name, int width = 640, int height = 480);

}  // namespace cvo
