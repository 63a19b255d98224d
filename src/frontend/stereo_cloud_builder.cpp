#include "cvo_odometry/frontend/stereo_cloud_builder.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <opencv2/features2d.hpp>

#include "cvo_odometry/frontend/color_features.hpp"
#include "cvo_odometry/frontend/depth_conversion.hpp"

namespace cvo {

namespace {
constexpr int kMatchingContextRows = 16;
// Point modes: FAST candidates at this much below the selection's last threshold, so that a
// selection that lowers its threshold by one within a frame still finds its corners with depth
// (KITTI 06: the threshold rose from 13 to 15 over 51 frames and never fell; each step down
// beyond this costs the selection one more FAST pass over the image).
constexpr int kFastMargin = 1;
// Grid candidates (grid and mixed selectors): about this many times max_points of them.
constexpr double kGridShare = 1.5;
// FAST needs 3 pixels on every side.
constexpr int kFastBorder = 3;
// Depth images kept for reuse: the front end's frame, the offset estimate's two, one spare.
constexpr std::size_t kDepthBuffers = 4;

// The point matcher's smallest block: without SGBM's paths to smooth its costs, a 5 px block
// matches KITTI 06's points less surely than SGBM's 5 px block does. quarter on the 51 pairs,
// block 5 -> 7: 10.02 -> 9.73 mm a frame (dense SGBM 9.60), stride 2 25.21 -> 23.60 mm, stride 3
// 45.65 -> 45.48 mm, at the same time a frame; 9 and 11 gave 9.82 and 9.64 mm at stride 1 but
// 25.3 mm at stride 2 (11).
constexpr int kMinPointBlock = 7;

PointMatcherOptions pointOptions(const StereoMatcherOptions& matcher) {
  PointMatcherOptions options;
  options.min_disparity = matcher.min_disparity;
  options.num_disparities = matcher.num_disparities;
  options.block_size = std::max(matcher.block_size, kMinPointBlock);
  options.coarse_level = std::max(matcher.pointLevel(), 0);
  return options;
}
}  // namespace

StereoCloudBuilder::StereoCloudBuilder(const StereoFrontendOptions& options)
    : options_(options),
      matcher_(options.matcher),
      cloud_builder_(options.cloud),
      point_options_(pointOptions(options.matcher)),
      fast_threshold_(options.cloud.selector.initial_fast_threshold) {
  if (!(options.disparity_scale > 0.0)) {
    throw std::invalid_argument("disparity scale must be positive");
  }
  if (options_.matcher.pointLevel() >= 0) {
    point_options_.validate();
    current_.matcher = std::make_unique<PointStereoMatcher>(point_options_);
    previous_.matcher = std::make_unique<PointStereoMatcher>(point_options_);
  }
}

void StereoCloudBuilder::checkFrame(const StereoFrame& frame) const {
  if (!(frame.baseline > 0.0) || !std::isfinite(frame.baseline)) {
    throw std::invalid_argument("stereo baseline must be positive, got " +
                                std::to_string(frame.baseline) + " m");
  }
  frame.intrinsics.validate();
  if (frame.disparity.empty() && frame.right.empty()) {
    throw std::invalid_argument("stereo frame has neither a right image nor a disparity image");
  }
}

std::vector<cv::Point> StereoCloudBuilder::pointPixels(const cv::Mat& grey) const {
  const int first = std::min(options_.cloud.crop_top_rows, grey.rows);
  const int top = std::max(0, first - kFastBorder);
  std::vector<cv::Point> pixels;
  if (top >= grey.rows) return pixels;
  std::vector<cv::KeyPoint> corners;
  cv::FAST(grey.rowRange(top, grey.rows), corners, std::max(1, fast_threshold_ - kFastMargin),
           false);
  pixels.reserve(corners.size());
  for (const cv::KeyPoint& corner : corners) {
    const cv::Point p(static_cast<int>(corner.pt.x), static_cast<int>(corner.pt.y) + top);
    if (p.y >= first) pixels.push_back(p);
  }
  if (options_.cloud.selector.kind != SelectorKind::kFast) {
    const double area = static_cast<double>(grey.cols) * (grey.rows - first);
    const int stride = std::max(
        1, static_cast<int>(std::sqrt(area / (kGridShare * options_.cloud.selector.max_points))));
    for (int v = first + stride / 2; v < grey.rows; v += stride)
      for (int u = stride / 2; u < grey.cols; u += stride)
        pixels.emplace_back(u, v);
  }
  return pixels;
}

void StereoCloudBuilder::completeDepth(const PointStereoMatcher& matcher, double focal_baseline,
                                       double offset, const std::vector<cv::Point>& pixels,
                                       cv::Mat& depth) const {
  std::vector<cv::Point> missing;
  missing.reserve(pixels.size());
  for (const cv::Point& p : pixels) {
    if (p.x < 0 || p.y < 0 || p.x >= depth.cols || p.y >= depth.rows) continue;
    if (std::isnan(depth.at<float>(p))) missing.push_back(p);
  }
  std::sort(missing.begin(), missing.end(), [](const cv::Point& a, const cv::Point& b) {
    return a.y != b.y ? a.y < b.y : a.x < b.x;
  });
  missing.erase(std::unique(missing.begin(), missing.end()), missing.end());
  const std::vector<float> disparities = matcher.match(missing);
  // disparityToMetres' rules, pixel by pixel: positive disparities, the offset added, depths
  // from min_depth on.
  const auto [near, far] =
      floatDepthRange(options_.cloud.min_depth, std::numeric_limits<double>::infinity());
  const auto fb = static_cast<float>(focal_baseline);
  const auto shift = static_cast<float>(offset);
  for (std::size_t k = 0; k < missing.size(); ++k) {
    const float d = disparities[k];
    const float z = d > 0.0f && std::isfinite(d) && d + shift > 0.0f ? fb / (d + shift) : NAN;
    if (z >= near && z <= far) depth.at<float>(missing[k]) = z;
  }
}

cv::Mat StereoCloudBuilder::pointDepth(const StereoFrame& frame,
                                       PointStereoMatcher& matcher) const {
  checkStereoPair(frame.left, frame.right);
  options_.matcher.checkImageSize(frame.left.cols, frame.left.rows);
  const cv::Mat grey = toGrey(frame.left);
  const int first =
      std::max(0, std::min(options_.cloud.crop_top_rows, grey.rows - 1) - kMatchingContextRows);
  std::vector<cv::Point> pixels;
  matcher.prepare(grey, toGrey(frame.right), first, [&] { pixels = pointPixels(grey); });
  cv::Mat depth = depthBuffer(grey.size());
  completeDepth(matcher, frame.intrinsics.fx * frame.baseline, options_.disparity_offset, pixels,
                depth);
  return depth;
}

cv::Mat StereoCloudBuilder::depthBuffer(cv::Size size) const {
  // One nobody else holds (a Mat's reference count counts its copies), else a new one: a new
  // image costs its pages' first touch every frame (KITTI: about 1 ms, as much as the fill).
  cv::Mat* free = nullptr;
  for (cv::Mat& buffer : depth_buffers_) {
    if (buffer.u && buffer.u->refcount == 1 && buffer.size() == size) free = &buffer;
  }
  if (!free) {
    if (depth_buffers_.size() >= kDepthBuffers) depth_buffers_.erase(depth_buffers_.begin());
    depth_buffers_.emplace_back(size, CV_32FC1);
    free = &depth_buffers_.back();
  }
  free->setTo(std::numeric_limits<float>::quiet_NaN());
  return *free;
}

cv::Mat StereoCloudBuilder::depth(const StereoFrame& frame) const {
  checkFrame(frame);
  if (frame.disparity.empty() && options_.matcher.pointLevel() >= 0) {
    PointStereoMatcher matcher(point_options_);
    return pointDepth(frame, matcher);
  }
  cv::Mat disparity;
  double scale = options_.disparity_scale;
  if (!frame.disparity.empty()) {
    if (frame.disparity.size() != frame.left.size()) {
      throw std::invalid_argument("disparity image size differs from the left image's");
    }
    disparity = frame.disparity;
  } else {
    if (frame.right.empty()) {
      throw std::invalid_argument("stereo frame has neither a right image nor a disparity image");
    }
    // Rows above crop_top_rows are never used (no point, no corner): only the rest is matched,
    // with kMatchingContextRows above it for SGBM's top-down paths to settle. KITTI 06: the
    // matching 22 % faster (49-51 -> 38-40 ms in the same minutes), per frame 14.13 / 31.56 /
    // 51.49 -> 13.91 / 31.28 / 51.67 mm at strides 1 / 2 / 3 (README "A whole frame").
    const int first = std::max(0, options_.cloud.crop_top_rows - kMatchingContextRows);
    // (Pairs of different sizes go to the matcher whole, which refuses them by name.)
    if (first > 0 && first < frame.left.rows && frame.left.size() == frame.right.size()) {
      disparity =
          cv::Mat(frame.left.size(), CV_32FC1, cv::Scalar(std::numeric_limits<float>::quiet_NaN()));
      const cv::Range band(first, frame.left.rows);
      matcher_.disparity(frame.left.rowRange(band), frame.right.rowRange(band))
          .copyTo(disparity.rowRange(band));
    } else {
      disparity = matcher_.disparity(frame.left, frame.right);
    }
    scale = 1.0;  // the matcher returns pixels
  }
  return disparityToMetres(disparity, frame.intrinsics.fx * frame.baseline, scale,
                           options_.cloud.min_depth, std::numeric_limits<double>::infinity(),
                           options_.disparity_offset);
}

void StereoCloudBuilder::completeTrackDepth(const MotionPrior& prior, const PinholeIntrinsics& K) {
  if (!current_.matcher || current_.depth.empty()) return;
  std::vector<cv::Point> now, before;
  const auto around = [](double u, double v, std::vector<cv::Point>* out) {
    if (!std::isfinite(u) || !std::isfinite(v) || std::abs(u) > 1e6 || std::abs(v) > 1e6) return;
    const int x = static_cast<int>(std::lround(u)), y = static_cast<int>(std::lround(v));
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx)
        out->emplace_back(x + dx, y + dy);
  };
  // As the offset estimate reads them: the tracks' rays in the current image, their points'
  // projections in the previous one.
  for (std::size_t k = 0; k < prior.tracked_points.size(); ++k) {
    const Eigen::Vector2d& seen = prior.tracked_observations[k];
    around(seen.x() * K.fx + K.cx, seen.y() * K.fy + K.cy, &now);
    const Eigen::Vector3d& point = prior.tracked_points[k];
    if (!(point.z() > 0.0)) continue;
    around(point.x() / point.z() * K.fx + K.cx, point.y() / point.z() * K.fy + K.cy, &before);
  }
  for (PointFrame* kept : {&current_, &previous_}) {
    if (!kept->matcher || kept->depth.empty() || !kept->matcher->prepared() ||
        kept->depth.size() != kept->matcher->size()) {
      continue;
    }
    completeDepth(*kept->matcher, kept->focal_baseline, kept->offset,
                  kept == &current_ ? now : before, kept->depth);
  }
}

void StereoCloudBuilder::setDisparityOffset(double offset) {
  if (!std::isfinite(offset)) throw std::invalid_argument("disparity offset must be finite");
  options_.disparity_offset = offset;
}

LabeledCloud StereoCloudBuilder::build(const StereoFrame& frame, FrontendStats* stats,
                                       FrameImages* images) {
  const auto start = std::chrono::steady_clock::now();
  if (frame.left.empty()) throw std::invalid_argument("left image is empty");
  cv::Mat metres;
  if (current_.matcher && frame.disparity.empty()) {
    checkFrame(frame);
    std::swap(current_, previous_);
    current_.depth.release();
    metres = pointDepth(frame, *current_.matcher);
    current_.depth = metres;
    current_.focal_baseline = frame.intrinsics.fx * frame.baseline;
    current_.offset = options_.disparity_offset;
  } else {
    metres = depth(frame);
    current_.depth.release();
    previous_.depth.release();
  }
  FrontendStats local;
  local.matching_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  LabeledCloud cloud =
      cloud_builder_.build(frame.left, metres, frame.intrinsics, frame.semantics, &local, images);
  if (local.selection.fast_threshold > 0) fast_threshold_ = local.selection.fast_threshold;
  if (stats) *stats = local;
  if (stats) {
    stats->time_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  }
  return cloud;
}

}  // namespace cvo
