// stereo_point_precision: how well stereo disparities at tracked corners agree with KITTI's
// ground-truth motion, per matcher, independent of any registration (issue 42: the point matcher
// against dense SGBM). Corners of left image k (min-eigen, below the crop) are tracked into image
// k + stride (pyramidal Lucas-Kanade, forward and back within 0.5 px); each matcher gives the
// disparity at the corner in frame k and at the track's pixel in frame k + stride. The second
// one's 3D point, moved by the ground-truth motion into frame k, predicts the first disparity; the
// residual (px) is the two disparities' disagreement, both matched by the same matcher. A constant
// disparity offset c (the rig's calibration error, which the odometry estimates) is fitted per
// matcher (least median of absolute residuals over a grid). Tracks that reproject more than
// 3 px from their corner under the ground truth (a moving object, a wrong track) are left out.
// Prints, per matcher, its coverage (tracks with a disparity at both ends, of all tracks) and, on
// the tracks every matcher covers, the median residual at c = 0 (the signed bias before any
// offset is known), c, the median absolute residual, the rms of residuals within
// 2 px and the shares beyond 0.5 and 1 px.
#include <algorithm>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <map>
#include <memory>
#include <sstream>
#include <vector>

#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

#include "cvo_odometry/core/trajectory_io.hpp"
#include "cvo_odometry/frontend/color_features.hpp"
#include "cvo_odometry/frontend/kitti_sequence.hpp"
#include "cvo_odometry/frontend/point_stereo_matcher.hpp"
#include "cvo_odometry/frontend/stereo_matcher.hpp"
#include "cvo_odometry/tools/command_line.hpp"

namespace {

const char* kUsage =
    "usage: stereo_point_precision --kitti DIR [--stride N] [--matchers "
    "dense,quarter,half,sparse]\n"
    "       [--crop 100] [--corners 1000] [--block 5] [--refine 15] [--refine-height 5]\n"
    "       [--cap 63] [--radius 3] [--uniqueness 5] [--lr 1]\n"
    "  DIR: a KITTI odometry folder with poses.txt. --block ... --lr: the point matcher's\n"
    "  options (PointMatcherOptions: block_size, refine_width, refine_height, prefilter_cap,\n"
    "  search_radius,"
    " uniqueness_ratio, max_lr_difference).\n";

constexpr double kFirstRowMargin = 16.0;  // rows of context above the crop, as the front end

struct Track {
  cv::Point2f before, after;
};

double median(std::vector<double> v) {
  if (v.empty()) return NAN;
  const auto middle = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), middle, v.end());
  return *middle;
}

// One matcher's disparities at pixels of a pair.
class Matcher {
 public:
  virtual ~Matcher() = default;
  virtual void prepare(const cv::Mat& left, const cv::Mat& right, int first_row) = 0;
  virtual std::vector<float> at(const std::vector<cv::Point>& pixels) = 0;
};

class DenseMatcher : public Matcher {
 public:
  void prepare(const cv::Mat& left, const cv::Mat& right, int first_row) override {
    disparity_ = cv::Mat(left.size(), CV_32FC1, cv::Scalar(NAN));
    const cv::Range band(first_row, left.rows);
    sgbm_.disparity(left.rowRange(band), right.rowRange(band)).copyTo(disparity_.rowRange(band));
  }
  std::vector<float> at(const std::vector<cv::Point>& pixels) override {
    std::vector<float> out;
    for (const cv::Point& p : pixels)
      out.push_back(disparity_.at<float>(p));
    return out;
  }

 private:
  cvo::StereoMatcher sgbm_{cvo::StereoMatcherOptions()};
  cv::Mat disparity_;
};

class PointMatcher : public Matcher {
 public:
  explicit PointMatcher(const cvo::PointMatcherOptions& options) : matcher_(options) {}
  void prepare(const cv::Mat& left, const cv::Mat& right, int first_row) override {
    matcher_.prepare(left, right, first_row);
  }
  std::vector<float> at(const std::vector<cv::Point>& pixels) override {
    return matcher_.match(pixels);
  }

 private:
  cvo::PointStereoMatcher matcher_;
};

}  // namespace

int main(int argc, char** argv) {
  try {
    const cvo::CommandLine cli(argc, argv,
                               {"kitti", "stride", "matchers", "crop", "corners", "block", "refine",
                                "refine-height", "cap", "radius", "uniqueness", "lr"},
                               {"help"});
    if (cli.has("help")) {
      std::cout << kUsage;
      return 0;
    }
    const std::string folder = cli.require("kitti");
    const cvo::KittiSequence sequence(folder, 0, "");
    const cvo::Trajectory truth = cvo::readKittiTrajectory(folder + "/poses.txt");
    const int stride = cli.getInt("stride", 1);
    const int crop = cli.getInt("crop", 100);
    const int max_corners = cli.getInt("corners", 1000);
    if (stride < 1 || crop < 0 || max_corners < 1) {
      throw std::invalid_argument("--stride and --corners must be >= 1 and --crop >= 0");
    }
    std::vector<std::string> names;
    std::stringstream list(cli.get("matchers", "dense,quarter,half,sparse"));
    for (std::string name; std::getline(list, name, ',');)
      names.push_back(name);
    std::vector<std::unique_ptr<Matcher>> matchers;
    for (const std::string& name : names) {
      if (name == "dense") {
        matchers.push_back(std::make_unique<DenseMatcher>());
        continue;
      }
      cvo::StereoMatcherOptions mode;
      mode.depth = name;
      mode.validate();  // names the modes
      cvo::PointMatcherOptions options;
      options.coarse_level = std::max(mode.pointLevel(), 0);
      options.block_size = cli.getInt("block", options.block_size);
      options.refine_width = cli.getInt("refine", options.refine_width);
      options.refine_height = cli.getInt("refine-height", options.refine_height);
      options.prefilter_cap = cli.getInt("cap", options.prefilter_cap);
      options.search_radius = cli.getInt("radius", options.search_radius);
      options.uniqueness_ratio = cli.getInt("uniqueness", options.uniqueness_ratio);
      options.max_lr_difference = cli.getInt("lr", options.max_lr_difference);
      matchers.push_back(std::make_unique<PointMatcher>(options));
    }
    const cvo::PinholeIntrinsics& K = sequence.calibration().left;
    const double fb = K.fx * sequence.calibration().baseline;
    const int first_row = std::max(0, crop - static_cast<int>(kFirstRowMargin));
    const std::size_t frames = std::min(sequence.size(), truth.size());

    // Per matcher and track (all pairs' tracks in one list): the two disparities.
    const std::size_t m = matchers.size();
    std::vector<std::vector<float>> before(m), after(m);
    std::vector<Eigen::Vector3d> rays_before, rays_after;
    std::vector<Eigen::Isometry3d> motions;  // k <- k + stride, per track
    std::vector<cv::Point2f> corner_pixels;
    std::size_t pairs = 0;
    cv::Mat left, right, next_left, next_right, unused;
    for (std::size_t k = 0; k + stride < frames; ++k) {
      sequence.load(k, &left, &right, &unused);
      sequence.load(k + stride, &next_left, &next_right, &unused);
      for (cv::Mat* image : {&left, &right, &next_left, &next_right})
        *image = cvo::toGrey(*image);
      cv::Mat mask = cv::Mat::zeros(left.size(), CV_8UC1);
      mask.rowRange(crop, left.rows).setTo(255);
      std::vector<cv::Point2f> corners, tracked, back;
      cv::goodFeaturesToTrack(left, corners, max_corners, 0.01, 8.0, mask, 3, false);
      if (corners.empty()) continue;
      std::vector<unsigned char> ok, ok_back;
      std::vector<float> error;
      cv::calcOpticalFlowPyrLK(left, next_left, corners, tracked, ok, error, cv::Size(21, 21), 3);
      cv::calcOpticalFlowPyrLK(next_left, left, tracked, back, ok_back, error, cv::Size(21, 21), 3);
      const Eigen::Isometry3d motion = truth[k].pose.inverse() * truth[k + stride].pose;
      std::vector<cv::Point> at_before, at_after;
      std::vector<Track> kept;
      for (std::size_t i = 0; i < corners.size(); ++i) {
        const cv::Point2f& t = tracked[i];
        if (!ok[i] || !ok_back[i] || cv::norm(back[i] - corners[i]) > 0.5) continue;
        if (t.x < 0 || t.y < crop || t.x > left.cols - 1 || t.y > left.rows - 1) continue;
        kept.push_back({corners[i], t});
        at_before.emplace_back(cvRound(corners[i].x), cvRound(corners[i].y));
        at_after.emplace_back(cvRound(t.x), cvRound(t.y));
      }
      for (std::size_t j = 0; j < m; ++j) {
        matchers[j]->prepare(left, right, first_row);
        const std::vector<float> a = matchers[j]->at(at_before);
        matchers[j]->prepare(next_left, next_right, first_row);
        const std::vector<float> b = matchers[j]->at(at_after);
        before[j].insert(before[j].end(), a.begin(), a.end());
        after[j].insert(after[j].end(), b.begin(), b.end());
      }
      for (const Track& t : kept) {
        rays_before.emplace_back((t.before.x - K.cx) / K.fx, (t.before.y - K.cy) / K.fy, 1.0);
        rays_after.emplace_back((t.after.x - K.cx) / K.fx, (t.after.y - K.cy) / K.fy, 1.0);
        motions.push_back(motion);
      }
      ++pairs;
    }
    const std::size_t n = rays_before.size();
    // The residual (px) of track i for matcher j at offset c; NaN without both disparities or
    // where the ground truth does not bring the track back to its corner.
    const auto residual = [&](std::size_t j, std::size_t i, double c) -> double {
      const double a = before[j][i], b = after[j][i];
      if (!std::isfinite(a) || !std::isfinite(b) || !(b + c > 0.0)) return NAN;
      const Eigen::Vector3d moved = motions[i] * (rays_after[i] * (fb / (b + c)));
      if (!(moved.z() > 0.0)) return NAN;
      const Eigen::Vector2d seen = moved.head<2>() / moved.z();
      if ((seen - rays_before[i].head<2>()).norm() * K.fx > 3.0) return NAN;
      return a - (fb / moved.z() - c);
    };
    std::vector<bool> common(n, true);
    std::vector<std::size_t> covered(m, 0);
    for (std::size_t i = 0; i < n; ++i) {
      for (std::size_t j = 0; j < m; ++j) {
        const bool has = std::isfinite(before[j][i]) && std::isfinite(after[j][i]);
        covered[j] += has;
        common[i] = common[i] && has;
      }
    }
    const auto common_count =
        static_cast<std::size_t>(std::count(common.begin(), common.end(), true));
    std::cout << "KITTI " << folder << ", stride " << stride << ": " << pairs << " pairs, " << n
              << " tracks, " << common_count << " with a disparity from every matcher\n"
              << "| matcher | coverage | median residual at c = 0 px | offset c px | median abs "
                 "residual px "
                 "| rms within 2 px | > 0.5 px | > 1 px |\n|---|---|---|---|---|---|---|---|\n";
    for (std::size_t j = 0; j < m; ++j) {
      double best_c = 0.0, best_median = INFINITY;
      for (double c = -1.0; c <= 1.5; c += 0.01) {
        std::vector<double> values;
        for (std::size_t i = 0; i < n; ++i) {
          if (!common[i]) continue;
          const double r = residual(j, i, c);
          if (std::isfinite(r)) values.push_back(std::abs(r));
        }
        const double med = median(values);
        if (med < best_median) {
          best_median = med;
          best_c = c;
        }
      }
      std::vector<double> at_zero;
      for (std::size_t i = 0; i < n; ++i) {
        if (!common[i]) continue;
        const double r = residual(j, i, 0.0);
        if (std::isfinite(r)) at_zero.push_back(r);
      }
      double sum = 0.0;
      std::size_t within = 0, over_half = 0, over_one = 0, used = 0;
      for (std::size_t i = 0; i < n; ++i) {
        if (!common[i]) continue;
        const double r = residual(j, i, best_c);
        if (!std::isfinite(r)) continue;
        ++used;
        over_half += std::abs(r) > 0.5;
        over_one += std::abs(r) > 1.0;
        if (std::abs(r) <= 2.0) {
          sum += r * r;
          ++within;
        }
      }
      std::cout << std::fixed << std::setprecision(3) << "| " << names[j] << " | "
                << static_cast<double>(covered[j]) / std::max<std::size_t>(n, 1) << " | "
                << median(at_zero) << " | " << best_c << " | " << best_median << " | "
                << std::sqrt(sum / std::max<std::size_t>(within, 1)) << " | "
                << static_cast<double>(over_half) / std::max<std::size_t>(used, 1) << " | "
                << static_cast<double>(over_one) / std::max<std::size_t>(used, 1) << " |\n";
    }
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "stereo_point_precision: " << e.what() << "\n";
    return 1;
  }
}
