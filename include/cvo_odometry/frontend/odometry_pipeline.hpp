// The odometry pipeline without ROS, which the nodelet and the tools share (as kiss-icp's
// pipeline sits between its core and its ROS node): a camera frame in (images, intrinsics,
// stamp, base <- camera), the front end's labeled cloud, registration against the reference,
// the tracking judgement, and the pose, twist and covariance in the base frame out. Every kind
// of bad input is classified here, once, for everyone:
//   - malformed input (empty or mismatched images, an unsupported encoding, intrinsics that make
//     no sense, non-finite points): the frame is skipped, not counted as a frame;
//   - a frame with a stamp equal to the previous one: skipped; an earlier stamp (a looping bag,
//     a restarted driver): the odometry restarts from that frame, said in `why`;
//   - an image byte-identical to its stream's previous one (a driver repeating frames): stale,
//     skipped (`stale_burst_start` on the first of a run, to log once per burst);
//   - a well-formed frame with nothing to track (no valid depth, too few points): a lost frame.
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <variant>

#include <Eigen/Geometry>

#include "cvo_odometry/core/keyframe_odometry.hpp"
#include "cvo_odometry/core/thread_governor.hpp"
#include "cvo_odometry/frontend/disparity_offset_calibration.hpp"
#include "cvo_odometry/frontend/feature_tracker.hpp"
#include "cvo_odometry/frontend/odometry_settings.hpp"
#include "cvo_odometry/frontend/stale_frame_detector.hpp"

namespace cvo {

using CameraFrame = std::variant<RgbdFrame, StereoFrame>;

enum class FrameOutcome {
  kProcessed,  // the odometry took the frame (tracked, recovered, lost, first)
  kSkipped,    // malformed input or a repeated stamp: not a frame
  kStale       // an image repeats its stream's previous one
};

struct PipelineResult {
  FrameOutcome outcome = FrameOutcome::kProcessed;
  std::string why;                 // skipped or stale: why; processed: a note (time jump)
  bool stale_burst_start = false;  // the first stale frame after a fresh one
  OdometryUpdate update;           // processed frames
  FrontendStats stats;
  std::shared_ptr<const LabeledCloud> cloud;      // the frame's cloud, when it had one
  std::shared_ptr<const LabeledCloud> reference;  // what it was registered to, if anything
  std::optional<MotionPrior> prior;               // the feature prior, when it ran
  // The feature prior's own odometry (start <- current, camera): its frame-to-frame motions
  // chained, constant velocity where it found none. A peer to compare with, never published.
  std::optional<Eigen::Isometry3d> prior_pose;
  // Stereo: the disparity offset this frame's depth was built with (px), and the self-calibrated
  // estimate so far (estimate_disparity_offset; README "Stereo scale").
  double disparity_offset = 0.0;
  std::optional<DisparityOffsetEstimate> disparity_offset_estimate;
  double disparity_offset_ms = 0.0;  // the estimate's update, on the caller's thread
  double total_ms = 0.0;
  // The CPU threads the registration and the photometric stage ran with (adaptive_threads: one
  // while the process got no more than about a core).
  int threads = 1;
};

class OdometryPipeline {
 public:
  // Makes the registration backend for the CVO parameters (default: makeBackend, with the
  // fallback note in backendNote()). Throws when the backend cannot be made.
  using BackendFactory = std::function<std::unique_ptr<RegistrationBackend>(const CvoParams&)>;

  // Throws std::invalid_argument for settings that make no sense.
  explicit OdometryPipeline(const OdometrySettings& settings, BackendFactory factory = {});

  PipelineResult process(double stamp, const CameraFrame& frame,
                         const Eigen::Isometry3d& base_from_camera = Eigen::Isometry3d::Identity());
  // The next frame starts a new trajectory with the base at `base_pose`.
  void reset(const Eigen::Isometry3d& base_pose = Eigen::Isometry3d::Identity());

  // New settings from the next frame on: all or nothing, the old ones stay when the new ones
  // are refused (std::invalid_argument) or their backend cannot be made (std::runtime_error). A
  // new backend restarts the odometry (returns true then).
  bool setSettings(const OdometrySettings& settings);
  const OdometrySettings& settings() const { return settings_; }

  std::string backendName() { return odometry_->registration().backend().name(); }
  // Why `backend: auto` settled on the CPU, else empty.
  const std::string& backendNote() const { return backend_note_; }
  KeyframeOdometry& odometry() { return *odometry_; }

 private:
  std::unique_ptr<KeyframeOdometry> makeOdometry(const OdometrySettings& settings);
  // A new governor for settings_ (none with adaptive_threads off or one thread), all threads.
  void resetGovernor();
  static std::unique_ptr<DisparityOffsetCalibration> makeOffsetCalibration(
      const OdometrySettings& settings);
  // The stereo depths are built at disparity offset `to` instead of `from` from now on (a rig
  // with f b = `focal_baseline`, none known: nothing to move): what is kept of earlier frames
  // (the reference, the last good frame, the corners to track) is moved to it.
  void moveKeptDepths(double from, double to, std::optional<double> focal_baseline);
  // The frame's cloud by the front end, or why it has none (EmptyFrameError); malformed input
  // throws std::invalid_argument.
  std::shared_ptr<const LabeledCloud> buildCloud(double stamp, const CameraFrame& frame,
                                                 FrontendStats* stats, FrameImages* images);
  // The prior's own pose for this frame.
  void advancePriorPose(PipelineResult& result);
  std::string staleness(const CameraFrame& frame);

  OdometrySettings settings_;
  BackendFactory factory_;
  std::string backend_note_;
  std::unique_ptr<KeyframeOdometry> odometry_;
  std::optional<ThreadGovernor> governor_;  // adaptive_threads
  std::unique_ptr<RgbdCloudBuilder> rgbd_builder_;
  std::unique_ptr<StereoCloudBuilder> stereo_builder_;
  std::unique_ptr<FeatureTracker> tracker_;
  StaleFrameDetector stale_;
  std::unique_ptr<DisparityOffsetCalibration> offset_calibration_;  // stereo
  Eigen::Isometry3d prior_pose_ = Eigen::Isometry3d::Identity();    // of the last frame
  Eigen::Isometry3d prior_step_ = Eigen::Isometry3d::Identity();    // last frame to frame
  bool stale_burst_ = false;
  Eigen::Isometry3d start_pose_ = Eigen::Isometry3d::Identity();
};

}  // namespace cvo
