#include "cvo_odometry/ros/odometry_diagnostics.hpp"

#include <cstdio>

namespace cvo {

OdometryDiagnostics::OdometryDiagnostics(ros::NodeHandle nh, ros::NodeHandle pnh, SyncState sync)
    : sync_(std::move(sync)), updater_(nh, pnh, pnh.getNamespace()) {
  updater_.setHardwareID("cvo_odometry");
  updater_.add("odometry", this, &OdometryDiagnostics::diagnose);
  rate_ = std::make_unique<diagnostic_updater::HeaderlessTopicDiagnostic>(
      "odom", updater_, diagnostic_updater::FrequencyStatusParam(&min_rate_, &max_rate_));
  timer_ =
      nh.createTimer(ros::Duration(1.0), [this](const ros::TimerEvent&) { updater_.update(); });
}

void OdometryDiagnostics::count(const PipelineResult& result, double latency_ms) {
  std::lock_guard<std::mutex> lock(mutex_);
  latency_ms_ = latency_ms;
  max_latency_ms_ = std::max(max_latency_ms_, latency_ms);
  if (result.outcome == FrameOutcome::kSkipped) {
    ++skipped_;
    last_problem_ = "skipped: " + result.why;
    return;
  }
  if (result.outcome == FrameOutcome::kStale) {
    ++stale_;
    last_problem_ = "stale: " + result.why;
    return;
  }
  ++frames_;
  if (result.disparity_offset_estimate) disparity_offset_ = result.disparity_offset_estimate;
  const OdometryUpdate& update = result.update;
  switch (update.state) {
    case TrackingState::kRecovered:
      ++recovered_;
      break;
    case TrackingState::kLost:
      ++lost_;
      break;
    case TrackingState::kReset:
      ++lost_;
      ++restarts_;
      break;
    default:
      break;
  }
  lost_now_ = update.state == TrackingState::kLost || update.state == TrackingState::kReset;
  if (lost_now_) lost_problem_ = update.problem;
  if (!update.problem.empty()) last_problem_ = toString(update.state) + ": " + update.problem;
  if (!update.report.warning.empty()) ++fallbacks_;
}

void OdometryDiagnostics::countSkipped(const std::string& why) {
  std::lock_guard<std::mutex> lock(mutex_);
  ++skipped_;
  last_problem_ = "skipped: " + why;
}

void OdometryDiagnostics::setBackend(const std::string& backend) {
  std::lock_guard<std::mutex> lock(mutex_);
  backend_ = backend;
}

void OdometryDiagnostics::diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (frames_ == 0) {
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN, "no frame processed yet");
  } else if (lost_now_) {
    status.summary(diagnostic_msgs::DiagnosticStatus::ERROR, "tracking lost: " + lost_problem_);
  } else if (!last_problem_.empty()) {
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN, last_problem_);
  } else {
    status.summary(diagnostic_msgs::DiagnosticStatus::OK, "tracking");
  }
  const std::size_t dropped = sync_.dropped ? sync_.dropped() : 0;
  status.add("frames", frames_);
  status.add("skipped frames", skipped_);
  status.add("stale frames", stale_);
  status.add("frames dropped for latency", dropped);
  status.add("frames dropped while paused", paused_);
  const std::size_t handled = frames_ + skipped_ + stale_ + dropped + paused_;
  const std::size_t arrived = sync_.arrived ? sync_.arrived() : handled;
  status.add("frames not synchronized", arrived > handled ? arrived - handled : 0);
  if (const auto offset = sync_.offset ? sync_.offset() : std::nullopt) {
    status.add("depth - colour stamp offset (ms)", *offset * 1000.0);
  }
  status.add("latency (ms, stamp to publish)", latency_ms_);
  status.add("largest latency (ms)", max_latency_ms_);
  status.add("lost frames", lost_);
  status.add("recovered frames", recovered_);
  status.add("tracking restarts", restarts_);
  status.add("backend fallbacks", fallbacks_);
  status.add("resets", resets_);
  status.add("backend", backend_);
  if (disparity_offset_) {
    // Stereo self-calibration (README "Stereo scale"): what the front end uses once trusted.
    status.add("disparity offset estimate (px)", disparity_offset_->offset);
    status.add("disparity offset standard error (px)", disparity_offset_->standard_error);
    status.add("disparity offset frame pairs", disparity_offset_->pairs);
    status.add("disparity offset in use", disparity_offset_->trusted ? "yes" : "not yet");
  }
  if (sync_.camera_info_stamp) {
    const std::optional<double> stamp = sync_.camera_info_stamp();
    char text[32] = "none yet";
    if (stamp) std::snprintf(text, sizeof text, "%.3f", *stamp);
    status.add("latest camera_info stamp", std::string(text));
  }
  last_problem_.clear();
}

}  // namespace cvo
