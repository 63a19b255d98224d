#include "cvo_odometry/frontend/tum_sequence.hpp"

#include <cmath>
#include <sstream>
#include <stdexcept>

#include <opencv2/imgcodecs.hpp>

#include "cvo_odometry/frontend/dataset_files.hpp"

namespace cvo {

namespace {

struct Listing {
  double stamp;
  std::string file;
};

}  // namespace

TumSequence::TumSequence(const std::string& folder, double max_gap) : folder_(folder) {
  const std::string associations = folder + "/associations.txt";
  if (fileExists(associations)) {
    for (const auto& row : readFieldRows(associations, 4)) {
      frames_.push_back({parseFiniteNumber(row[0], associations),
                         parseFiniteNumber(row[2], associations), folder + "/" + row[1],
                         folder + "/" + row[3], row[1]});
    }
  } else {
    std::vector<Listing> rgb, depth;
    for (const auto& row : readFieldRows(folder + "/rgb.txt", 2)) {
      rgb.push_back({parseFiniteNumber(row[0], "rgb.txt"), row[1]});
    }
    for (const auto& row : readFieldRows(folder + "/depth.txt", 2)) {
      depth.push_back({parseFiniteNumber(row[0], "depth.txt"), row[1]});
    }
    for (const auto& r : rgb) {
      const Listing* best = nullptr;
      for (const auto& d : depth) {
        if (std::abs(d.stamp - r.stamp) <= max_gap &&
            (!best || std::abs(d.stamp - r.stamp) < std::abs(best->stamp - r.stamp))) {
          best = &d;
        }
      }
      if (best) {
        frames_.push_back(
            {r.stamp, best->stamp, folder + "/" + r.file, folder + "/" + best->file, r.file});
      }
    }
  }
  if (frames_.empty()) throw std::runtime_error("no rgb/depth pairs found in '" + folder + "'");
}

void TumSequence::load(std::size_t index, cv::Mat* image, cv::Mat* depth) const {
  const TumFramePaths& f = frames_.at(index);
  *image = cv::imread(f.rgb_path, cv::IMREAD_COLOR);
  if (image->empty()) throw std::runtime_error("cannot read image '" + f.rgb_path + "'");
  *depth = cv::imread(f.depth_path, cv::IMREAD_ANYDEPTH);
  if (depth->empty()) throw std::runtime_error("cannot read depth '" + f.depth_path + "'");
}

PinholeIntrinsics tumIntrinsics(const std::string& name, int width, int height) {
  PinholeIntrinsics K;
  K.width = width;
  K.height = height;
  if (name == "fr1") {
    K.fx = 517.3, K.fy = 516.5, K.cx = 318.6, K.cy = 255.3;
    K.distortion = {0.2624, -0.9531, -0.0054, 0.0026, 1.1633};
  } else if (name == "fr2") {
    K.fx = 520.9, K.fy = 521.0, K.cx = 325.1, K.cy = 249.7;
    K.distortion = {0.2312, -0.7849, -0.0033, -0.0001, 0.9172};
  } else if (name == "fr3") {
    K.fx = 535.4, K.fy = 539.2, K.cx = 320.1, K.cy = 247.6;
  } else {
    std::vector<double> v;
    std::stringstream ss(name);
    std::string item;
    while (std::getline(ss, item, ','))
      v.push_back(std::strtod(item.c_str(), nullptr));
    if (v.size() != 4 && v.size() != 9) {
      throw std::invalid_argument("camera '" + name +
                                  "': expected fr1, fr2, fr3 or fx,fy,cx,cy[,k1,k2,p1,p2,k3]");
    }
    K.fx = v[0], K.fy = v[1], K.cx = v[2], K.cy = v[3];
    if (v.size() == 9) K.distortion.assign(v.begin() + 4, v.end());
  }
  K.validate();
  return K;
}

}  // namespace cvo
