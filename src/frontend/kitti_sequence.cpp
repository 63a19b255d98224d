#include "cvo_odometry/frontend/kitti_sequence.hpp"

#include <array>
#include <cstdio>
#include <stdexcept>

#include <opencv2/imgcodecs.hpp>

#include "cvo_odometry/core/format_error.hpp"
#include "cvo_odometry/frontend/dataset_files.hpp"

namespace cvo {

namespace {

std::array<double, 12> projectionRow(const std::string& path, const std::string& key) {
  for (const auto& row : readFieldRows(path)) {
    if (row[0] != key + ":") continue;
    if (row.size() != 13) {
      throw FormatError(path + ": " + key + " has " + std::to_string(row.size() - 1) +
                        " numbers, expected 12");
    }
    std::array<double, 12> p{};
    for (std::size_t k = 0; k < 12; ++k)
      p[k] = parseFiniteNumber(row[k + 1], path + " " + key);
    return p;
  }
  throw FormatError(path + ": no " + key + " line");
}

cv::Mat readImage(const std::string& path, int flags) {
  cv::Mat image = cv::imread(path, flags);
  if (image.empty()) throw std::runtime_error("cannot read image '" + path + "'");
  return image;
}

}  // namespace

KittiStereoCalibration readKittiCalibration(const std::string& path, int left_camera, int width,
                                            int height) {
  const auto left = projectionRow(path, "P" + std::to_string(left_camera));
  const auto right = projectionRow(path, "P" + std::to_string(left_camera + 1));
  KittiStereoCalibration calibration;
  calibration.left.fx = left[0];
  calibration.left.fy = left[5];
  calibration.left.cx = left[2];
  calibration.left.cy = left[6];
  calibration.left.width = width;
  calibration.left.height = height;
  calibration.left.validate();
  // P = K [R | t] with t_x = -fx * (camera x offset): the baseline is the offsets' difference.
  calibration.baseline = (left[3] - right[3]) / calibration.left.fx;
  if (!(calibration.baseline > 0.0)) {
    throw FormatError(path + ": P" + std::to_string(left_camera + 1) + " is not to the right of P" +
                      std::to_string(left_camera) + " (baseline " +
                      std::to_string(calibration.baseline) + " m)");
  }
  return calibration;
}

KittiSequence::KittiSequence(const std::string& folder, int left_camera,
                             const std::string& segmentation_folder)
    : folder_(folder), segmentation_dir_(segmentation_folder) {
  if (left_camera != 0 && left_camera != 2) {
    throw std::invalid_argument("KITTI left camera must be 0 (grey) or 2 (colour)");
  }
  left_dir_ = folder + "/image_" + std::to_string(left_camera);
  right_dir_ = folder + "/image_" + std::to_string(left_camera + 1);
  for (const auto& row : readFieldRows(folder + "/times.txt", 1))
    stamps_.push_back(parseFiniteNumber(row[0], folder + "/times.txt"));
  if (stamps_.empty()) throw std::runtime_error("'" + folder + "/times.txt' lists no frames");
  const cv::Mat first = readImage(left_dir_ + "/" + imageName(0), cv::IMREAD_UNCHANGED);
  calibration_ = readKittiCalibration(folder + "/calib.txt", left_camera, first.cols, first.rows);
}

std::string KittiSequence::imageName(std::size_t index) const {
  char name[32];
  std::snprintf(name, sizeof(name), "%06zu.png", index);
  return name;
}

void KittiSequence::load(std::size_t index, cv::Mat* left, cv::Mat* right,
                         cv::Mat* segmentation) const {
  if (index >= stamps_.size()) throw std::out_of_range("KITTI frame index out of range");
  const std::string name = imageName(index);
  *left = readImage(left_dir_ + "/" + name, cv::IMREAD_COLOR);
  *right = readImage(right_dir_ + "/" + name, cv::IMREAD_COLOR);
  if (segmentation) {
    *segmentation = segmentation_dir_.empty()
                        ? cv::Mat()
                        : readImage(segmentation_dir_ + "/" + name, cv::IMREAD_UNCHANGED);
  }
}

}  // namespace cvo
