#include "cvo_odometry/frontend/seven_scenes_sequence.hpp"

#include <cstdio>
#include <fstream>
#include <stdexcept>

#include <opencv2/imgcodecs.hpp>

#include "cvo_odometry/core/format_error.hpp"
#include "cvo_odometry/frontend/dataset_files.hpp"

namespace cvo {

namespace {

std::string framePrefix(const std::string& folder, std::size_t index) {
  char name[32];
  std::snprintf(name, sizeof(name), "/frame-%06zu", index);
  return folder + name;
}

}  // namespace

SevenScenesSequence::SevenScenesSequence(const std::string& folder) : folder_(folder) {
  for (std::size_t k = 0;; ++k) {
    const std::string prefix = framePrefix(folder, k);
    std::string colour = prefix + ".color.png";
    if (!fileExists(colour)) colour = prefix + ".color.jpg";
    const std::string depth = prefix + ".depth.png";
    if (!fileExists(colour) || !fileExists(depth)) break;
    colour_paths_.push_back(colour);
    depth_paths_.push_back(depth);
  }
  if (colour_paths_.empty()) {
    throw std::runtime_error("'" + folder +
                             "' is not a 7-Scenes sequence: no frame-000000.color.png (or .jpg) "
                             "with frame-000000.depth.png");
  }
}

std::string SevenScenesSequence::colourName(std::size_t index) const {
  return colour_paths_.at(index).substr(folder_.size() + 1);
}

void SevenScenesSequence::load(std::size_t index, cv::Mat* image, cv::Mat* depth) const {
  *image = cv::imread(colour_paths_.at(index), cv::IMREAD_COLOR);
  if (image->empty()) throw std::runtime_error("cannot read '" + colour_paths_[index] + "'");
  *depth = cv::imread(depth_paths_.at(index), cv::IMREAD_ANYDEPTH);
  if (depth->empty() || depth->type() != CV_16UC1) {
    throw std::runtime_error("cannot read 16-bit depth '" + depth_paths_[index] + "'");
  }
  depth->setTo(0, *depth == 65535);  // the format's "no depth"
}

Trajectory SevenScenesSequence::groundTruth() const {
  Trajectory poses;
  for (std::size_t k = 0; k < size(); ++k) {
    const std::string path = framePrefix(folder_, k) + ".pose.txt";
    if (!fileExists(path)) continue;
    const auto rows = readFieldRows(path, 4);
    if (rows.size() < 3) throw FormatError(path + ": expected a 4x4 matrix");
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 4; ++c)
        pose.matrix()(r, c) = parseFiniteNumber(rows[r][c], path);
    // Re-orthonormalise: the files carry a few digits only.
    pose.linear() = Eigen::Quaterniond(pose.linear()).normalized().toRotationMatrix();
    poses.append(stamp(k), pose);
  }
  return poses;
}

PinholeIntrinsics sevenScenesIntrinsics(int width, int height) {
  PinholeIntrinsics K;
  K.width = width;
  K.height = height;
  const double sx = width / 640.0, sy = height / 480.0;
  K.fx = 585.0 * sx, K.fy = 585.0 * sy, K.cx = 320.0 * sx, K.cy = 240.0 * sy;
  K.validate();
  return K;
}

}  // namespace cvo
