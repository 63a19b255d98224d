#include "cvo_odometry/ros/odometry_diagnostics.hpp"

#include <cmath>
#include <cstdio>

namespace cvo {

const char* skipReasonName(SkipReason reason) {
  switch (reason) {
    case SkipReason::kNoCameraInfo:
      return "no camera_info yet";
    case SkipReason::kUnreadable:
      return "unreadable message";
    case SkipReason::kRefused:
      return "refused by the odometry";
    case SkipReason::kRepeatedStamp:
      return "repeated stamp";
    case SkipReason::kInternalError:
      return "internal error";
  }
  return "unknown";
}

OdometryDiagnostics::OdometryDiagnostics(ros::NodeHandle nh, ros::NodeHandle pnh, SyncState sync)
    : sync_(std::move(sync)), updater_(nh, pnh, pnh.getNamespace()) {
  updater_.setHardwareID("cvo_odometry");
  updater_.add("odometry", this, &OdometryDiagnostics::diagnose);
  updater_.add("odom topic status", this, &OdometryDiagnostics::diagnoseRate);
  // Every second of the node's clock. force_update: update() waits for a time it computed
  // before the clock went backwards (a looping bag) and would publish nothing until then.
  timer_ = nh.createTimer(ros::Duration(1.0),
                          [this](const ros::TimerEvent&) { updater_.force_update(); });
}

void OdometryDiagnostics::odometryPublished() {
  const double now = ros::Time::now().toSec();
  std::lock_guard<std::mutex> lock(mutex_);
  rate_.tick(now);
}

void OdometryDiagnostics::count(const PipelineResult& result, double latency_ms) {
  std::lock_guard<std::mutex> lock(mutex_);
  latency_ms_ = latency_ms;
  if (std::isfinite(latency_ms)) max_latency_ms_ = std::max(max_latency_ms_, latency_ms);
  if (result.outcome == FrameOutcome::kSkipped) {
    skipped(SkipReason::kRefused, result.why);  // the caller tells a repeated stamp apart
    return;
  }
  if (result.outcome == FrameOutcome::kStale) {
    ++stale_;
    last_problem_ = "stale: " + result.why;
    return;
  }
  ++frames_;
  threads_ = result.threads;
  if (result.threads == 1) ++one_thread_frames_;
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

void OdometryDiagnostics::countSkipped(SkipReason reason, const std::string& why) {
  std::lock_guard<std::mutex> lock(mutex_);
  skipped(reason, why);
}

void OdometryDiagnostics::skipped(SkipReason reason, const std::string& why) {
  ++skipped_;
  ++skipped_by_reason_.at(static_cast<std::size_t>(reason));
  latest_skip_ = std::string(skipReasonName(reason)) + ": " + why;
  last_problem_ = "skipped (" + latest_skip_ + ")";
}

void OdometryDiagnostics::setBackend(const std::string& backend) {
  std::lock_guard<std::mutex> lock(mutex_);
  backend_ = backend;
}

void OdometryDiagnostics::diagnoseRate(diagnostic_updater::DiagnosticStatusWrapper& status) {
  const double now = ros::Time::now().toSec();
  std::lock_guard<std::mutex> lock(mutex_);
  const EventRate::Judgement judgement = rate_.judge(now);
  status.summary(judgement.warn ? diagnostic_msgs::DiagnosticStatus::WARN
                                : diagnostic_msgs::DiagnosticStatus::OK,
                 judgement.message);
  // The keys of diagnostic_updater's frequency status, which monitors may read.
  status.add("Events in window", judgement.events);
  status.add("Events since startup", rate_.total());
  status.add("Duration of window (s)", judgement.span);
  if (judgement.measured) status.add("Actual frequency (Hz)", judgement.rate);
  status.add("Minimum acceptable frequency (Hz)",
             rate_.options().min_rate * (1.0 - rate_.options().tolerance));
  status.add("Maximum acceptable frequency (Hz)",
             rate_.options().max_rate * (1.0 + rate_.options().tolerance));
}

void OdometryDiagnostics::diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) {
  std::lock_guard<std::mutex> lock(mutex_);
  const bool far_from_clock = clock_offset_ && std::abs(*clock_offset_) > kFarFromClock;
  char text[200];
  if (frames_ == 0) {
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN, "no frame processed yet");
  } else if (lost_now_) {
    status.summary(diagnostic_msgs::DiagnosticStatus::ERROR, "tracking lost: " + lost_problem_);
  } else if (far_from_clock) {
    std::snprintf(text, sizeof text,
                  "frame stamps are %.3g s %s this node's clock (use_sim_time and rosbag play "
                  "--clock?): latency unknown",
                  std::abs(*clock_offset_), *clock_offset_ > 0.0 ? "behind" : "ahead of");
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN, text);
  } else if (!last_problem_.empty()) {
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN, last_problem_);
  } else {
    status.summary(diagnostic_msgs::DiagnosticStatus::OK, "tracking");
  }
  const std::size_t dropped = sync_.dropped ? sync_.dropped() : 0;
  status.add("frames", frames_);
  status.add("skipped frames", skipped_);
  for (std::size_t k = 0; k < kSkipReasons; ++k) {
    status.add(std::string("skipped: ") + skipReasonName(static_cast<SkipReason>(k)),
               skipped_by_reason_[k]);
  }
  status.add("latest skip reason", latest_skip_.empty() ? std::string("none") : latest_skip_);
  status.add("stale frames", stale_);
  status.add("frames dropped for latency", dropped);
  status.add("frames dropped while paused", paused_);
  const std::size_t handled = frames_ + skipped_ + stale_ + dropped + paused_;
  const std::size_t arrived = sync_.arrived ? sync_.arrived() : handled;
  status.add("frames not synchronized", arrived > handled ? arrived - handled : 0);
  if (const auto offset = sync_.offset ? sync_.offset() : std::nullopt) {
    status.add("depth - colour stamp offset (ms)", *offset * 1000.0);
  }
  if (std::isfinite(latency_ms_)) {
    status.add("latency (ms, stamp to publish)", latency_ms_);
  } else {
    status.add("latency (ms, stamp to publish)",
               std::string("unknown: the stamps are far from this node's clock"));
  }
  status.add("largest latency (ms)", max_latency_ms_);
  if (clock_offset_) {
    std::snprintf(text, sizeof text, "%.3f", *clock_offset_);
    status.add("clock - stamp at arrival (s)", std::string(text));
  } else {
    status.add("clock - stamp at arrival (s)", std::string("none yet"));
  }
  status.add("TF withheld (frames from before the clock went back)", tf_withheld_);
  status.add("lost frames", lost_);
  status.add("recovered frames", recovered_);
  status.add("tracking restarts", restarts_);
  status.add("backend fallbacks", fallbacks_);
  status.add("resets", resets_);
  status.add("backend", backend_);
  status.add("CPU threads (adaptive_threads: one while the frames get about a core)", threads_);
  status.add("frames on one thread", one_thread_frames_);
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
