// The nodelet's diagnostics: the odometry rate, and a status (named after the nodelet, not its
// manager) with every count a user needs to see what happened to the frames: processed,
// skipped, stale, dropped for latency or while paused, not synchronized, lost, recovered, restarts,
// backend fallbacks, resets; the latency from stamp to publish; the backend. ERROR while tracking
// is lost.
#pragma once

#include <functional>
#include <mutex>
#include <optional>
#include <string>

#include <diagnostic_updater/diagnostic_updater.h>
#include <diagnostic_updater/publisher.h>

#include "cvo_odometry/frontend/odometry_pipeline.hpp"

namespace cvo {

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

  OdometryDiagnostics(ros::NodeHandle nh, ros::NodeHandle pnh, SyncState sync);

  void count(const PipelineResult& result, double latency_ms);
  void countSkipped(const std::string& why);  // before the pipeline (conversion, no camera_info)
  void countPaused() {                        // a frame that came while ~pause was in effect
    std::lock_guard<std::mutex> lock(mutex_);
    ++paused_;
  }
  void countReset() {
    std::lock_guard<std::mutex> lock(mutex_);
    ++resets_;
  }
  void setBackend(const std::string& backend);
  void odometryPublished() { rate_->tick(); }

 private:
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& status);

  SyncState sync_;
  std::mutex mutex_;
  std::size_t frames_ = 0, skipped_ = 0, stale_ = 0, paused_ = 0, resets_ = 0;
  std::size_t lost_ = 0, recovered_ = 0, restarts_ = 0, fallbacks_ = 0;
  bool lost_now_ = false;
  std::string lost_problem_, last_problem_, backend_;
  double latency_ms_ = 0.0, max_latency_ms_ = 0.0;
  std::optional<DisparityOffsetEstimate> disparity_offset_;
  double min_rate_ = 1.0, max_rate_ = 100.0;
  diagnostic_updater::Updater updater_;
  std::unique_ptr<diagnostic_updater::HeaderlessTopicDiagnostic> rate_;
  ros::Timer timer_;
};

}  // namespace cvo
