// The stereo front end's side of the disparity offset's self-calibration (the estimator is
// core/disparity_offset_estimator.hpp): which offset a frame's depth is built with, the feature
// prior's tracks turned into raw disparities at both ends, and when a new estimate is used.
//
// Bookkeeping it owns, frame by frame:
//   - the offset in use starts at the setting `disparity_offset` and moves to the estimate once
//     it is trusted, then only by steps of at least kOffsetStep; each step changes the depths
//     the front end builds, and the caller moves what it keeps of earlier frames to the new
//     offset (depthAtNewOffset) so that the next frame meets a reference built as it is;
//   - the previous frame's depth and offset, which the next frame's tracks start from: recorded
//     as soon as the tracker has taken a frame, whatever the registration then says of it;
//   - a change of camera (image size, focal length, baseline) starts the estimate anew: one
//     rig's offset in pixels says nothing of another's.
#pragma once

#include <functional>
#include <optional>

#include <opencv2/core.hpp>

#include "cvo_odometry/core/disparity_offset_estimator.hpp"
#include "cvo_odometry/core/motion_prior.hpp"
#include "cvo_odometry/frontend/stereo_cloud_builder.hpp"

namespace cvo {

// A depth built at disparity offset `from` (px) as offset `to` builds it, on a rig with
// f b = `focal_baseline` (z = f b / (d + offset), the same raw disparity d); NaN where no positive
// disparity is left or the new depth is outside [min_depth, max_depth], where the front end builds
// none.
std::function<float(float)> depthAtNewOffset(double from, double to, double focal_baseline,
                                             double min_depth, double max_depth);

class DisparityOffsetCalibration {
 public:
  // Smallest change of the offset in use (px): at 20 m (KITTI: 19 px of disparity) 0.05 px
  // moves a point 5 cm; smaller changes wait, so that what is kept of earlier frames is not
  // moved to a new offset every frame.
  static constexpr double kOffsetStep = 0.05;

  // `start`: the setting disparity_offset; `enabled`: estimate_disparity_offset.
  DisparityOffsetCalibration(double start, bool enabled, const DisparityOffsetOptions& options);

  // The offset to build this frame's depth with (a new camera restarts the estimate first).
  double offsetFor(const StereoFrame& frame);
  // The tracker has taken this frame (its depth, built with offsetFor's offset; empty without):
  // the next frame's tracks start here.
  void frameTracked(const cv::Mat& depth);
  // After the frame's registration: its prior's tracks join the estimate when the frame is
  // trusted. Returns true when the offset in use changed (from the next frame on).
  bool update(const StereoFrame& frame, const cv::Mat& depth,
              const std::optional<MotionPrior>& prior, bool trusted);
  // f b of the camera the estimate belongs to, once a frame has been seen.
  std::optional<double> focalBaseline() const;

  double offset() const { return offset_; }
  std::optional<DisparityOffsetEstimate> estimate() const { return estimator_.estimate(); }

 private:
  struct Camera {
    int width = 0, height = 0;
    double fx = 0.0, baseline = 0.0;
    bool operator==(const Camera& other) const {
      return width == other.width && height == other.height && fx == other.fx &&
             baseline == other.baseline;
    }
  };

  double start_;
  bool enabled_;
  DisparityOffsetEstimator estimator_;
  double offset_;                 // in use: this frame's depth
  std::optional<Camera> camera_;  // the estimate's
  cv::Mat previous_depth_;        // the last tracked frame's
  double previous_offset_ = 0.0;  // and the offset it was built with
  cv::Mat current_depth_;         // this frame's, once tracked
  double current_offset_ = 0.0;
};

}  // namespace cvo
