#include "cvo_odometry/frontend/kitti_sequence.hpp"

#include <array>
#include <cstdio>
#include <stdexcept>
#include <vector>

#include <opencv2/imgcodecs.hpp>

#include "cvo_odometry/core/format_error.hpp"
#include "cvo_odometry/frontend/dataset_files.hpp"

namespace cvo {

namespace {

// Row `index` of the projection matrices: "P<index>:" lines (KITTI's form) or, in a file
// without prefixes, the index-th row of 12 numbers (left then right).
std::array<double, 12> projectionRow(const std::string& path, int index) {
  const std::string key = "P" + std::to_string(index) + ":";
  std::vector<std::vector<std::string>> unprefixed;
  for (const auto& row : readFieldRows(path)) {
    if (row[0] == key) {
      if (row.size() != 13) {
        throw FormatError(path + ": " + key + " has " + std::to_string(row.size() - 1) +
                          " numbers, expected 12");
      }
      std::array<double, 12> p{};
      for (std::size_t k = 0; k < 12; ++k)
        p[k] = parseFiniteNumber(row[k + 1], path + " " + key);
      return p;
    }
    if (row.size() == 12 && row[0].back() != ':') unprefixed.push_back(row);
  }
  // Unprefixed: two rows are the pair asked for, four or more are P0..P3.
  const std::size_t at = unprefixed.size() == 2 ? static_cast<std::size_t>(index % 2)
                                                : static_cast<std::size_t>(index);
  if (at < unprefixed.size()) {
    std::array<double, 12> p{};
    for (std::size_t k = 0; k < 12; ++k)
      p[k] = parseFiniteNumber(unprefixed[at][k], path + " row " + std::to_string(at + 1));
    return p;
  }
  throw FormatError(path + ": no " + key + " line (and no unprefixed rows of 12 numbers)");
}

cv::Mat readImage(const std::string& path, int flags) {
  cv::Mat image = cv::imread(path, flags);
  if (image.empty()) throw std::runtime_error("cannot read image '" + path + "'");
  return image;
}

}  // namespace

KittiStereoCalibration readKittiCalibration(const std::string& path, int left_camera, int width,
                                            int height) {
  const auto left = projectionRow(path, left_camera);
  const auto right = projectionRow(path, left_camera + 1);
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
  // The whole layout first: everything missing is reported at once.
  std::vector<std::string> missing;
  if (!fileExists(folder + "/times.txt")) missing.push_back("times.txt (one stamp per line, s)");
  if (!fileExists(folder + "/calib.txt")) {
    missing.push_back("calib.txt (P" + std::to_string(left_camera) + ": and P" +
                      std::to_string(left_camera + 1) + ": projection rows)");
  }
  for (const std::string* dir : {&left_dir_, &right_dir_}) {
    if (!fileExists(*dir + "/" + imageName(0))) {
      missing.push_back(dir->substr(folder.size() + 1) + "/" + imageName(0) +
                        (dir == &left_dir_ ? " (left images)" : " (right images)"));
    }
  }
  if (!missing.empty()) {
    std::string message = "'" + folder + "' is not a KITTI odometry folder: missing ";
    for (std::size_t k = 0; k < missing.size(); ++k)
      message += (k ? ", " : "") + missing[k];
    for (const char* other : {"image_l", "image_r", "image_left", "image_right", "left", "right"}) {
      if (fileExists(folder + "/" + other + "/" + imageName(0))) {
        message += "; found " + std::string(other) +
                   "/ (KITTI names the pair image_0/ and "
                   "image_1/, or image_2/ and image_3/ for colour)";
        break;
      }
    }
    throw std::runtime_error(message);
  }
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
