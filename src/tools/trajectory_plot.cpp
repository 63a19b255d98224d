#include "cvo_odometry/tools/trajectory_plot.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <vector>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace cvo {

namespace {

std::vector<Eigen::Vector3d> positions(const Trajectory& t, const Eigen::Isometry3d& alignment,
                                       double from, double to) {
  std::vector<Eigen::Vector3d> out;
  for (const auto& p : t.poses()) {
    if (p.stamp >= from && p.stamp <= to) out.push_back(alignment * p.pose.translation());
  }
  return out;
}

}  // namespace

void plotTrajectories(const std::string& png_path, const Trajectory& ground_truth,
                      const Trajectory& estimate, const Eigen::Isometry3d& alignment,
                      const std::string& title) {
  if (estimate.empty()) throw std::runtime_error("nothing to plot: the estimate is empty");
  const double from = estimate[0].stamp - 1e-6;
  const double to = estimate[estimate.size() - 1].stamp + 1e-6;
  const auto gt = positions(ground_truth, Eigen::Isometry3d::Identity(), from, to);
  const auto est = positions(estimate, alignment, from, to);
  const auto& reference = gt.size() >= 2 ? gt : est;

  // The two axes with the largest extent of the reference path.
  Eigen::Vector3d lo = reference[0], hi = reference[0];
  for (const auto& p : reference) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  for (const auto& p : est) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  std::array<int, 3> axes{0, 1, 2};
  const Eigen::Vector3d extent = hi - lo;
  std::sort(axes.begin(), axes.end(), [&](int a, int b) { return extent[a] > extent[b]; });
  const int ax = std::min(axes[0], axes[1]), ay = std::max(axes[0], axes[1]);

  const int size = 800, margin = 70;
  const double span = std::max({extent[ax], extent[ay], 1e-3});
  const double scale = (size - 2 * margin) / span;
  auto pixel = [&](const Eigen::Vector3d& p) {
    return cv::Point(static_cast<int>(margin + (p[ax] - lo[ax]) * scale),
                     static_cast<int>(size - margin - (p[ay] - lo[ay]) * scale));
  };
  cv::Mat canvas(size, size, CV_8UC3, cv::Scalar(255, 255, 255));
  auto draw = [&](const std::vector<Eigen::Vector3d>& path, const cv::Scalar& colour) {
    for (std::size_t k = 1; k < path.size(); ++k)
      cv::line(canvas, pixel(path[k - 1]), pixel(path[k]), colour, 2, cv::LINE_AA);
    if (!path.empty()) cv::circle(canvas, pixel(path.front()), 5, colour, -1, cv::LINE_AA);
  };
  draw(gt, cv::Scalar(60, 60, 60));
  draw(est, cv::Scalar(40, 40, 220));

  const char* names = "xyz";
  const auto font = cv::FONT_HERSHEY_SIMPLEX;
  cv::putText(canvas, title, cv::Point(margin, 35), font, 0.7, cv::Scalar(0, 0, 0), 2);
  cv::putText(canvas, "ground truth", cv::Point(margin, 60), font, 0.5, cv::Scalar(60, 60, 60), 1);
  cv::putText(canvas, "estimate (aligned)", cv::Point(margin + 130, 60), font, 0.5,
              cv::Scalar(40, 40, 220), 1);
  // A scale bar of a round length about a fifth of the plot.
  const double bar = std::pow(10.0, std::floor(std::log10(span / 5.0 * 2.0)));
  const int bar_px = static_cast<int>(bar * scale);
  cv::line(canvas, cv::Point(margin, size - 30), cv::Point(margin + bar_px, size - 30),
           cv::Scalar(0, 0, 0), 2);
  char label[64];
  std::snprintf(label, sizeof(label), "%g m   (axes: %c right, %c up)", bar, names[ax], names[ay]);
  cv::putText(canvas, label, cv::Point(margin + bar_px + 10, size - 25), font, 0.5,
              cv::Scalar(0, 0, 0), 1);
  if (!cv::imwrite(png_path, canvas)) throw std::runtime_error("cannot write '" + png_path + "'");
}

}  // namespace cvo
