// stereo_depth_scale: is the stereo front end's depth to scale? Independent of any registration:
// corners tracked (pyramidal Lucas-Kanade) from left image k to k+1 of a KITTI odometry folder,
// each with the matcher's depth in both frames, give p_k and p_k+1; under the ground-truth
// motion (R, t), R p_k+1 - p_k = -t / s when depths are s times the truth. Prints s per depth
// band, the median over frame pairs of |t|^2 / median(-(R p_k+1 - p_k) . t).
#include <algorithm>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <vector>

#include <opencv2/features2d.hpp>
#include <opencv2/video/tracking.hpp>

#include "cvo_odometry/core/trajectory_io.hpp"
#include "cvo_odometry/frontend/kitti_sequence.hpp"
#include "cvo_odometry/frontend/stereo_matcher.hpp"
#include "cvo_odometry/tools/command_line.hpp"

namespace {

const char* kUsage =
    "usage: stereo_depth_scale --kitti DIR [--sgbm-mode sgbm_3way|sgbm|hh] [--bands 12,16,25]\n"
    "  DIR holds calib.txt, times.txt, poses.txt and image_0/1 (KITTI odometry layout)\n";

double median(std::vector<double> v) {
  const auto middle = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), middle, v.end());
  return *middle;
}

struct TrackedPoint {
  Eigen::Vector3d before, after;  // in the left camera of frame k and of frame k + 1
};

// Depth of pixel p from the disparity image, or NaN.
double depthAt(const cv::Mat& disparity, const cv::Point2f& p, double fx_baseline) {
  const int u = static_cast<int>(std::lround(p.x)), v = static_cast<int>(std::lround(p.y));
  if (u < 0 || v < 0 || u >= disparity.cols || v >= disparity.rows) return NAN;
  const float d = disparity.at<float>(v, u);
  return d > 1.0f ? fx_baseline / d : NAN;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    const cvo::CommandLine cli(argc, argv, {"kitti", "sgbm-mode", "bands"}, {"help"});
    if (cli.has("help")) {
      std::cout << kUsage;
      return 0;
    }
    const std::string folder = cli.require("kitti");
    const cvo::KittiSequence sequence(folder, 0, "");
    const cvo::Trajectory truth = cvo::readKittiTrajectory(folder + "/poses.txt");
    cvo::StereoMatcherOptions matching;
    matching.mode = cli.get("sgbm-mode", matching.mode);
    const cvo::StereoMatcher matcher(matching);
    const cvo::PinholeIntrinsics& K = sequence.calibration().left;
    const double fx_baseline = K.fx * sequence.calibration().baseline;
    const std::vector<double> bands = cli.getDoubleList("bands", {12.0, 16.0, 25.0});
    const std::size_t frames = std::min(sequence.stamps().size(), truth.size());
    if (frames < 2) throw std::invalid_argument("need two frames with ground truth");

    // Per band, the scale of each frame pair.
    std::vector<std::vector<double>> scales(bands.size());
    std::vector<std::size_t> points(bands.size(), 0);
    cv::Mat left, right, unused, next_left, next_right;
    sequence.load(0, &left, &right, &unused);
    cv::Mat disparity = matcher.disparity(left, right);
    for (std::size_t k = 0; k + 1 < frames; ++k) {
      sequence.load(k + 1, &next_left, &next_right, &unused);
      const cv::Mat next_disparity = matcher.disparity(next_left, next_right);
      std::vector<cv::KeyPoint> corners;
      cv::FAST(left, corners, 8);
      std::vector<cv::Point2f> from, to;
      for (const auto& c : corners)
        from.push_back(c.pt);
      std::vector<unsigned char> found;
      std::vector<float> error;
      cv::calcOpticalFlowPyrLK(left, next_left, from, to, found, error, cv::Size(21, 21), 3);
      const Eigen::Isometry3d motion = truth[k].pose.inverse() * truth[k + 1].pose;  // k <- k+1
      const Eigen::Vector3d t = motion.translation();
      auto ray = [&](const cv::Point2f& p, double z) {
        return Eigen::Vector3d((p.x - K.cx) / K.fx * z, (p.y - K.cy) / K.fy * z, z);
      };
      std::vector<std::vector<double>> projections(bands.size());
      for (std::size_t i = 0; i < from.size(); ++i) {
        if (!found[i]) continue;
        const double z0 = depthAt(disparity, from[i], fx_baseline);
        const double z1 = depthAt(next_disparity, to[i], fx_baseline);
        if (std::isnan(z0) || std::isnan(z1)) continue;
        const Eigen::Vector3d a = motion.linear() * ray(to[i], z1) - ray(from[i], z0);
        if ((a + t).norm() > 0.5) continue;  // a moving object or a wrong track
        for (std::size_t b = 0; b < bands.size(); ++b) {
          if (std::max(z0, z1) <= bands[b]) projections[b].push_back(-a.dot(t));
        }
      }
      for (std::size_t b = 0; b < bands.size(); ++b) {
        if (projections[b].size() < 5) continue;
        points[b] += projections[b].size();
        scales[b].push_back(t.squaredNorm() / median(projections[b]));
      }
      left = next_left;
      disparity = next_disparity;
    }
    std::cout << "matching " << matching.mode << ", " << frames - 1 << " frame pairs\n";
    for (std::size_t b = 0; b < bands.size(); ++b) {
      std::cout << "  depth <= " << std::setw(5) << bands[b] << " m: ";
      if (scales[b].empty()) {
        std::cout << "no points\n";
        continue;
      }
      std::cout << "depth scale " << std::fixed << std::setprecision(4) << median(scales[b])
                << " (median of " << scales[b].size() << " pairs, " << points[b] << " points)\n";
      std::cout.unsetf(std::ios::fixed);
    }
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "stereo_depth_scale: " << e.what() << "\n";
    return 1;
  }
}
