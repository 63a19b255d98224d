// The nodelet's diagnostics: the odometry rate, and a status (named after the nodelet, not its
// manager) with every count a user needs to see what happened to the frames: processed,
// skipped (and why: counts per reason and the latest reason), stale, dropped for latency or while
// paused, not synchronized, lost, recovered, restarts, backend fallbacks, resets; the latency from
// stamp to publish and how far the stamps are from the node's clock; the backend. ERROR while
// tracking is lost.
#pragma once

#include <array>
#include <functional>
#include <mutex>
#include <optional>
#include <string>

#include <diagnostic_updater/diagnostic_updater.h>

#include "cvo_odometry/frontend/odometry_pipeline.hpp"
#include "cvo_odometry/ros/event_rate.hpp"

namespace cvo {

// Why a frame was skipped (not a frame of the odometry at all).
enum class SkipReason {
  kNoCameraInfo,   // RGB-D: no rgb/camera_info received yet
  kUnreadable,     // a message the nodelet cannot read (encoding, empty image, calibration)
  kRefused,        // the odometry refused the frame's content (sizes that differ, ...)
  kRepeatedStamp,  // a second frame with the stamp of the last one
  kInternalError,  // a bug: reported, the nodelet goes on
};
constexpr std::size_t kSkipReasons = 5;
const char* skipReasonName(SkipReason reason);

class OdometryDiagnostics {
 public:
  // Where the synchronizer stands: colour (left) images arrived, the learned depth offset.
  struct SyncState {
    std::function<std::size_t()> arrived;
    std::function<std::optional<double>()> offset;
    std::function<std::size_t()> dropped;  // frames dropped to keep latency bounded
    // RGB-D: the stamp of the latest rgb/camera_info (not synchronized with the images), or
    // nothing yet: shows that one arrives, and lets a test wait until the nodelet has it.
    std::function<std::optional<double>()> camera_info_stamp;
  };

  // Frame stamps further than this from the node's clock when they arrive (s) make the latency
  // meaningless: a bag played without --clock, use_sim_time without /clock, an unsynchronized
  // camera clock.
  static constexpr double kFarFromClock = 5.0;

  OdometryDiagnostics(ros::NodeHandle nh, ros::NodeHandle pnh, SyncState sync);

  // `latency_ms`: stamp to publish, NaN when not meaningful. A skipped result counts as refused
  // by the odometry (a repeated stamp goes to countSkipped).
  void count(const PipelineResult& result, double latency_ms);
  // A frame skipped before or by the pipeline, with why.
  void countSkipped(SkipReason reason, const std::string& why);
  void countPaused() {  // a frame that came while ~pause was in effect
    std::lock_guard<std::mutex> lock(mutex_);
    ++paused_;
  }
  void countReset() {
    std::lock_guard<std::mutex> lock(mutex_);
    ++resets_;
  }
  // A frame whose TF was not sent: it arrived before the clock went backwards (a looping bag).
  void countTfWithheld() {
    std::lock_guard<std::mutex> lock(mutex_);
    ++tf_withheld_;
  }
  // The node's clock minus a frame's stamp when the frame arrived (s).
  void clockOffset(double clock_minus_stamp) {
    std::lock_guard<std::mutex> lock(mutex_);
    clock_offset_ = clock_minus_stamp;
  }
  void setBackend(const std::string& backend);
  void odometryPublished();

 private:
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& status);
  void diagnoseRate(diagnostic_updater::DiagnosticStatusWrapper& status);
  void skipped(SkipReason reason, const std::string& why);  // under mutex_

  SyncState sync_;
  std::mutex mutex_;
  std::size_t frames_ = 0, skipped_ = 0, stale_ = 0, paused_ = 0, resets_ = 0;
  std::size_t lost_ = 0, recovered_ = 0, restarts_ = 0, fallbacks_ = 0, tf_withheld_ = 0;
  std::array<std::size_t, kSkipReasons> skipped_by_reason_{};
  std::string latest_skip_;
  bool lost_now_ = false;
  std::string lost_problem_, last_problem_, backend_;
  double latency_ms_ = 0.0, max_latency_ms_ = 0.0;
  int threads_ = 0;  // the last frame's CPU threads
  std::size_t one_thread_frames_ = 0;
  std::optional<double> clock_offset_;
  std::optional<DisparityOffsetEstimate> disparity_offset_;
  EventRate rate_;
  diagnostic_updater::Updater updater_;
  ros::Timer timer_;
};

}  // namespace cvo
