// The feature-track motion prior, independent of CVO: Shi-Tomasi corners of the previous frame,
// lifted to 3-D with its depth, tracked into the current image by pyramidal KLT (kept only when
// the backward track returns within max_flow_error), and previous <- current solved by PnP with
// RANSAC, refined by Levenberg-Marquardt on the inliers. Fresh corners every frame: chained
// tracks would drift along edges. The odometry starts CVO from it when it is confident and
// judges CVO's result by its inlier tracks (keyframe_odometry.hpp).
#pragma once

#include <functional>
#include <future>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "cvo_odometry/core/motion_prior.hpp"
#include "cvo_odometry/frontend/min_eigen_corners.hpp"
#include "cvo_odometry/frontend/pinhole_intrinsics.hpp"

namespace cvo {

struct FeatureTrackerOptions {
  bool enabled = true;
  int max_corners = 500;
  double min_distance = 12.0;   // px between corners
  int window = 11;              // KLT window (px)
  int levels = 4;               // pyramid levels above the image
  double max_flow_error = 1.0;  // px, forward-backward
  double ransac_px = 1.5;       // PnP inlier threshold (px)

  void validate() const;
};

class FeatureTracker {
 public:
  explicit FeatureTracker(const FeatureTrackerOptions& options);
  ~FeatureTracker();  // waits for corners still being found
  FeatureTracker(const FeatureTracker&) = delete;
  FeatureTracker& operator=(const FeatureTracker&) = delete;

  // The previous frame's corners tracked into `grey` (8-bit) and previous <- current solved from
  // them (`solved` false with the reason when it cannot be); then this frame's own corners are
  // found, from its metric depth (CV_32FC1, NaN invalid) below `crop_top_rows`, for the next
  // frame: on a thread of their own, since only the next frame needs them (the caller's frame
  // goes on meanwhile; the next call waits for them, so the result does not depend on timing).
  // The first frame after construction or reset() only seeds.
  MotionPrior track(const cv::Mat& grey, const cv::Mat& depth, const PinholeIntrinsics& intrinsics,
                    int crop_top_rows = 0);
  // The last frame's depths are built differently from now on (a new stereo disparity offset):
  // its corners move along their rays to depth new_depth(z) (waits for them); those given no
  // positive finite depth are dropped.
  void remapDepths(const std::function<float(float)>& new_depth);
  // The last frame left corners to track (waits for them).
  bool seeded();
  // A frame was tracked since construction or reset(): the next prior relates two frames, solved
  // or with the reason why not (no corners, a failed corner search).
  bool hasPreviousFrame() const { return has_previous_; }
  void reset();

 private:
  // The KLT pyramid of `grey`, built in the buffers of `reuse` where their sizes fit.
  std::vector<cv::Mat> pyramid(const cv::Mat& grey, std::vector<cv::Mat> reuse) const;
  // Finds this frame's corners in seed_grey_ and seed_depth_ (written again only after
  // finishSeeding()), after forgetCorners().
  void seed(const cv::Mat& grey, const cv::Mat& depth, const PinholeIntrinsics& intrinsics,
            int crop_top_rows, std::vector<cv::Mat> pyramid);
  // Waits for the corners being found, if any; a failure there leaves none, and says why.
  void finishSeeding();
  // Drops the corners and the pyramid they were found in: nothing to track from.
  void forgetCorners();
  // track() after the wait: the prior, then this frame's corners started on their thread.
  MotionPrior trackAndSeed(const cv::Mat& grey, const cv::Mat& depth,
                           const PinholeIntrinsics& intrinsics, int crop_top_rows);
  MotionPrior solve(const std::vector<cv::Mat>& current, const cv::Size& size,
                    const PinholeIntrinsics& intrinsics) const;

  FeatureTrackerOptions options_;
  MinEigenCorners corners_;            // used by seed() only
  std::vector<cv::Point3f> points_;    // the previous frame's camera frame
  std::vector<cv::Point2f> pixels_;    // where the previous image sees them
  std::vector<cv::Mat> last_pyramid_;  // of the previous image
  // The one before, done with: the next frame's pyramid is built in its buffers (~2 MB a frame
  // at 640x480, otherwise allocated and first touched anew).
  std::vector<cv::Mat> spare_pyramid_;
  std::future<void> seeding_;       // the previous frame's corners, being found
  cv::Mat seed_grey_, seed_depth_;  // that frame's images, read by the search only
  double seed_ms_ = 0.0;            // how long they took
  std::string seed_problem_;        // why finding them failed
  bool has_previous_ = false;
};

}  // namespace cvo
