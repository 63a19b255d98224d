#include "cvo_odometry/ros/cvo_odometry_ros.hpp"

#include <cmath>
#include <limits>
#include <sstream>

#include <nav_msgs/Odometry.h>

#include "cvo_odometry/core/backend_factory.hpp"
#include "cvo_odometry/core/cpu_backend.hpp"
#include "cvo_odometry/core/failover_backend.hpp"
#include "cvo_odometry/core/fault_injection_backend.hpp"
#include "cvo_odometry/core/trajectory_io.hpp"
#include "cvo_odometry/ros/ros_conversions.hpp"
#include "cvo_odometry/ros/settings_reconfigure.hpp"

namespace cvo {

using cvo_odometry::CvoOdometryConfig;

namespace {

// An RGB-D frame before the first rgb/camera_info: skipped, counted apart from unreadable input.
struct NoCameraInfo : std::invalid_argument {
  NoCameraInfo() : std::invalid_argument("no rgb/camera_info received yet") {}
};

}  // namespace

CvoOdometryRos::CvoOdometryRos(ros::NodeHandle nh, ros::NodeHandle pnh)
    : nh_(nh),
      pnh_(pnh),
      settings_(readNodeSettings(pnh)),
      it_(nh),
      queue_(settings_.node.process_every_frame) {
  pipeline_ = std::make_unique<OdometryPipeline>(
      settings_.odometry, [this](const CvoParams& params) { return makeBackend(params); });
  pipeline_->reset(initialPose(settings_.node));
  ROS_INFO_STREAM(pnh_.getNamespace()
                  << ": mode " << settingText(settings_.node.mode) << ", backend "
                  << pipeline_->backendName() << ", " << settings_.node.odom_frame << " -> "
                  << settings_.node.base_frame << "; settings:\n"
                  << describeSettings(settings_));
  if (!pipeline_->backendNote().empty()) ROS_INFO_STREAM(pipeline_->backendNote());

  odom_pub_ = nh_.advertise<nav_msgs::Odometry>("odom", 10);
  indicator_pub_ = nh_.advertise<cvo_odometry::CvoIndicator>("indicator", 10);
  path_pub_ = nh_.advertise<nav_msgs::Path>("path", 1, true);
  current_cloud_pub_ = nh_.advertise<sensor_msgs::PointCloud2>("cloud/current", 1);
  reference_cloud_pub_ = nh_.advertise<sensor_msgs::PointCloud2>("cloud/previous", 1);
  aligned_cloud_pub_ = nh_.advertise<sensor_msgs::PointCloud2>("cloud/aligned", 1);
  reset_service_ = pnh_.advertiseService<std_srvs::Empty::Request, std_srvs::Empty::Response>(
      "reset", [this](auto&, auto&) {
        restart(initialPose(settings_.node), "reset requested");
        return true;
      });
  reset_to_pose_service_ = pnh_.advertiseService<cvo_odometry::ResetToPose::Request,
                                                 cvo_odometry::ResetToPose::Response>(
      "reset_to_pose", [this](auto& request, auto& response) {
        try {
          restart(fromPoseMsg(request.pose), "reset to a pose requested");
          response.success = true;
        } catch (const std::invalid_argument& e) {
          response.message = e.what();
        }
        return true;
      });
  pause_service_ = pnh_.advertiseService<std_srvs::Empty::Request, std_srvs::Empty::Response>(
      "pause", [this](auto&, auto&) {
        paused_ = true;
        ROS_INFO_STREAM(pnh_.getNamespace() << ": paused; frames are dropped until ~resume");
        return true;
      });
  resume_service_ = pnh_.advertiseService<std_srvs::Empty::Request, std_srvs::Empty::Response>(
      "resume", [this](auto&, auto&) {
        // The camera moved meanwhile: the next frame starts over where the pose was.
        std::lock_guard<std::mutex> lock(pipeline_mutex_);
        if (!paused_.exchange(false)) return true;
        pipeline_->reset(path_.poses.empty() ? initialPose(settings_.node)
                                             : fromPoseMsg(path_.poses.back().pose));
        ROS_INFO_STREAM(pnh_.getNamespace() << ": resumed from the last pose");
        return true;
      });

  reconfigure_ =
      std::make_unique<dynamic_reconfigure::Server<CvoOdometryConfig>>(reconfigure_mutex_, pnh_);
  reconfigure_->updateConfig(toConfig(settings_));
  reconfigure_->setCallback(
      [this](CvoOdometryConfig& config, uint32_t level) { onReconfigure(config, level); });
  worker_ = std::thread([this] { work(); });
  subscribe();
}

CvoOdometryRos::~CvoOdometryRos() {
  rgbd_sync_.reset();
  stereo_sync_.reset();
  queue_.close();
  if (worker_.joinable()) worker_.join();
  if (settings_.node.trajectory_file.empty()) return;
  try {
    writeTrajectory(settings_.node.trajectory_file, trajectory_, TrajectoryFormat::kTum);
  } catch (const std::exception& e) {
    ROS_ERROR_STREAM(pnh_.getNamespace() << ": " << e.what());
  }
}

std::unique_ptr<RegistrationBackend> CvoOdometryRos::makeBackend(const CvoParams& params) const {
  std::unique_ptr<RegistrationBackend> backend =
      cvo::makeBackend(params.backend, params.num_threads);
  const int fault_after = settings_.node.inject_backend_fault_after;
  if (fault_after < 0) return backend;
  // Test hook: the backend fails from then on, as a GPU lost mid-run; the CPU takes over.
  ROS_WARN_STREAM(pnh_.getNamespace()
                  << ": the backend will fail after " << fault_after << " evaluations (test hook)");
  return std::make_unique<FailoverBackend>(
      std::make_unique<FaultInjectionBackend>(std::move(backend), fault_after),
      std::make_unique<CpuBackend>(params.num_threads));
}

void CvoOdometryRos::subscribe() {
  const NodeOptions& node = settings_.node;
  diagnostics_ = std::make_unique<OdometryDiagnostics>(
      nh_, pnh_,
      OdometryDiagnostics::SyncState{
          [this] { return rgbd_sync_ ? rgbd_sync_->arrived() : stereo_sync_->arrived(); },
          [this] { return rgbd_sync_ ? rgbd_sync_->learnedOffset() : std::nullopt; },
          [this] { return queue_.dropped(); },
          [this]() -> std::optional<double> {
            if (rgbd_sync_ == nullptr) return std::nullopt;
            std::lock_guard<std::mutex> lock(info_mutex_);
            if (!rgb_info_) return std::nullopt;
            return rgb_info_->header.stamp.toSec();
          }});
  diagnostics_->setBackend(pipeline_->backendName());
  const image_transport::TransportHints hints("raw", ros::TransportHints(), pnh_);
  if (node.mode != CameraMode::kRgbd) {
    const SyncPolicy policy =
        node.sync_policy == SyncPolicy::kAuto ? SyncPolicy::kExact : node.sync_policy;
    StereoSyncOptions options;
    options.with_disparity = node.mode == CameraMode::kDisparity;
    options.policy = policy;
    options.queue_size = node.queue_size;
    options.min_frame_interval = node.min_frame_interval;
    options.with_labels = node.use_segmentation;
    stereo_sync_ = std::make_unique<StereoTopicSync>(
        nh_, it_, hints, options, [this](const StereoTopicSync::Frame& frame) {
          enqueue(frame.left->header, [&] {
            return stereoFrameFromMsgs(*frame.left, *frame.left_info, frame.right.get(),
                                       frame.right_info.get(), frame.disparity.get(),
                                       frame.labels.get());
          });
        });
    return;
  }
  // camera_info is not synchronized: the latest one is used (it rarely changes), which keeps
  // the synchronization to the streams whose stamps really differ.
  rgb_info_sub_ = nh_.subscribe<sensor_msgs::CameraInfo>(
      "rgb/camera_info", 1, [this](const sensor_msgs::CameraInfoConstPtr& info) {
        std::lock_guard<std::mutex> lock(info_mutex_);
        rgb_info_ = info;
      });
  RgbdSyncOptions options;
  options.policy = node.sync_policy == SyncPolicy::kAuto ? SyncPolicy::kOrdered : node.sync_policy;
  options.queue_size = node.queue_size;
  options.min_frame_interval = node.min_frame_interval;
  options.tolerance = node.sync_tolerance;
  options.with_labels = node.use_segmentation;
  rgbd_sync_ = std::make_unique<RgbdTopicSync>(
      it_, hints, options,
      [this](const auto& image, const auto& depth, const auto& labels, bool held) {
        sensor_msgs::CameraInfoConstPtr info;
        {
          std::lock_guard<std::mutex> lock(info_mutex_);
          info = rgb_info_;
        }
        std_msgs::Header header = depth->header;  // the pose is stamped with the depth time
        if (!image->header.frame_id.empty()) header.frame_id = image->header.frame_id;
        enqueue(
            header,
            [&] {
              if (!info) throw NoCameraInfo();
              return rgbdFrameFromMsgs(*image, *info, *depth, labels.get());
            },
            held);
      });
}

void CvoOdometryRos::enqueue(const std_msgs::Header& header,
                             const std::function<CameraFrame()>& convert, bool held) {
  if (paused_) {
    diagnostics_->countPaused();
    return;
  }
  const ros::Time now = ros::Time::now();
  const bool far = checkClock(header.stamp, now);
  try {
    queue_.push(QueuedFrame{header, convert(), now, far}, held);
  } catch (const NoCameraInfo& e) {
    diagnostics_->countSkipped(SkipReason::kNoCameraInfo, e.what());
    ROS_WARN_STREAM_THROTTLE(2.0, pnh_.getNamespace() << ": frame skipped: " << e.what());
  } catch (const std::exception& e) {
    diagnostics_->countSkipped(SkipReason::kUnreadable, e.what());
    ROS_WARN_STREAM_THROTTLE(2.0, pnh_.getNamespace() << ": frame skipped: " << e.what());
  }
}

bool CvoOdometryRos::checkClock(const ros::Time& stamp, const ros::Time& now) {
  const double behind = (now - stamp).toSec();
  diagnostics_->clockOffset(behind);
  if (std::abs(behind) <= OdometryDiagnostics::kFarFromClock) return false;
  std::ostringstream why;
  if (now.isZero()) {
    why << "this node's clock reads 0: use_sim_time is true and nothing publishes /clock (play "
           "the bag with rosbag play --clock)";
  } else if (ros::Time::isSimTime()) {
    why << "use_sim_time is true and /clock is at " << now
        << ": the stamps come from another clock (a live camera while a bag plays with --clock?)";
  } else {
    why << "this node runs on the wall clock: a bag played without --clock, or /use_sim_time set "
           "after the nodelet started (set it before, and play with rosbag play --clock, as "
           "play_bag.launch does), or a camera whose clock is not this machine's";
  }
  ROS_WARN_STREAM_THROTTLE(
      60.0, pnh_.getNamespace() << ": frame stamps are " << std::abs(behind) << " s "
                                << (behind > 0.0 ? "behind" : "ahead of")
                                << " this node's clock (stamp " << stamp << ", clock " << now
                                << "): " << why.str() << ". latency_ms is NaN while this lasts.");
  return true;
}

void CvoOdometryRos::work() {
  while (std::optional<QueuedFrame> queued = queue_.pop()) {
    try {
      handle(*queued);
    } catch (const std::exception& e) {
      // A bug, not bad input (the pipeline classifies that): report it and keep running.
      ROS_ERROR_STREAM(pnh_.getNamespace() << ": frame failed: " << e.what());
      diagnostics_->countSkipped(SkipReason::kInternalError, e.what());
    }
  }
}

void CvoOdometryRos::handle(const QueuedFrame& queued) {
  std::lock_guard<std::mutex> lock(pipeline_mutex_);
  if (paused_) {
    diagnostics_->countPaused();
    return;
  }
  std_msgs::Header header = queued.header;
  if (!settings_.node.camera_frame.empty()) header.frame_id = settings_.node.camera_frame;
  if (!base_from_camera_) base_from_camera_ = baseFromCamera(header.frame_id);
  const std::optional<double> last_stamp = pipeline_->odometry().lastStamp();
  const PipelineResult result =
      pipeline_->process(header.stamp.toSec(), queued.frame, *base_from_camera_);
  const ros::Time now = ros::Time::now();
  // The clock went backwards since the frame came (a looping bag): it belongs to the loop before.
  const bool before_clock_jump = now < queued.arrival;
  const double latency_ms = queued.far_from_clock || before_clock_jump
                                ? std::numeric_limits<double>::quiet_NaN()
                                : (now - header.stamp).toSec() * 1000.0;
  if (result.outcome == FrameOutcome::kSkipped && last_stamp &&
      *last_stamp == header.stamp.toSec()) {
    diagnostics_->countSkipped(SkipReason::kRepeatedStamp, result.why);
  } else {
    diagnostics_->count(result, latency_ms);
  }
  if (!result.why.empty()) {
    if (result.outcome == FrameOutcome::kProcessed) {
      ROS_WARN_STREAM(pnh_.getNamespace() << ": " << result.why);
      path_.poses.clear();
    } else if (result.outcome == FrameOutcome::kSkipped || result.stale_burst_start) {
      ROS_WARN_STREAM_THROTTLE(
          2.0, pnh_.getNamespace() << ": frame " << header.stamp << " skipped: " << result.why
                                   << (result.stale_burst_start ? " (counted from now on)" : ""));
    }
  }
  if (result.outcome != FrameOutcome::kProcessed) return;
  if (!result.update.problem.empty()) {
    ROS_WARN_STREAM_THROTTLE(2.0, pnh_.getNamespace() << ": frame " << toString(result.update.state)
                                                      << ": " << result.update.problem);
  }
  if (!result.update.report.warning.empty()) {
    ROS_WARN_STREAM_THROTTLE(5.0, pnh_.getNamespace() << ": " << result.update.report.warning);
  }
  publish(header, result, latency_ms, !before_clock_jump);
}

void CvoOdometryRos::publish(const std_msgs::Header& header, const PipelineResult& result,
                             double latency_ms, bool send_tf) {
  const NodeOptions& node = settings_.node;
  indicator_pub_.publish(
      indicatorMsg(result, header.stamp, node.odom_frame, {latency_ms, queue_.dropped()}));
  if (!result.update.has_pose) return;  // lost_frame_policy publish_nothing
  const nav_msgs::Odometry odom =
      odometryMsg(result.update, header.stamp, node.odom_frame, node.base_frame);
  odom_pub_.publish(odom);
  diagnostics_->odometryPublished();
  // A repeated stamp would only make listeners warn (TF_REPEATED_DATA). So would a frame from
  // before the clock went backwards: listeners clear their buffers when it does, would keep its
  // stamp, and get the same stamp again in the next loop.
  if (node.publish_tf && !send_tf) {
    diagnostics_->countTfWithheld();
    ROS_INFO_STREAM_THROTTLE(5.0, pnh_.getNamespace()
                                      << ": the clock went backwards (a looping bag?): no TF for "
                                         "the frames that came before it");
  } else if (node.publish_tf && header.stamp != last_tf_stamp_) {
    tf_broadcaster_.sendTransform(odometryTransformMsg(odom));
    last_tf_stamp_ = header.stamp;
  }
  geometry_msgs::PoseStamped stamped;
  stamped.header = odom.header;
  stamped.pose = odom.pose.pose;
  path_.header = odom.header;
  path_.poses.push_back(stamped);
  // Bounded: a long run must not grow memory or the message without limit.
  const auto keep = static_cast<std::size_t>(node.max_path_poses);
  if (path_.poses.size() > keep) path_.poses.erase(path_.poses.begin(), path_.poses.end() - keep);
  // The camera's trajectory, as documented and as cvo_run_sequence writes it: comparable with a
  // dataset's ground truth, which is the camera's.
  if (!node.trajectory_file.empty())
    trajectory_.append(header.stamp.toSec(), result.update.base_pose * *base_from_camera_);
  if (path_pub_.getNumSubscribers() > 0) path_pub_.publish(path_);
  publishClouds(header, result);
}

void CvoOdometryRos::publishClouds(const std_msgs::Header& header, const PipelineResult& result) {
  if (result.cloud && current_cloud_pub_.getNumSubscribers() > 0) {
    current_cloud_pub_.publish(cloudToMsg(*result.cloud, Eigen::Isometry3f::Identity(), header));
  }
  if (result.update.firstFrame()) return;
  if (result.reference && reference_cloud_pub_.getNumSubscribers() > 0) {
    reference_cloud_pub_.publish(
        cloudToMsg(*result.reference, Eigen::Isometry3f::Identity(), header));
  }
  // The current cloud moved into the reference camera frame: it should overlay cloud/previous.
  if (result.cloud && aligned_cloud_pub_.getNumSubscribers() > 0) {
    aligned_cloud_pub_.publish(
        cloudToMsg(*result.cloud, result.update.motion.cast<float>(), header));
  }
}

void CvoOdometryRos::restart(const Eigen::Isometry3d& base_pose, const std::string& why) {
  std::lock_guard<std::mutex> lock(pipeline_mutex_);
  ROS_WARN_STREAM(pnh_.getNamespace() << ": " << why << ": the next frame starts a new odometry");
  queue_.clear();
  pipeline_->reset(base_pose);
  base_from_camera_.reset();              // a transform published since is taken now
  if (rgbd_sync_) rgbd_sync_->relearn();  // the source may have other timing now
  path_.poses.clear();
  trajectory_ = Trajectory();
  diagnostics_->countReset();
}

void CvoOdometryRos::onReconfigure(CvoOdometryConfig& config, uint32_t) {
  std::lock_guard<std::mutex> lock(pipeline_mutex_);
  try {
    const NodeSettings next = applyConfig(config, settings_);
    const std::string changes = describeChanges(next, settings_);
    if (changes.empty()) return;
    const bool restarted = pipeline_->setSettings(next.odometry);
    settings_ = next;
    diagnostics_->setBackend(pipeline_->backendName());
    ROS_INFO_STREAM(pnh_.getNamespace() << ": reconfigured:\n"
                                        << changes
                                        << (restarted ? "backend now " + pipeline_->backendName() +
                                                            ": odometry restarted"
                                                      : ""));
  } catch (const std::exception& e) {
    ROS_ERROR_STREAM(pnh_.getNamespace() << ": reconfigure refused, nothing changed: " << e.what());
  }
  config = toConfig(settings_);  // the server shows what is in effect
}

Eigen::Isometry3d CvoOdometryRos::baseFromCamera(const std::string& camera_frame) {
  const NodeOptions& node = settings_.node;
  if (camera_frame.empty() || camera_frame == node.base_frame) return Eigen::Isometry3d::Identity();
  if (!node.camera_transform.empty()) {
    // Stated by the user: used as is, and published so that rviz and others see the same.
    const Eigen::Isometry3d base_from_camera = poseFromXyzRpy(node.camera_transform);
    geometry_msgs::TransformStamped stamped;
    stamped.header.stamp = ros::Time::now();
    stamped.header.frame_id = node.base_frame;
    stamped.child_frame_id = camera_frame;
    stamped.transform = toTransformMsg(base_from_camera);
    static_broadcaster_.sendTransform(stamped);
    return base_from_camera;
  }
  // A listener for this lookup only: one kept all along would take in every /tf message, our
  // own odometry's included, and warn at each jump of a looping bag's clock. The wait is on the
  // wall clock: a simulated one may stand still meanwhile (a player paced by our indicator waits
  // for this very frame).
  tf2_ros::Buffer buffer;
  tf2_ros::TransformListener listener(buffer);
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(node.tf_wait);
  std::string why;
  do {
    try {
      return fromTransformMsg(
          buffer.lookupTransform(node.base_frame, camera_frame, ros::Time(0)).transform);
    } catch (const tf2::TransformException& e) {
      why = e.what();
    }
    ros::WallDuration(0.01).sleep();
  } while (ros::WallTime::now() < deadline && ros::ok());
  ROS_WARN_STREAM(pnh_.getNamespace()
                  << ": no transform " << node.base_frame << " <- " << camera_frame << " after "
                  << node.tf_wait << " s (" << why << "); assuming a camera looking along "
                  << node.base_frame
                  << "'s x axis (optical frame z forward). Publish the camera's transform (e.g. "
                     "the launch files' camera_transform argument), then call ~reset.");
  return opticalFrameInBase();
}

}  // namespace cvo
