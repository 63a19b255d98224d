// The ROS adapter of cvo_odometry: synchronized camera topics in; odometry, TF, the indicator,
// a path, debug clouds and diagnostics out; parameters, dynamic_reconfigure and services. It
// only translates: the odometry is OdometryPipeline's, which the tools run too.
//
// Threads: subscriber callbacks convert messages into frames and queue them (FrameQueue); one
// worker thread runs the pipeline and publishes. Reconfigure and the services take the
// pipeline's lock, so they apply between frames. Nothing a topic, a parameter, a reconfigure or
// a service brings may end the manager: errors are caught here, reported and refused.
#pragma once

#include <atomic>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include <dynamic_reconfigure/server.h>
#include <image_transport/image_transport.h>
#include <nav_msgs/Path.h>
#include <ros/ros.h>
#include <std_srvs/Empty.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/static_transform_broadcaster.h>
#include <tf2_ros/transform_broadcaster.h>
#include <tf2_ros/transform_listener.h>
#include <boost/thread/recursive_mutex.hpp>

#include "cvo_odometry/CvoOdometryConfig.h"
#include "cvo_odometry/ResetToPose.h"
#include "cvo_odometry/core/trajectory.hpp"
#include "cvo_odometry/frontend/odometry_pipeline.hpp"
#include "cvo_odometry/ros/frame_queue.hpp"
#include "cvo_odometry/ros/node_settings.hpp"
#include "cvo_odometry/ros/odometry_diagnostics.hpp"
#include "cvo_odometry/ros/rgbd_topic_sync.hpp"
#include "cvo_odometry/ros/stereo_topic_sync.hpp"

namespace cvo {

class CvoOdometryRos {
 public:
  // `nh`: topics (relative names); `pnh`: parameters and services. Throws for parameters that
  // make no sense (the nodelet logs it and stays idle).
  CvoOdometryRos(ros::NodeHandle nh, ros::NodeHandle pnh);
  ~CvoOdometryRos();

 private:
  struct QueuedFrame {
    std_msgs::Header header;  // stamp of the pose, frame_id of the camera
    CameraFrame frame;
    ros::Time arrival;            // the node's clock when the frame was queued
    bool far_from_clock = false;  // its stamp was far from that clock: no latency
  };

  void subscribe();
  // Converts and queues a frame; `held`: one of the first frames after a start, which waited
  // for the synchronizer (kept in live mode rather than replaced by the next).
  void enqueue(const std_msgs::Header& header, const std::function<CameraFrame()>& convert,
               bool held = false);
  // Warns (throttled) when a frame's stamp is far from the node's clock; returns whether it is.
  bool checkClock(const ros::Time& stamp, const ros::Time& now);
  void work();
  void handle(const QueuedFrame& queued);
  // `send_tf`: false for a frame from before the clock went backwards.
  void publish(const std_msgs::Header& header, const PipelineResult& result, double latency_ms,
               bool send_tf);
  void publishClouds(const std_msgs::Header& header, const PipelineResult& result);
  void onReconfigure(cvo_odometry::CvoOdometryConfig& config, uint32_t level);
  // The next frame starts a new trajectory with the base at `base_pose`; base <- camera is
  // looked up again.
  void restart(const Eigen::Isometry3d& base_pose, const std::string& why);
  // camera_transform when set (and published on /tf_static), else TF, else a forward camera.
  Eigen::Isometry3d baseFromCamera(const std::string& camera_frame);
  std::unique_ptr<RegistrationBackend> makeBackend(const CvoParams& params) const;

  ros::NodeHandle nh_, pnh_;
  NodeSettings settings_;
  std::mutex pipeline_mutex_;  // one frame, reconfigure or service at a time
  std::unique_ptr<OdometryPipeline> pipeline_;
  std::optional<Eigen::Isometry3d> base_from_camera_;
  nav_msgs::Path path_;
  Trajectory trajectory_;  // kept only when trajectory_file is set, written at shutdown
  ros::Time last_tf_stamp_;
  std::atomic<bool> paused_{false};

  image_transport::ImageTransport it_;
  ros::Publisher odom_pub_, indicator_pub_, path_pub_;
  ros::Publisher current_cloud_pub_, reference_cloud_pub_, aligned_cloud_pub_;
  ros::ServiceServer reset_service_, reset_to_pose_service_, pause_service_, resume_service_;
  tf2_ros::TransformBroadcaster tf_broadcaster_;
  tf2_ros::StaticTransformBroadcaster static_broadcaster_;  // camera_transform
  boost::recursive_mutex reconfigure_mutex_;
  std::unique_ptr<dynamic_reconfigure::Server<cvo_odometry::CvoOdometryConfig>> reconfigure_;
  std::unique_ptr<OdometryDiagnostics> diagnostics_;

  FrameQueue<QueuedFrame> queue_;
  std::thread worker_;
  std::mutex info_mutex_;
  sensor_msgs::CameraInfoConstPtr rgb_info_;  // latest rgb/camera_info
  ros::Subscriber rgb_info_sub_;
  // Destroyed first (reverse order of members), ending callbacks into the rest.
  std::unique_ptr<RgbdTopicSync> rgbd_sync_;
  std::unique_ptr<StereoTopicSync> stereo_sync_;
};

}  // namespace cvo
