// The ROS adapter of cvo_odometry: synchronized camera topics in; odometry, TF, the indicator,
// a path, debug clouds and diagnostics out; parameters, dynamic_reconfigure and a reset service.
// The algorithm lives in the core and front end; this class converts, sequences and publishes.
#pragma once

#include <atomic>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include <diagnostic_updater/diagnostic_updater.h>
#include <diagnostic_updater/publisher.h>
#include <dynamic_reconfigure/server.h>
#include <image_transport/image_transport.h>
#include <image_transport/subscriber_filter.h>
#include <message_filters/subscriber.h>
#include <nav_msgs/Path.h>
#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <std_srvs/Empty.h>
#include <stereo_msgs/DisparityImage.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_broadcaster.h>
#include <tf2_ros/transform_listener.h>
#include <boost/thread/recursive_mutex.hpp>

#include "cvo_odometry/CvoOdometryConfig.h"
#include "cvo_odometry/core/frame_to_frame_odometry.hpp"
#include "cvo_odometry/core/trajectory.hpp"
#include "cvo_odometry/frontend/rgbd_cloud_builder.hpp"
#include "cvo_odometry/frontend/stereo_cloud_builder.hpp"
#include "cvo_odometry/ros/rgbd_topic_sync.hpp"

namespace cvo {

using cvo_odometry::CvoOdometryConfig;

class CvoOdometryRos {
 public:
  // `nh`: topics (relative names); `pnh`: parameters. Throws std::invalid_argument for parameters
  // that make no sense (the nodelet logs it and stays idle).
  CvoOdometryRos(ros::NodeHandle nh, ros::NodeHandle pnh);
  ~CvoOdometryRos();

 private:
  enum class Mode { kRgbd, kStereo, kDisparity };

  void loadParameters();
  // The RGB-D and stereo front ends from cloud_options_ (at start and when the point range
  // changes).
  void makeCloudBuilders();
  // FrameToFrameOdometry with the backend of params_ (at start and when the backend changes).
  void makeOdometry();
  void subscribe();
  void onRgbd(const sensor_msgs::ImageConstPtr& image, const sensor_msgs::CameraInfoConstPtr& info,
              const sensor_msgs::ImageConstPtr& depth, const sensor_msgs::ImageConstPtr& labels);
  void countArrivals(image_transport::SubscriberFilter& images);
  void onRgbdWithLabels(const sensor_msgs::ImageConstPtr& image,
                        const sensor_msgs::ImageConstPtr& depth,
                        const sensor_msgs::ImageConstPtr& labels);
  void onStereoImages(const sensor_msgs::ImageConstPtr& left,
                      const sensor_msgs::CameraInfoConstPtr& info,
                      const sensor_msgs::ImageConstPtr& right,
                      const sensor_msgs::CameraInfoConstPtr& right_info);
  void onStereoDisparity(const sensor_msgs::ImageConstPtr& left,
                         const sensor_msgs::CameraInfoConstPtr& info,
                         const stereo_msgs::DisparityImageConstPtr& disparity);
  void onStereo(const sensor_msgs::ImageConstPtr& left, const sensor_msgs::CameraInfoConstPtr& info,
                const sensor_msgs::ImageConstPtr& right,
                const sensor_msgs::CameraInfoConstPtr& right_info,
                const stereo_msgs::DisparityImageConstPtr& disparity);
  // Runs the front end: a cloud is processed, an empty frame is a lost frame, inconsistent
  // input is skipped.
  void buildAndProcess(const std_msgs::Header& header,
                       const std::function<LabeledCloud(FrontendStats*)>& build);
  // Registers `cloud` (or, without one, a lost frame for `why_no_cloud`) and publishes;
  // `header` is the current frame's.
  void process(const std_msgs::Header& header, std::optional<LabeledCloud> cloud,
               const std::string& why_no_cloud, const FrontendStats& stats);
  void count(const OdometryUpdate& update);
  // The indicator always; odometry, TF, path and debug clouds when the update has a pose.
  void publish(const std_msgs::Header& header, const OdometryUpdate& update,
               const LabeledCloud* cloud, const FrontendStats& stats);
  void publishDebugClouds(const std_msgs::Header& header, const OdometryUpdate& update,
                          const LabeledCloud& cloud);
  void skipFrame(const std::string& why);
  void applyPendingConfig();
  void onReconfigure(CvoOdometryConfig& config, uint32_t level);
  bool onReset(std_srvs::Empty::Request&, std_srvs::Empty::Response&);
  void resetState(const std::string& why);
  Eigen::Isometry3d baseFromCamera(const std::string& camera_frame);
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& status);

  ros::NodeHandle nh_, pnh_;
  Mode mode_ = Mode::kRgbd;
  bool use_segmentation_ = false;
  std::string odom_frame_ = "odom", base_frame_ = "base_link";
  bool publish_tf_ = true;
  double depth_units_per_metre_ = 1000.0;
  std::string trajectory_file_;
  Trajectory trajectory_;       // kept only when trajectory_file_ is set, written at shutdown
  int max_path_poses_ = 10000;  // the path topic keeps the latest poses

  std::mutex mutex_;  // one frame at a time; guards state below and the pending config
  CvoParams params_;
  CloudBuilderOptions cloud_options_;
  std::optional<CvoParams> pending_params_;
  std::optional<CloudBuilderOptions> pending_cloud_options_;
  std::unique_ptr<FrameToFrameOdometry> odometry_;
  std::unique_ptr<RgbdCloudBuilder> rgbd_builder_;
  std::unique_ptr<StereoCloudBuilder> stereo_builder_;
  std::optional<Eigen::Isometry3d> base_from_camera_;
  std::optional<ros::Time> last_stamp_;
  Eigen::Matrix<double, 6, 6> pose_covariance_ = Eigen::Matrix<double, 6, 6>::Zero();
  nav_msgs::Path path_;

  int inject_backend_fault_after_ = -1;  // test hook, see makeOdometry

  std::size_t frames_ = 0, skipped_ = 0, resets_ = 0;
  std::size_t lost_ = 0, recovered_ = 0, tracking_resets_ = 0, backend_fallbacks_ = 0;
  bool lost_now_ = false;  // the latest frame was lost
  std::string lost_problem_;
  std::atomic<std::size_t> arrived_{0};  // stereo: left images, before synchronization
  std::string last_problem_;

  image_transport::ImageTransport it_;
  // Members are destroyed in reverse order: the synchronizer before the filters it is
  // connected to, the reconfigure server before its mutex.
  std::vector<std::shared_ptr<void>> filters_;
  std::shared_ptr<void> sync_;  // stereo: the message_filters synchronizer
  std::mutex info_mutex_;
  sensor_msgs::CameraInfoConstPtr rgb_info_;  // latest rgb/camera_info
  ros::Subscriber rgb_info_sub_;
  ros::Publisher odom_pub_, indicator_pub_, path_pub_;
  ros::Publisher current_cloud_pub_, previous_cloud_pub_, aligned_cloud_pub_;
  ros::ServiceServer reset_service_;
  tf2_ros::Buffer tf_buffer_;
  tf2_ros::TransformListener tf_listener_;
  tf2_ros::TransformBroadcaster tf_broadcaster_;
  boost::recursive_mutex reconfigure_mutex_;
  std::unique_ptr<dynamic_reconfigure::Server<CvoOdometryConfig>> reconfigure_;
  diagnostic_updater::Updater diagnostics_;
  std::unique_ptr<diagnostic_updater::HeaderlessTopicDiagnostic> rate_diagnostic_;
  double min_rate_ = 1.0, max_rate_ = 100.0;
  ros::Timer diagnostics_timer_;
  std::unique_ptr<RgbdTopicSync> rgbd_sync_;  // RGB-D topics; destroyed first, ending callbacks
};

}  // namespace cvo
