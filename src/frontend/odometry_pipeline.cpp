#include "cvo_odometry/frontend/odometry_pipeline.hpp"

#include <chrono>
#include <cmath>
#include <ctime>
#include <functional>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "cvo_odometry/core/backend_factory.hpp"
#include "cvo_odometry/frontend/empty_frame_error.hpp"

namespace cvo {

namespace {

double millisecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

std::string stampText(double stamp) {
  std::ostringstream out;
  out.precision(6);
  out << std::fixed << stamp;
  return out.str();
}

// The prior without the tracks the current image sees inside `region`.
MotionPrior withoutTracksIn(const MotionPrior& prior, const PixelRegion& region) {
  MotionPrior out = prior;
  out.tracked_points.clear();
  out.tracked_observations.clear();
  out.tracked_pixels.clear();
  for (std::size_t k = 0; k < prior.tracked_points.size(); ++k) {
    const Eigen::Vector2f& pixel = prior.tracked_pixels[k];
    if (region.contains(pixel.x(), pixel.y())) continue;
    out.tracked_points.push_back(prior.tracked_points[k]);
    out.tracked_observations.push_back(prior.tracked_observations[k]);
    out.tracked_pixels.push_back(pixel);
  }
  return out;
}

}  // namespace

OdometryPipeline::OdometryPipeline(const OdometrySettings& settings, BackendFactory factory)
    : settings_(settings), factory_(std::move(factory)) {
  settings_.validate();
  odometry_ = makeOdometry(settings_);
  resetGovernor();
  rgbd_builder_ = std::make_unique<RgbdCloudBuilder>(settings_.rgbdOptions());
  stereo_builder_ = std::make_unique<StereoCloudBuilder>(settings_.stereoOptions());
  tracker_ = std::make_unique<FeatureTracker>(settings_.trackerOptions());
  offset_calibration_ = makeOffsetCalibration(settings_);
}

std::unique_ptr<KeyframeOdometry> OdometryPipeline::makeOdometry(const OdometrySettings& settings) {
  std::string note;
  std::unique_ptr<RegistrationBackend> backend =
      factory_ ? factory_(settings.cvo)
               : makeBackend(settings.cvo.backend, settings.cvo.num_threads, &note);
  auto odometry = std::make_unique<KeyframeOdometry>(settings.cvo, std::move(backend));
  backend_note_ = note;
  return odometry;
}

void OdometryPipeline::resetGovernor() {
  governor_.reset();
  const int threads = resolvedThreadCount(settings_.cvo.num_threads);
  if (settings_.cvo.adaptive_threads && threads > 1) governor_.emplace(threads);
  odometry_->setThreadLimit(threads);
}

bool OdometryPipeline::setSettings(const OdometrySettings& settings) {
  settings.validate();
  // Build everything new first: a refusal leaves the pipeline as it was.
  auto rgbd = std::make_unique<RgbdCloudBuilder>(settings.rgbdOptions());
  auto stereo = std::make_unique<StereoCloudBuilder>(settings.stereoOptions());
  auto tracker = std::make_unique<FeatureTracker>(settings.trackerOptions());
  const bool new_backend = settings.cvo.backend != settings_.cvo.backend ||
                           settings.cvo.num_threads != settings_.cvo.num_threads;
  const bool new_governor =
      new_backend || settings.cvo.adaptive_threads != settings_.cvo.adaptive_threads;
  // The offset's estimate belongs to the rig: it survives other changes, not new settings of
  // its own.
  const DisparityOffsetOptions& a = settings.disparity_offset_estimate;
  const DisparityOffsetOptions& b = settings_.disparity_offset_estimate;
  const bool new_offset =
      settings.disparity_offset != settings_.disparity_offset ||
      settings.estimate_disparity_offset != settings_.estimate_disparity_offset ||
      a.min_pairs != b.min_pairs || a.max_standard_error != b.max_standard_error;
  auto offset_calibration = new_offset ? makeOffsetCalibration(settings) : nullptr;
  std::unique_ptr<KeyframeOdometry> odometry;
  if (new_backend) odometry = makeOdometry(settings);
  settings_ = settings;
  rgbd_builder_ = std::move(rgbd);
  stereo_builder_ = std::move(stereo);
  tracker_ = std::move(tracker);  // the next frame only takes its corners
  if (new_backend) {
    odometry_ = std::move(odometry);
    reset(start_pose_);
  } else {
    odometry_->setParams(settings.cvo);
  }
  if (new_governor) resetGovernor();
  if (offset_calibration) {
    // Back to the new start: the reference is moved there, as for an estimate's change (after
    // a new backend's reset there is nothing to move).
    moveKeptDepths(offset_calibration_->offset(), offset_calibration->offset(),
                   offset_calibration_->focalBaseline());
    offset_calibration_ = std::move(offset_calibration);
  }
  return new_backend;
}

void OdometryPipeline::reset(const Eigen::Isometry3d& base_pose) {
  start_pose_ = base_pose;
  odometry_->reset(base_pose);
  tracker_->reset();
  prior_pose_ = prior_step_ = Eigen::Isometry3d::Identity();
  stale_.reset();
  stale_burst_ = false;
}

std::string OdometryPipeline::staleness(const CameraFrame& frame) {
  if (const auto* rgbd = std::get_if<RgbdFrame>(&frame)) {
    return stale_.check({rgbd->image, rgbd->depth}, {"colour", "depth"});
  }
  const auto& stereo = std::get<StereoFrame>(frame);
  return stale_.check({stereo.left, stereo.right, stereo.disparity},
                      {"left", "right", "disparity"});
}

std::unique_ptr<DisparityOffsetCalibration> OdometryPipeline::makeOffsetCalibration(
    const OdometrySettings& settings) {
  return std::make_unique<DisparityOffsetCalibration>(settings.disparity_offset,
                                                      settings.estimate_disparity_offset,
                                                      settings.disparity_offset_estimate);
}

void OdometryPipeline::moveKeptDepths(double from, double to,
                                      std::optional<double> focal_baseline) {
  if (from == to || !focal_baseline) return;
  const double near = settings_.cloud.min_depth;
  odometry_->remapDepths(
      depthAtNewOffset(from, to, *focal_baseline, near, settings_.cloud.max_depth));
  // The tracker's corners, like the depth image they come from, keep depths beyond max_depth.
  tracker_->remapDepths(
      depthAtNewOffset(from, to, *focal_baseline, near, std::numeric_limits<double>::infinity()));
}

std::shared_ptr<const LabeledCloud> OdometryPipeline::buildCloud(double stamp,
                                                                 const CameraFrame& frame,
                                                                 FrontendStats* stats,
                                                                 FrameImages* images) {
  if (const auto* rgbd = std::get_if<RgbdFrame>(&frame)) {
    return std::make_shared<const LabeledCloud>(rgbd_builder_->build(*rgbd, stats, images, stamp));
  }
  const auto& stereo = std::get<StereoFrame>(frame);
  // A new camera starts the offset again: the old rig's kept depths go to the start as well.
  const double before = offset_calibration_->offset();
  const std::optional<double> focal_baseline = offset_calibration_->focalBaseline();
  const double offset = offset_calibration_->offsetFor(stereo);
  moveKeptDepths(before, offset, focal_baseline);
  stereo_builder_->setDisparityOffset(offset);
  return std::make_shared<const LabeledCloud>(stereo_builder_->build(stereo, stats, images));
}

void OdometryPipeline::advancePriorPose(PipelineResult& result) {
  if (!result.update.firstFrame()) {
    // Its own motions chained; constant velocity where it found none.
    if (result.prior && result.prior->solved) prior_step_ = result.prior->motion;
    prior_pose_ = prior_pose_ * prior_step_;
  }
  result.prior_pose = prior_pose_;
}

PipelineResult OdometryPipeline::process(double stamp, const CameraFrame& frame,
                                         const Eigen::Isometry3d& base_from_camera) {
  const auto start = std::chrono::steady_clock::now();
  const std::clock_t cpu_start = std::clock();
  PipelineResult result;
  result.threads =
      governor_ ? governor_->threads() : resolvedThreadCount(settings_.cvo.num_threads);
  const std::optional<double> last = odometry_->lastStamp();
  if (last && stamp == *last) {
    result.outcome = FrameOutcome::kSkipped;
    result.why = "a second frame with stamp " + stampText(stamp);
    return result;
  }
  if (last && stamp < *last) {
    result.why = "time went backwards (" + stampText(stamp) + " after " + stampText(*last) +
                 " s): a looping bag? odometry restarted";
    reset(start_pose_);
  }
  const std::string stale = staleness(frame);
  if (!stale.empty()) {
    result.outcome = FrameOutcome::kStale;
    result.why = stale;
    result.stale_burst_start = !stale_burst_;
    stale_burst_ = true;
    return result;
  }
  stale_burst_ = false;
  OdometryFrame input;
  input.stamp = stamp;
  input.base_from_camera = base_from_camera;
  FrameImages images;
  const PinholeIntrinsics& intrinsics = std::holds_alternative<RgbdFrame>(frame)
                                            ? std::get<RgbdFrame>(frame).intrinsics
                                            : std::get<StereoFrame>(frame).intrinsics;
  try {
    input.cloud = buildCloud(stamp, frame, &result.stats, &images);
  } catch (const EmptyFrameError& e) {
    input.why_no_cloud = e.what();  // well-formed, nothing to track: a lost frame
  } catch (const std::invalid_argument& e) {
    result.outcome = FrameOutcome::kSkipped;  // malformed: not a frame at all
    result.why = e.what();
    return result;
  }
  stale_.accept();
  input.moving_classes_left_out = !images.excluded.empty();
  // A frame with nothing usable (everything masked, say a person right in front of the lens)
  // leaves the anchor as it is: the next frame is tracked from the last trusted one, whose pose
  // is known. Anchored on the empty frame, the tracks would relate the next ones to a pose
  // nobody knows: they could neither guess nor judge until a frame was trusted without them.
  const bool tracks_this_frame =
      settings_.features.enabled && !images.grey.empty() && input.cloud != nullptr;
  if (!settings_.features.enabled || (images.grey.empty() && input.cloud != nullptr)) {
    tracker_->reset();  // the prior relates this frame and the next only: none without images
  } else if (tracks_this_frame) {
    // From the second frame on, the prior (solved, or why not) relates this frame to the last.
    const bool tracked = tracker_->hasPreviousFrame();
    MotionPrior prior = tracker_->track(images.grey, images.depth, intrinsics,
                                        settings_.cloud.crop_top_rows, images.excluded, stamp);
    if (tracked) input.prior = result.prior = std::move(prior);
  }
  const auto* stereo = std::get_if<StereoFrame>(&frame);
  if (stereo) offset_calibration_->frameTracked(images.depth);
  result.cloud = input.cloud;
  result.reference = odometry_->referenceCloud();
  try {
    result.update = odometry_->process(std::move(input));
  } catch (const std::invalid_argument& e) {
    result.outcome = FrameOutcome::kSkipped;
    result.why = std::string("registration rejected the frame: ") + e.what();
    return result;
  }
  // The next frame is tracked from the last trusted one, telling apart the corners of an object
  // the odometry found moving in it.
  if (tracks_this_frame && tracker_->hasPreviousFrame()) {
    tracker_->frameJudged(result.update.trusted() || result.update.restart_tracks,
                          result.update.moving_region);
  }
  advancePriorPose(result);
  if (stereo) {
    result.disparity_offset = offset_calibration_->offset();
    const auto calibration_start = std::chrono::steady_clock::now();
    // Its depths pair with the previous frame's: only tracks from that frame, and none on an
    // object the odometry found moving (its tracks follow the object, not the rig's scale).
    const bool from_previous = result.prior && (std::isnan(result.prior->from_stamp) ||
                                                (last && result.prior->from_stamp == *last));
    std::optional<MotionPrior> scene_tracks = result.prior;
    if (scene_tracks && result.update.moving_region) {
      scene_tracks = withoutTracksIn(*scene_tracks, *result.update.moving_region);
    }
    // Depth matched at points only: the tracks' pixels get theirs (nothing to do when dense).
    if (scene_tracks && settings_.estimate_disparity_offset) {
      stereo_builder_->completeTrackDepth(*scene_tracks, stereo->intrinsics);
    }
    if (offset_calibration_->update(
            *stereo, images.depth, scene_tracks,
            result.update.trusted() && !result.update.firstFrame() && from_previous)) {
      moveKeptDepths(result.disparity_offset, offset_calibration_->offset(),
                     offset_calibration_->focalBaseline());
    }
    result.disparity_offset_estimate = offset_calibration_->estimate();
    result.disparity_offset_ms = millisecondsSince(calibration_start);
  }
  result.total_ms = millisecondsSince(start);
  if (governor_) {
    // The process's CPU time: every thread's, ours and OpenCV's (another nodelet's in the same
    // manager too, which only makes the fallback rarer).
    const double cpu_ms = 1000.0 * static_cast<double>(std::clock() - cpu_start) / CLOCKS_PER_SEC;
    const int before = governor_->threads();
    if (governor_->update(result.total_ms, cpu_ms) != before) {
      odometry_->setThreadLimit(governor_->threads());
    }
  }
  return result;
}

}  // namespace cvo
