#include "cvo_odometry/frontend/disparity_offset_calibration.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "cvo_odometry/frontend/depth_conversion.hpp"

namespace cvo {

namespace {

// The disparity (f b / depth) at pixel (x, y) when its 3x3 neighbourhood is one surface, its
// disparities within kMaxDisparitySpread of each other; NaN otherwise. A corner on an occluding
// edge has the background's disparity on one side and the foreground's on the other: the matcher
// may give either, and the track follows a mixture of the two as they move apart.
constexpr double kMaxDisparitySpread = 1.0;  // px
double smoothDisparity(const cv::Mat& depth, double x, double y, double focal_baseline) {
  if (!std::isfinite(x) || !std::isfinite(y)) return NAN;
  const double u_real = std::round(x), v_real = std::round(y);
  if (u_real < 1.0 || v_real < 1.0 || u_real + 1.0 >= depth.cols || v_real + 1.0 >= depth.rows) {
    return NAN;
  }
  const int u = static_cast<int>(u_real), v = static_cast<int>(v_real);
  double low = INFINITY, high = -INFINITY;
  for (int dv = -1; dv <= 1; ++dv) {
    const float* row = depth.ptr<float>(v + dv);
    for (int du = -1; du <= 1; ++du) {
      const float z = row[u + du];
      if (!(z > 0.0f) || !std::isfinite(z)) return NAN;
      const double disparity = focal_baseline / z;
      low = std::min(low, disparity);
      high = std::max(high, disparity);
    }
  }
  if (high - low > kMaxDisparitySpread) return NAN;
  return focal_baseline / depth.at<float>(v, u);
}

}  // namespace

std::function<float(float)> depthAtNewOffset(double from, double to, double focal_baseline,
                                             double min_depth, double max_depth) {
  // Judged in float against the front end's bounds, as the front end judges depths; a moved
  // depth beyond float's range (a disparity near 0 after the change) is none: converting it to
  // float is undefined.
  const std::pair<float, float> range = floatDepthRange(min_depth, max_depth);
  return [change = to - from, focal_baseline, lo = range.first, hi = range.second](float depth) {
    const double disparity = focal_baseline / depth + change;
    if (!(disparity > 0.0)) return NAN;
    const double largest = std::numeric_limits<float>::max();
    const double moved = focal_baseline / disparity;
    if (!(moved <= largest)) return NAN;
    const float result = static_cast<float>(moved);
    return result >= lo && result <= hi ? result : NAN;
  };
}

DisparityOffsetCalibration::DisparityOffsetCalibration(double start, bool enabled,
                                                       const DisparityOffsetOptions& options)
    : start_(start), enabled_(enabled), estimator_(options), offset_(start) {}

double DisparityOffsetCalibration::offsetFor(const StereoFrame& frame) {
  // A malformed frame (the front end refuses it) must not restart the estimate.
  if (frame.left.empty() || !(frame.baseline > 0.0) || !std::isfinite(frame.baseline) ||
      !(frame.intrinsics.fx > 0.0) || !std::isfinite(frame.intrinsics.fx)) {
    return offset_;
  }
  const Camera camera{frame.left.cols, frame.left.rows, frame.intrinsics.fx, frame.baseline};
  if (camera_ && !(*camera_ == camera)) {
    estimator_.reset();
    offset_ = start_;
    previous_depth_.release();
    current_depth_.release();
  }
  camera_ = camera;
  return offset_;
}

void DisparityOffsetCalibration::frameTracked(const cv::Mat& depth) {
  previous_depth_ = current_depth_;
  previous_offset_ = current_offset_;
  current_depth_ = depth.type() == CV_32FC1 ? depth : cv::Mat();
  current_offset_ = offset_;
}

bool DisparityOffsetCalibration::update(const StereoFrame& frame, const cv::Mat& depth,
                                        const std::optional<MotionPrior>& prior, bool trusted) {
  if (!enabled_) return false;
  if (prior && prior->solved && trusted && depth.type() == CV_32FC1 &&
      previous_depth_.size() == depth.size() && previous_depth_.type() == CV_32FC1) {
    // The prior's tracks, their raw disparities at both ends (depth back to disparity, less the
    // offset each frame was built with). All of them, not PnP's inliers: those agree with the
    // depth at the offset in use, which would pull the estimate towards it (KITTI 06 at stride 3:
    // 0.07 px from inliers against 0.22 at stride 1).
    const PinholeIntrinsics& K = frame.intrinsics;
    const double focal_baseline = K.fx * frame.baseline;
    StereoTracks tracks;
    tracks.reserve(prior->tracked_points.size());
    for (std::size_t k = 0; k < prior->tracked_points.size(); ++k) {
      const Eigen::Vector3d& point = prior->tracked_points[k];
      const Eigen::Vector2d& seen = prior->tracked_observations[k];
      if (!(point.z() > 0.0)) continue;
      const Eigen::Vector2d before = point.head<2>() / point.z();
      const double after_disparity =
          smoothDisparity(depth, seen.x() * K.fx + K.cx, seen.y() * K.fy + K.cy, focal_baseline);
      const double before_disparity = smoothDisparity(previous_depth_, before.x() * K.fx + K.cx,
                                                      before.y() * K.fy + K.cy, focal_baseline);
      if (std::isnan(after_disparity) || std::isnan(before_disparity)) continue;
      tracks.push_back(
          {before, seen, before_disparity - previous_offset_, after_disparity - current_offset_});
    }
    estimator_.addPair(tracks, prior->motion.inverse(), K.fx, focal_baseline, current_offset_);
  }
  const std::optional<DisparityOffsetEstimate> estimate = estimator_.estimate();
  if (!estimate || !estimate->trusted || !std::isfinite(estimate->offset) ||
      std::abs(estimate->offset - offset_) < kOffsetStep) {
    return false;
  }
  offset_ = estimate->offset;
  return true;
}

std::optional<double> DisparityOffsetCalibration::focalBaseline() const {
  if (!camera_) return std::nullopt;
  return camera_->fx * camera_->baseline;
}

}  // namespace cvo
