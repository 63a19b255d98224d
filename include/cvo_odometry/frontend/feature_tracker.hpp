// The feature-track motion prior, independent of CVO: Shi-Tomasi corners of the keyframe, lifted
// to 3-D with its depth, tracked image to image by pyramidal KLT (kept only when the backward
// track returns within max_flow_error), and the keyframe <- current motion solved by PnP with
// RANSAC, refined by Levenberg-Marquardt on the inliers. The odometry starts CVO from it when it
// is confident and judges CVO's result by its inlier tracks (keyframe_odometry.hpp).
#pragma once

#include <vector>

#include <opencv2/core.hpp>

#include "cvo_odometry/core/motion_prior.hpp"
#include "cvo_odometry/frontend/pinhole_intrinsics.hpp"

namespace cvo {

struct FeatureTrackerOptions {
  bool enabled = true;
  int max_corners = 500;
  double min_distance = 12.0;   // px between corners
  int window = 21;              // KLT window (px)
  int levels = 4;               // pyramid levels above the image
  double max_flow_error = 1.0;  // px, forward-backward
  double ransac_px = 1.5;       // PnP inlier threshold (px)
  // Ask for a new keyframe when fewer than this fraction of its corners are still tracked.
  double reseed_fraction = 0.4;

  void validate() const;
};

class FeatureTracker {
 public:
  explicit FeatureTracker(const FeatureTrackerOptions& options);

  // The keyframe's corners from its 8-bit grey image and metric depth (CV_32FC1, NaN invalid),
  // below `crop_top_rows`. Reuses the image pyramid when `grey` is the image last tracked.
  void seed(const cv::Mat& grey, const cv::Mat& depth, const PinholeIntrinsics& intrinsics,
            int crop_top_rows = 0);
  // The keyframe's corners tracked into `grey` (from the image they were last tracked into)
  // and keyframe <- current solved from them; `solved` false with the reason when it cannot be.
  MotionPrior track(const cv::Mat& grey, const PinholeIntrinsics& intrinsics);
  bool seeded() const { return !points_.empty(); }
  void reset();

 private:
  std::vector<cv::Mat> pyramid(const cv::Mat& grey) const;

  FeatureTrackerOptions options_;
  std::vector<cv::Point3f> points_;    // keyframe camera frame
  std::vector<cv::Point2f> pixels_;    // where the last tracked image sees them
  std::vector<cv::Mat> last_pyramid_;  // of the last image tracked into (or seeded from)
  const void* last_image_ = nullptr;   // its pixels, to know it again
  std::size_t seeded_ = 0;
};

}  // namespace cvo
