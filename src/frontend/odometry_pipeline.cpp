#include "cvo_odometry/frontend/odometry_pipeline.hpp"

#include <chrono>
#include <cmath>
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

// The disparity (f b / depth) at pixel (u, v) when its 3x3 neighbourhood is one surface, its
// disparities within kMaxDisparitySpread of each other; NaN otherwise. A corner on an occluding
// edge has the background's disparity on one side and the foreground's on the other: the matcher
// may give either, and the track follows a mixture of the two as they move apart.
constexpr double kMaxDisparitySpread = 1.0;  // px
double smoothDisparity(const cv::Mat& depth, double x, double y, double focal_baseline) {
  const int u = static_cast<int>(std::lround(x)), v = static_cast<int>(std::lround(y));
  if (u < 1 || v < 1 || u + 1 >= depth.cols || v + 1 >= depth.rows) return NAN;
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

OdometryPipeline::OdometryPipeline(const OdometrySettings& settings, BackendFactory factory)
    : settings_(settings), factory_(std::move(factory)) {
  settings_.validate();
  odometry_ = makeOdometry(settings_);
  rgbd_builder_ = std::make_unique<RgbdCloudBuilder>(settings_.rgbdOptions());
  stereo_builder_ = std::make_unique<StereoCloudBuilder>(settings_.stereoOptions());
  tracker_ = std::make_unique<FeatureTracker>(settings_.features);
  frame_offset_ = previous_offset_ = settings_.disparity_offset;
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

bool OdometryPipeline::setSettings(const OdometrySettings& settings) {
  settings.validate();
  // Build everything new first: a refusal leaves the pipeline as it was.
  auto rgbd = std::make_unique<RgbdCloudBuilder>(settings.rgbdOptions());
  auto stereo = std::make_unique<StereoCloudBuilder>(settings.stereoOptions());
  auto tracker = std::make_unique<FeatureTracker>(settings.features);
  const bool new_backend = settings.cvo.backend != settings_.cvo.backend ||
                           settings.cvo.num_threads != settings_.cvo.num_threads;
  // The offset's estimate belongs to the rig: it survives other changes, not a new start value.
  const bool new_offset = settings.disparity_offset != settings_.disparity_offset ||
                          settings.estimate_disparity_offset != settings_.estimate_disparity_offset;
  if (!new_offset) stereo->setDisparityOffset(frame_offset_);
  std::unique_ptr<KeyframeOdometry> odometry;
  if (new_backend) odometry = makeOdometry(settings);
  settings_ = settings;
  rgbd_builder_ = std::move(rgbd);
  stereo_builder_ = std::move(stereo);
  tracker_ = std::move(tracker);  // the next frame only takes its corners
  if (new_offset) {
    offset_estimator_.reset();
    frame_offset_ = previous_offset_ = settings.disparity_offset;
  }
  if (new_backend) {
    odometry_ = std::move(odometry);
    reset(start_pose_);
  } else {
    odometry_->setParams(settings.cvo);
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

std::shared_ptr<const LabeledCloud> OdometryPipeline::buildCloud(const CameraFrame& frame,
                                                                 FrontendStats* stats,
                                                                 FrameImages* images) {
  if (const auto* rgbd = std::get_if<RgbdFrame>(&frame)) {
    return std::make_shared<const LabeledCloud>(rgbd_builder_->build(*rgbd, stats, images));
  }
  return std::make_shared<const LabeledCloud>(
      stereo_builder_->build(std::get<StereoFrame>(frame), stats, images));
}

void OdometryPipeline::calibrateDisparityOffset(const StereoFrame& frame, const FrameImages& images,
                                                PipelineResult& result) {
  const double previous_offset = previous_offset_;
  previous_offset_ = frame_offset_;
  if (!settings_.estimate_disparity_offset) return;
  const std::optional<MotionPrior>& prior = result.prior;
  const cv::Mat& depth = images.depth;
  if (prior && prior->solved && result.update.trusted() && !result.update.firstFrame() &&
      depth.type() == CV_32FC1 && previous_depth_.size() == depth.size() &&
      previous_depth_.type() == CV_32FC1) {
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
          {before, seen, before_disparity - previous_offset, after_disparity - frame_offset_});
    }
    offset_estimator_.addPair(tracks, prior->motion.inverse(), K.fx, focal_baseline, frame_offset_);
  }
  previous_depth_ = depth;
  result.disparity_offset_estimate = offset_estimator_.estimate();
  if (result.disparity_offset_estimate && result.disparity_offset_estimate->trusted) {
    frame_offset_ = result.disparity_offset_estimate->offset;
    stereo_builder_->setDisparityOffset(frame_offset_);
  }
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
  PipelineResult result;
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
    input.cloud = buildCloud(frame, &result.stats, &images);
  } catch (const EmptyFrameError& e) {
    input.why_no_cloud = e.what();  // well-formed, nothing to track: a lost frame
  } catch (const std::invalid_argument& e) {
    result.outcome = FrameOutcome::kSkipped;  // malformed: not a frame at all
    result.why = e.what();
    return result;
  }
  stale_.accept();
  if (!settings_.features.enabled || images.grey.empty()) {
    tracker_->reset();  // the prior relates this frame and the next only: none without images
  } else {
    // From the second frame on, the prior (solved, or why not) relates this frame to the last.
    const bool tracked = tracker_->hasPreviousFrame();
    MotionPrior prior =
        tracker_->track(images.grey, images.depth, intrinsics, settings_.cloud.crop_top_rows);
    if (tracked) input.prior = result.prior = std::move(prior);
  }
  result.cloud = input.cloud;
  result.reference = odometry_->referenceCloud();
  try {
    result.update = odometry_->process(std::move(input));
  } catch (const std::invalid_argument& e) {
    result.outcome = FrameOutcome::kSkipped;
    result.why = std::string("registration rejected the frame: ") + e.what();
    return result;
  }
  advancePriorPose(result);
  if (const auto* stereo = std::get_if<StereoFrame>(&frame)) {
    result.disparity_offset = frame_offset_;
    const auto calibration_start = std::chrono::steady_clock::now();
    calibrateDisparityOffset(*stereo, images, result);
    result.disparity_offset_ms = millisecondsSince(calibration_start);
  }
  result.total_ms = millisecondsSince(start);
  return result;
}

}  // namespace cvo
