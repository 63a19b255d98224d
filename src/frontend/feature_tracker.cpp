#include "cvo_odometry/frontend/feature_tracker.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <stdexcept>
#include <string>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

#include "cvo_odometry/core/labeled_cloud.hpp"
#include "cvo_odometry/frontend/depth_cloud_builder.hpp"

namespace cvo {

namespace {

// Fewest tracks a PnP solution is worth trying with.
constexpr std::size_t kMinTracks = 8;
// Pyramid levels of the backward (checking) track.
constexpr int kBackwardLevels = 1;
// A corner's response is at least this fraction of the strongest one's (OpenCV's suggestion).
constexpr double kCornerQuality = 0.01;

}  // namespace

void FeatureTrackerOptions::validate() const {
  if (max_corners < static_cast<int>(kMinTracks)) {
    throw std::invalid_argument("feature_corners must be >= " + std::to_string(kMinTracks));
  }
  if (!(min_distance > 0.0) || window < 5 || levels < 0 || levels > 8 || !(max_flow_error > 0.0) ||
      !(ransac_px > 0.0)) {
    throw std::invalid_argument("feature tracker options make no sense");
  }
}

FeatureTracker::FeatureTracker(const FeatureTrackerOptions& options) : options_(options) {
  options_.validate();
}

FeatureTracker::~FeatureTracker() {
  finishSeeding();
}

void FeatureTracker::finishSeeding() {
  if (!seeding_.valid()) return;
  std::string failure;
  try {
    seeding_.get();
  } catch (const std::exception& e) {
    failure = e.what();
  } catch (...) {
    failure = "an unknown error";
  }
  if (!failure.empty()) {
    forgetCorners();
    seed_problem_ = "finding the previous frame's corners failed: " + failure;
  }
}

void FeatureTracker::forgetCorners() {
  points_.clear();
  pixels_.clear();
  last_pyramid_.clear();
}

bool FeatureTracker::seeded() {
  finishSeeding();
  return !points_.empty();
}

void FeatureTracker::remapDepths(const std::function<float(float)>& new_depth) {
  finishSeeding();
  std::size_t kept = 0;
  for (std::size_t k = 0; k < points_.size(); ++k) {
    const float scale = rayScale(points_[k].z, new_depth);
    if (std::isnan(scale)) continue;
    points_[kept] = points_[k] * scale;
    pixels_[kept++] = pixels_[k];
  }
  points_.resize(kept);
  pixels_.resize(kept);
}

void FeatureTracker::reset() {
  finishSeeding();
  forgetCorners();
  seed_problem_.clear();
  seed_ms_ = 0.0;
  has_previous_ = false;
}

std::vector<cv::Mat> FeatureTracker::pyramid(const cv::Mat& grey,
                                             std::vector<cv::Mat> reuse) const {
  // OpenCV writes into the buffers that have the right size. Level 0 is always a copy (not the
  // caller's image, which a view with a wide enough border would be): the caller may reuse its
  // image, and these buffers are written again two frames on.
  std::vector<cv::Mat> levels = std::move(reuse);
  cv::buildOpticalFlowPyramid(grey, levels, cv::Size(options_.window, options_.window),
                              options_.levels, true, cv::BORDER_REFLECT_101, cv::BORDER_CONSTANT,
                              false);
  return levels;
}

void FeatureTracker::seed(const cv::Mat& grey, const cv::Mat& depth, const PinholeIntrinsics& K,
                          int crop_top_rows, std::vector<cv::Mat> levels) {
  last_pyramid_ = std::move(levels);
  if (grey.empty() || depth.size() != grey.size() || depth.type() != CV_32FC1) return;
  // Only the rows below the crop, with depth, can hold a corner (KITTI: a quarter of the image
  // skipped); the measure reads the rows above them.
  const std::vector<cv::Point2f>& corners = corners_.find(
      grey, depth, crop_top_rows, options_.max_corners, kCornerQuality, options_.min_distance);
  const std::vector<cv::Point2f> rays = normalisedRays(corners, K);
  for (std::size_t k = 0; k < corners.size(); ++k) {
    const float z = depth.at<float>(cvRound(corners[k].y), cvRound(corners[k].x));
    if (!std::isfinite(z) || !(z > 0.0f)) continue;
    points_.emplace_back(rays[k].x * z, rays[k].y * z, z);
    pixels_.push_back(corners[k]);
  }
}

MotionPrior FeatureTracker::track(const cv::Mat& grey, const cv::Mat& depth,
                                  const PinholeIntrinsics& K, int crop_top_rows) {
  finishSeeding();
  try {
    return trackAndSeed(grey, depth, K, crop_top_rows);
  } catch (...) {
    // The next frame must not be tracked from an older one: start over from it.
    reset();
    throw;
  }
}

MotionPrior FeatureTracker::trackAndSeed(const cv::Mat& grey, const cv::Mat& depth,
                                         const PinholeIntrinsics& K, int crop_top_rows) {
  const auto start = std::chrono::steady_clock::now();
  std::vector<cv::Mat> current = pyramid(grey, std::move(spare_pyramid_));
  MotionPrior prior =
      points_.empty() || last_pyramid_.empty() ? MotionPrior{} : solve(current, grey.size(), K);
  if (points_.empty()) {
    prior.problem =
        seed_problem_.empty() ? "no corners of a previous frame to track" : seed_problem_;
  }
  prior.seed_ms = seed_ms_;
  seed_problem_.clear();
  seed_ms_ = 0.0;
  // This frame's corners replace the previous frame's; none if the search cannot even start.
  // The previous pyramid is no longer read by anyone (the corner search is finished).
  spare_pyramid_ = std::move(last_pyramid_);
  forgetCorners();
  has_previous_ = true;
  // Copies, into the buffers of the last ones (the search for them is finished): the caller may
  // reuse its images once this returns.
  grey.copyTo(seed_grey_);
  depth.copyTo(seed_depth_);
  seeding_ = std::async(std::launch::async, [this, K, crop_top_rows,
                                             levels = std::move(current)]() mutable {
    const auto begin = std::chrono::steady_clock::now();
    seed(seed_grey_, seed_depth_, K, crop_top_rows, std::move(levels));
    seed_ms_ =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - begin).count();
  });
  prior.time_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return prior;
}

MotionPrior FeatureTracker::solve(const std::vector<cv::Mat>& current, const cv::Size& size,
                                  const PinholeIntrinsics& K) const {
  MotionPrior prior;
  const cv::Size window(options_.window, options_.window);
  const cv::TermCriteria stop(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 30, 0.01);
  std::vector<cv::Point2f> forward, backward;
  std::vector<unsigned char> ok_forward, ok_backward;
  std::vector<float> errors;
  cv::calcOpticalFlowPyrLK(last_pyramid_, current, pixels_, forward, ok_forward, errors, window,
                           options_.levels, stop);
  backward = pixels_;
  // The check starts at home (the initial flow): a right track has nothing to search for, so
  // one level above the image will do; a wrong one still moves away or fails, and RANSAC's
  // inliers judge what passes. 0.4x the cost of all levels (TUM 2.1 -> 0.9 ms, KITTI 3.8 ->
  // 1.4 ms a frame), the prior alone as accurate (README "Large motions").
  cv::calcOpticalFlowPyrLK(current, last_pyramid_, forward, backward, ok_backward, errors, window,
                           std::min(options_.levels, kBackwardLevels), stop,
                           cv::OPTFLOW_USE_INITIAL_FLOW);
  std::vector<cv::Point3f> points;
  std::vector<cv::Point2f> pixels;
  for (std::size_t k = 0; k < pixels_.size(); ++k) {
    const cv::Point2f& p = forward[k];
    const bool inside = p.x >= 0 && p.y >= 0 && p.x < size.width && p.y < size.height;
    if (!ok_forward[k] || !ok_backward[k] || !inside ||
        cv::norm(backward[k] - pixels_[k]) > options_.max_flow_error) {
      continue;
    }
    points.push_back(points_[k]);
    pixels.push_back(p);
  }
  prior.tracks = static_cast<int>(points.size());
  if (points.size() < kMinTracks) {
    prior.problem = "only " + std::to_string(points.size()) + " corners tracked";
    return prior;
  }
  const std::vector<cv::Point2f> observed = normalisedRays(pixels, K);
  const double focal = 0.5 * (K.fx + K.fy);
  const double threshold = options_.ransac_px / focal;
  cv::Mat rvec, tvec;
  std::vector<int> inliers;
  const cv::Matx33d identity = cv::Matx33d::eye();
  const bool solved =
      cv::solvePnPRansac(points, observed, identity, cv::noArray(), rvec, tvec, false, 100,
                         static_cast<float>(threshold), 0.999, inliers, cv::SOLVEPNP_EPNP);
  if (!solved || inliers.size() < 6) {
    prior.problem = "PnP found no consistent motion";
    return prior;
  }
  std::vector<cv::Point3f> inlier_points;
  std::vector<cv::Point2f> inlier_observed;
  for (int i : inliers) {
    inlier_points.push_back(points[static_cast<std::size_t>(i)]);
    inlier_observed.push_back(observed[static_cast<std::size_t>(i)]);
  }
  cv::solvePnPRefineLM(inlier_points, inlier_observed, identity, cv::noArray(), rvec, tvec);
  cv::Matx33d R;
  cv::Rodrigues(rvec, R);
  Eigen::Isometry3d current_from_previous = Eigen::Isometry3d::Identity();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c)
      current_from_previous.linear()(r, c) = R(r, c);
    current_from_previous.translation()[r] = tvec.at<double>(r);
  }
  if (!current_from_previous.matrix().allFinite()) {
    prior.problem = "PnP gave no finite motion";
    return prior;
  }
  prior.solved = true;
  prior.motion = current_from_previous.inverse();
  prior.focal_px = focal;
  // The inliers of the refined motion are the tracks that judge CVO.
  prior.tracked_points.reserve(points.size());
  prior.tracked_observations.reserve(points.size());
  for (std::size_t k = 0; k < points.size(); ++k) {
    const Eigen::Vector3d X(points[k].x, points[k].y, points[k].z);
    const Eigen::Vector2d x(observed[k].x, observed[k].y);
    prior.tracked_points.push_back(X);
    prior.tracked_observations.push_back(x);
    const Eigen::Vector3d p = current_from_previous * X;
    if (!(p.z() > 1e-6) || (p.head<2>() / p.z() - x).norm() > threshold) continue;
    prior.points.push_back(X);
    prior.observations.push_back(x);
  }
  prior.inliers = static_cast<int>(prior.points.size());
  prior.inlier_ratio = static_cast<double>(prior.inliers) / static_cast<double>(points.size());
  return prior;
}

}  // namespace cvo
