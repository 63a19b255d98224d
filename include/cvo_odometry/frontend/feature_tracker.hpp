// The feature-track motion prior, independent of CVO: Shi-Tomasi corners of the previous frame,
// lifted to 3-D with its depth, tracked into the current image by pyramidal KLT (kept only when
// the backward track returns within max_flow_error), and previous <- current solved by PnP with
// RANSAC, refined by Levenberg-Marquardt on the inliers. Fresh corners every frame: chained
// tracks would drift along edges. The odometry starts CVO from it when it is confident and
// judges CVO's result by its inlier tracks (keyframe_odometry.hpp).
#pragma once

#include <functional>
#include <future>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "cvo_odometry/core/motion_prior.hpp"
#include "cvo_odometry/core/pixel_region.hpp"
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
  // Corners spread over square cells, this many across the image, none holding more than its
  // share (0: the strongest anywhere): a corner-rich object moving through the view takes far
  // fewer of the tracks than it would (a third of TUM's view: 55-62 % of them, against over
  // 90 % unspread).
  int grid_columns = 8;
  // A second motion that moves the tracks at least this far (px) from the first is an object's
  // (OdometrySettings::trackerOptions: moving_min_px); only beside one is a third motion searched
  // among the tracks the first two leave out. 0: beside every second motion.
  double object_apart_px = 0.0;

  void validate() const;
};

class FeatureTracker {
 public:
  explicit FeatureTracker(const FeatureTrackerOptions& options);
  ~FeatureTracker();  // waits for corners still being found
  FeatureTracker(const FeatureTracker&) = delete;
  FeatureTracker& operator=(const FeatureTracker&) = delete;

  // The anchor frame's corners tracked into `grey` (8-bit) and anchor <- current solved from
  // them (`solved` false with the reason when it cannot be); then this frame's own corners are
  // found, from its metric depth (CV_32FC1, NaN invalid) below `crop_top_rows`, for the next
  // frame: on a thread of their own, since only the next frame needs them (the caller's frame
  // goes on meanwhile; the next call waits for them, so the result does not depend on timing).
  // The anchor is the previous frame, unless frameJudged() kept an older one. The first frame
  // after construction or reset() only seeds. `excluded` (CV_8UC1 of the image's size, or
  // empty): pixels no corner may be taken at or tracked into (FrameImages::excluded). `stamp`
  // names the frame: the prior's from_stamp is its anchor's.
  MotionPrior track(const cv::Mat& grey, const cv::Mat& depth, const PinholeIntrinsics& intrinsics,
                    int crop_top_rows = 0, const cv::Mat& excluded = cv::Mat(),
                    double stamp = std::numeric_limits<double>::quiet_NaN());
  // What the odometry made of the frame just tracked. Untrusted: the next frame is tracked from
  // the anchor still (the last trusted frame), so that its prior relates it to a frame whose
  // pose is known; a frame tracked from an untrusted one could not be judged. Trusted: its
  // corners become the anchor, those within `moving_region` (where it saw an object moving
  // through the view; may be null) as the object's, so that the next prior's first motion is
  // the scene's even where the object holds most of the corners. Without a call the frame
  // becomes the anchor, its corners all the scene's.
  void frameJudged(bool trusted, std::shared_ptr<const PixelRegion> moving_region = nullptr);
  // The kept frames' depths are built differently from now on (a new stereo disparity offset):
  // their corners move along their rays to depth new_depth(z) (waits for them); those given no
  // positive finite depth are dropped.
  void remapDepths(const std::function<float(float)>& new_depth);
  // A frame left corners to track (waits for them).
  bool seeded();
  // A frame was tracked since construction or reset(): the next prior relates two frames, solved
  // or with the reason why not (no corners, a failed corner search).
  bool hasPreviousFrame() const { return has_previous_; }
  void reset();

 private:
  // A frame's corners: what a later frame is tracked from.
  struct Corners {
    std::vector<cv::Point3f> points;                   // the frame's camera frame
    std::vector<cv::Point2f> pixels;                   // where its image sees them
    std::vector<cv::Mat> pyramid;                      // of its image
    std::shared_ptr<const PixelRegion> moving_region;  // in its image, or null
    // Where its image saw the tracks of a second motion whose depths missed the first's
    // prediction (MotionPrior::SecondMotion::apart_in_depth) when it was the current frame.
    std::vector<cv::Point2f> depth_shifted;
    double stamp = std::numeric_limits<double>::quiet_NaN();
    bool empty() const { return points.empty() || pyramid.empty(); }
  };
  // The KLT pyramid of `grey`, built in the buffers of `reuse` where their sizes fit.
  std::vector<cv::Mat> pyramid(const cv::Mat& grey, std::vector<cv::Mat> reuse) const;
  // Finds this frame's corners in seed_grey_ and seed_depth_ (written again only after
  // finishSeeding()) into candidate_.
  void seed(const cv::Mat& grey, const cv::Mat& depth, const PinholeIntrinsics& intrinsics,
            int crop_top_rows, std::vector<cv::Mat> pyramid);
  // Waits for the corners being found, if any; a failure there leaves none, and says why.
  void finishSeeding();
  // The candidate becomes the anchor, or is dropped, as frameJudged() said.
  void settleCandidate();
  // Drops `corners`, keeping its pyramid's buffers for the next frame.
  void recycle(Corners& corners);
  // track() after the wait: the prior, then this frame's corners started on their thread.
  MotionPrior trackAndSeed(const cv::Mat& grey, const cv::Mat& depth,
                           const PinholeIntrinsics& intrinsics, int crop_top_rows,
                           const cv::Mat& excluded, double stamp);
  // The prior from the anchor's corners tracked into `current` (the current frame's pyramid;
  // `depth` its depth image, CV_32FC1, or empty). `depth_shifted`: where the second motion's
  // tracks' depths missed the first's (none when they did not).
  MotionPrior solve(const std::vector<cv::Mat>& current, const cv::Mat& depth, const cv::Size& size,
                    const PinholeIntrinsics& intrinsics, const cv::Mat& excluded,
                    std::vector<cv::Point2f>* depth_shifted) const;
  // Per track of `which` (`points` seen at `from_pixels`, with KLT's `track_errors`): true where
  // KLT, started where `current_from_previous` puts it, settles there too with a patch about as
  // alike as its own track's (a repeating texture).
  std::vector<bool> slippedTracks(const std::vector<cv::Mat>& current,
                                  const std::vector<cv::Point3f>& points,
                                  const std::vector<cv::Point2f>& from_pixels,
                                  const std::vector<float>& track_errors,
                                  const std::vector<bool>& which,
                                  const Eigen::Isometry3d& current_from_previous,
                                  const std::optional<CameraModel>& camera) const;
  // prior->third from the tracks `among` (indices into `points`, seen at the normalised rays
  // `observed`): those neither `first` (current <- previous) nor the second motion puts within
  // `threshold`.
  void solveThirdMotion(const std::vector<cv::Mat>& current, const std::vector<cv::Point3f>& points,
                        const std::vector<cv::Point2f>& observed,
                        const std::vector<cv::Point2f>& from_pixels,
                        const std::vector<float>& track_errors,
                        const std::vector<std::size_t>& among, const Eigen::Isometry3d& first,
                        double threshold, MotionPrior* prior) const;

  FeatureTrackerOptions options_;
  MinEigenCorners corners_;         // used by seed() only
  Corners anchor_;                  // tracked from
  Corners candidate_;               // the last tracked frame's (found on the seeding thread)
  bool candidate_pending_ = false;  // found, not yet settled
  bool candidate_kept_ = true;      // frameJudged()'s word on it
  std::shared_ptr<const PixelRegion> candidate_region_;
  // Pyramids done with: the next frame's is built in their buffers (~2 MB a frame at 640x480,
  // otherwise allocated and first touched anew).
  std::vector<cv::Mat> spare_pyramid_;
  std::future<void> seeding_;       // the last frame's corners, being found
  cv::Mat seed_grey_, seed_depth_;  // that frame's images, read by the search only
  double seed_ms_ = 0.0;            // how long they took
  std::string seed_problem_;        // why finding them failed
  bool has_previous_ = false;
};

}  // namespace cvo
