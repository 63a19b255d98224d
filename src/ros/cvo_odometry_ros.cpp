#include "cvo_odometry/ros/cvo_odometry_ros.hpp"

#include <cstdio>
#include <fstream>
#include <sstream>

#include <nav_msgs/Odometry.h>
#include <boost/function.hpp>

#include "cvo_odometry/CvoIndicator.h"
#include "cvo_odometry/core/backend_factory.hpp"
#include "cvo_odometry/core/cpu_backend.hpp"
#include "cvo_odometry/core/failover_backend.hpp"
#include "cvo_odometry/core/fault_injection_backend.hpp"
#include "cvo_odometry/core/lie_group.hpp"
#include "cvo_odometry/core/params_io.hpp"
#include "cvo_odometry/core/registration_covariance.hpp"
#include "cvo_odometry/core/trajectory_io.hpp"
#include "cvo_odometry/frontend/empty_frame_error.hpp"
#include "cvo_odometry/frontend/frontend_params.hpp"
#include "cvo_odometry/ros/policy_synchronizer.hpp"
#include "cvo_odometry/ros/ros_conversions.hpp"

namespace cvo {

namespace {

// Every parameter, from the preset file first and then single ROS parameters of the same name.
template <class T>
void override(const ros::NodeHandle& pnh, const std::string& key, T* value) {
  pnh.param(key, *value, *value);
}

std::string describe(const CvoParams& params, const CloudBuilderOptions& cloud) {
  std::ostringstream out;
  writeCvoParams(out, params);
  out << "point_selector: "
      << (cloud.selector.kind == SelectorKind::kFast   ? "fast"
          : cloud.selector.kind == SelectorKind::kGrid ? "grid"
                                                       : "mixed")
      << "\nmin_points: " << cloud.selector.min_points
      << "\nmax_points: " << cloud.selector.max_points << "\nmin_depth: " << cloud.min_depth
      << "\nmax_depth: " << cloud.max_depth << "\ncrop_top_rows: " << cloud.crop_top_rows
      << "\nimage_levels: " << cloud.image_levels << "\n";
  return out.str();
}

}  // namespace

CvoOdometryRos::CvoOdometryRos(ros::NodeHandle nh, ros::NodeHandle pnh)
    : nh_(nh), pnh_(pnh), it_(nh), tf_listener_(tf_buffer_), diagnostics_(nh, pnh) {
  loadParameters();
  makeOdometry();
  ROS_INFO_STREAM("cvo_odometry: mode "
                  << (mode_ == Mode::kRgbd     ? "rgbd"
                      : mode_ == Mode::kStereo ? "stereo"
                                               : "disparity")
                  << ", backend " << odometry_->registration().backend().name() << ", frames "
                  << odom_frame_ << " -> " << base_frame_ << "; effective parameters:\n"
                  << describe(params_, cloud_options_));

  odom_pub_ = nh_.advertise<nav_msgs::Odometry>("odom", 10);
  indicator_pub_ = nh_.advertise<cvo_odometry::CvoIndicator>("indicator", 10);
  path_pub_ = nh_.advertise<nav_msgs::Path>("path", 1, true);
  current_cloud_pub_ = nh_.advertise<sensor_msgs::PointCloud2>("cloud/current", 1);
  previous_cloud_pub_ = nh_.advertise<sensor_msgs::PointCloud2>("cloud/previous", 1);
  aligned_cloud_pub_ = nh_.advertise<sensor_msgs::PointCloud2>("cloud/aligned", 1);
  reset_service_ = pnh_.advertiseService("reset", &CvoOdometryRos::onReset, this);

  diagnostics_.setHardwareID("cvo_odometry");
  diagnostics_.add("odometry", this, &CvoOdometryRos::diagnose);
  rate_diagnostic_ = std::make_unique<diagnostic_updater::HeaderlessTopicDiagnostic>(
      "odom", diagnostics_, diagnostic_updater::FrequencyStatusParam(&min_rate_, &max_rate_));
  diagnostics_timer_ = nh_.createTimer(ros::Duration(1.0),
                                       [this](const ros::TimerEvent&) { diagnostics_.update(); });

  reconfigure_ =
      std::make_unique<dynamic_reconfigure::Server<CvoOdometryConfig>>(reconfigure_mutex_, pnh_);
  CvoOdometryConfig initial;
  initial.ell_init = params_.ell_init, initial.ell_min = params_.ell_min;
  initial.ell_first_frame = params_.ell_first_frame,
  initial.schedule_decay = params_.schedule_decay;
  initial.sigma = params_.sigma, initial.sp_thres = params_.sp_thres;
  initial.use_color = params_.use_color, initial.color_ell = params_.color_ell;
  initial.color_sigma = params_.color_sigma, initial.use_semantics = params_.use_semantics;
  initial.semantic_ell = params_.semantic_ell, initial.semantic_sigma = params_.semantic_sigma;
  initial.max_iterations = params_.max_iterations, initial.min_step = params_.min_step;
  initial.max_step = params_.max_step, initial.min_points = cloud_options_.selector.min_points;
  initial.max_points = cloud_options_.selector.max_points;
  initial.backend = toString(params_.backend);
  initial.min_cosine = params_.min_cosine;
  initial.min_tracking_points = params_.min_tracking_points;
  initial.max_linear_speed = params_.max_linear_speed;
  initial.max_angular_speed = params_.max_angular_speed;
  initial.lost_frame_policy = toString(params_.lost_frame_policy);
  initial.max_lost_frames = params_.max_lost_frames;
  initial.photometric_rotation = params_.photometric_rotation;
  initial.photometric_iterations = params_.photometric_iterations;
  initial.photometric_max_correction = params_.photometric_max_correction;
  reconfigure_->updateConfig(initial);
  reconfigure_->setCallback(
      [this](CvoOdometryConfig& config, uint32_t level) { onReconfigure(config, level); });
  subscribe();
}

CvoOdometryRos::~CvoOdometryRos() {
  if (trajectory_file_.empty()) return;
  try {
    writeTrajectory(trajectory_file_, trajectory_, TrajectoryFormat::kTum);
  } catch (const std::exception& e) {
    ROS_ERROR_STREAM("cvo_odometry: " << e.what());
  }
}

void CvoOdometryRos::loadParameters() {
  std::string preset, mode, backend;
  pnh_.param<std::string>("preset", preset, "");
  pnh_.param<std::string>("mode", mode, "rgbd");
  mode_ = mode == "rgbd"     ? Mode::kRgbd
          : mode == "stereo" ? Mode::kStereo
          : mode == "disparity"
              ? Mode::kDisparity
              : throw std::invalid_argument("mode must be rgbd, stereo or disparity");
  if (mode_ != Mode::kRgbd) cloud_options_ = kittiStereoFrontendOptions().cloud;
  if (!preset.empty()) {
    params_ = loadCvoParams(preset);
    loadFrontendParams(preset, &cloud_options_);
  }
  // Single parameters override the preset.
  for (const auto& name : cvoParamNames()) {
    XmlRpc::XmlRpcValue value;
    if (!pnh_.getParam(name, value)) continue;
    std::ostringstream text;
    if (value.getType() == XmlRpc::XmlRpcValue::TypeBoolean) {
      text << (static_cast<bool>(value) ? "true" : "false");
    } else if (value.getType() == XmlRpc::XmlRpcValue::TypeString) {
      text << static_cast<std::string>(value);
    } else if (value.getType() == XmlRpc::XmlRpcValue::TypeInt) {
      text << static_cast<int>(value);
    } else {
      text.precision(17);
      text << static_cast<double>(value);
    }
    setCvoParam(params_, name, text.str());
  }
  override(pnh_, "min_points", &cloud_options_.selector.min_points);
  override(pnh_, "max_points", &cloud_options_.selector.max_points);
  override(pnh_, "min_depth", &cloud_options_.min_depth);
  override(pnh_, "max_depth", &cloud_options_.max_depth);
  override(pnh_, "crop_top_rows", &cloud_options_.crop_top_rows);
  override(pnh_, "image_levels", &cloud_options_.image_levels);
  std::string selector;
  if (pnh_.getParam("point_selector", selector)) {
    cloud_options_.selector.kind = parseSelectorKind(selector);
  }
  pnh_.param("use_segmentation", use_segmentation_, false);
  pnh_.param("semantic_classes", cloud_options_.semantic_classes, 0);
  pnh_.param("ignore_classes", cloud_options_.ignore_classes, cloud_options_.ignore_classes);
  if (use_segmentation_ && cloud_options_.semantic_classes < 1) {
    throw std::invalid_argument("use_segmentation needs semantic_classes >= 1");
  }
  if (!use_segmentation_) cloud_options_.semantic_classes = 0;
  pnh_.param<std::string>("odom_frame", odom_frame_, odom_frame_);
  pnh_.param<std::string>("base_frame", base_frame_, base_frame_);
  pnh_.param("publish_tf", publish_tf_, publish_tf_);
  pnh_.param("depth_units_per_metre", depth_units_per_metre_, depth_units_per_metre_);
  pnh_.param<std::string>("trajectory_file", trajectory_file_, "");
  pnh_.param("max_path_poses", max_path_poses_, max_path_poses_);
  if (max_path_poses_ < 1) throw std::invalid_argument("max_path_poses must be >= 1");
  pnh_.param("inject_backend_fault_after", inject_backend_fault_after_, -1);
  pnh_.param("expected_rate_min", min_rate_, min_rate_);
  pnh_.param("expected_rate_max", max_rate_, max_rate_);
  params_.validate();
  cloud_options_.validate();
  makeCloudBuilders();
}

void CvoOdometryRos::makeCloudBuilders() {
  const CloudBuilderOptions cloud = frontendOptionsFor(cloud_options_, params_);
  RgbdFrontendOptions rgbd;
  rgbd.depth_units_per_metre = depth_units_per_metre_;
  rgbd.cloud = cloud;
  rgbd_builder_ = std::make_unique<RgbdCloudBuilder>(rgbd);
  StereoFrontendOptions stereo;
  stereo.cloud = cloud;
  stereo_builder_ = std::make_unique<StereoCloudBuilder>(stereo);
}

void CvoOdometryRos::subscribe() {
  int queue = 10;
  pnh_.param("queue_size", queue, queue);
  double frame_interval = 0.0;
  pnh_.param("min_frame_interval", frame_interval, frame_interval);
  std::string policy_name = mode_ == Mode::kRgbd ? "ordered" : "exact";
  bool approximate = false;
  if (pnh_.getParam("approximate_sync", approximate)) {
    ROS_WARN(
        "cvo_odometry: approximate_sync is deprecated; use sync_policy (exact, approximate "
        "or ordered)");
    policy_name = approximate ? "approximate" : "exact";
  }
  pnh_.param("sync_policy", policy_name, policy_name);
  const SyncPolicy policy = parseSyncPolicy(policy_name);
  ROS_INFO_STREAM("cvo_odometry: sync_policy " << toString(policy) << ", queue_size " << queue);
  const image_transport::TransportHints hints("raw", ros::TransportHints(), pnh_);
  if (mode_ == Mode::kRgbd) {
    // camera_info is not synchronized: the latest one is used (it rarely changes), which keeps
    // the synchronization to the streams whose stamps really differ.
    rgb_info_sub_ = nh_.subscribe<sensor_msgs::CameraInfo>(
        "rgb/camera_info", 1, [this](const sensor_msgs::CameraInfoConstPtr& info) {
          std::lock_guard<std::mutex> lock(info_mutex_);
          rgb_info_ = info;
        });
    RgbdSyncOptions options;
    options.policy = policy;
    options.queue_size = queue;
    options.min_frame_interval = frame_interval;
    pnh_.param("sync_tolerance", options.tolerance, options.tolerance);
    options.with_labels = use_segmentation_;
    rgbd_sync_ = std::make_unique<RgbdTopicSync>(
        it_, hints, options,
        [this](const sensor_msgs::ImageConstPtr& image, const sensor_msgs::ImageConstPtr& depth,
               const sensor_msgs::ImageConstPtr& labels) {
          onRgbdWithLabels(image, depth, labels);
        });
    return;
  }
  auto image = [&](const std::string& topic) {
    auto filter = std::make_shared<image_transport::SubscriberFilter>(it_, topic, queue, hints);
    filters_.push_back(filter);
    return filter;
  };
  auto info = [&](const std::string& topic) {
    auto filter =
        std::make_shared<message_filters::Subscriber<sensor_msgs::CameraInfo>>(nh_, topic, queue);
    filters_.push_back(filter);
    return filter;
  };
  auto left = image("left/image_rect");
  countArrivals(*left);
  auto left_info = info("left/camera_info");
  if (mode_ == Mode::kStereo) {
    auto right = image("right/image_rect");
    auto right_info = info("right/camera_info");
    sync_ = synchronize(policy, queue, frame_interval, &CvoOdometryRos::onStereoImages, this, *left,
                        *left_info, *right, *right_info);
  } else {
    auto disparity = std::make_shared<message_filters::Subscriber<stereo_msgs::DisparityImage>>(
        nh_, "disparity", queue);
    filters_.push_back(disparity);
    sync_ = synchronize(policy, queue, frame_interval, &CvoOdometryRos::onStereoDisparity, this,
                        *left, *left_info, *disparity);
  }
}

void CvoOdometryRos::countArrivals(image_transport::SubscriberFilter& images) {
  // Frames that arrive but never come out of the synchronizer are counted in diagnostics.
  images.registerCallback(boost::function<void(const sensor_msgs::ImageConstPtr&)>(
      [this](const sensor_msgs::ImageConstPtr&) { ++arrived_; }));
}

void CvoOdometryRos::onRgbdWithLabels(const sensor_msgs::ImageConstPtr& image,
                                      const sensor_msgs::ImageConstPtr& depth,
                                      const sensor_msgs::ImageConstPtr& labels) {
  sensor_msgs::CameraInfoConstPtr info;
  {
    std::lock_guard<std::mutex> lock(info_mutex_);
    info = rgb_info_;
  }
  if (!info) {
    std::lock_guard<std::mutex> lock(mutex_);
    skipFrame("no rgb/camera_info received yet");
    return;
  }
  onRgbd(image, info, depth, labels);
}

void CvoOdometryRos::onStereoImages(const sensor_msgs::ImageConstPtr& left,
                                    const sensor_msgs::CameraInfoConstPtr& info,
                                    const sensor_msgs::ImageConstPtr& right,
                                    const sensor_msgs::CameraInfoConstPtr& right_info) {
  onStereo(left, info, right, right_info, nullptr);
}

void CvoOdometryRos::onStereoDisparity(const sensor_msgs::ImageConstPtr& left,
                                       const sensor_msgs::CameraInfoConstPtr& info,
                                       const stereo_msgs::DisparityImageConstPtr& disparity) {
  onStereo(left, info, nullptr, nullptr, disparity);
}

void CvoOdometryRos::onRgbd(const sensor_msgs::ImageConstPtr& image,
                            const sensor_msgs::CameraInfoConstPtr& info,
                            const sensor_msgs::ImageConstPtr& depth,
                            const sensor_msgs::ImageConstPtr& labels) {
  std::lock_guard<std::mutex> lock(mutex_);
  applyPendingConfig();
  RgbdFrame frame;
  try {
    frame.image = colorImageFromMsg(*image);
    frame.depth = depthImageFromMsg(*depth);
    frame.intrinsics = intrinsicsFromCameraInfo(*info);
    if (labels) frame.semantics = labelImageFromMsg(*labels);
  } catch (const std::invalid_argument& e) {
    skipFrame(e.what());
    return;
  }
  std_msgs::Header header = depth->header;  // the pose is stamped with the depth time
  header.frame_id =
      image->header.frame_id.empty() ? depth->header.frame_id : image->header.frame_id;
  buildAndProcess(header, [&](FrontendStats* stats) { return rgbd_builder_->build(frame, stats); });
}

void CvoOdometryRos::onStereo(const sensor_msgs::ImageConstPtr& left,
                              const sensor_msgs::CameraInfoConstPtr& info,
                              const sensor_msgs::ImageConstPtr& right,
                              const sensor_msgs::CameraInfoConstPtr& right_info,
                              const stereo_msgs::DisparityImageConstPtr& disparity) {
  std::lock_guard<std::mutex> lock(mutex_);
  applyPendingConfig();
  StereoFrame frame;
  try {
    frame.left = colorImageFromMsg(*left);
    frame.intrinsics = intrinsicsFromCameraInfo(*info);
    if (disparity) {
      frame.disparity = disparityImageFromMsg(*disparity);
      frame.baseline = disparity->T;
    } else {
      frame.right = colorImageFromMsg(*right);
      frame.baseline = stereoBaseline(*info, *right_info);
    }
  } catch (const std::invalid_argument& e) {
    skipFrame(e.what());
    return;
  }
  buildAndProcess(left->header,
                  [&](FrontendStats* stats) { return stereo_builder_->build(frame, stats); });
}

void CvoOdometryRos::buildAndProcess(const std_msgs::Header& header,
                                     const std::function<LabeledCloud(FrontendStats*)>& build) {
  FrontendStats stats;
  try {
    process(header, build(&stats), "", stats);
  } catch (const EmptyFrameError& e) {
    // Well-formed but nothing to track (no valid depth): a lost frame, reported as such.
    process(header, std::nullopt, e.what(), stats);
  } catch (const std::invalid_argument& e) {
    skipFrame(e.what());  // inconsistent input (sizes, calibration): not a frame at all
  }
}

void CvoOdometryRos::process(const std_msgs::Header& header, std::optional<LabeledCloud> cloud,
                             const std::string& why_no_cloud, const FrontendStats& stats) {
  if (last_stamp_ && header.stamp < *last_stamp_) {
    resetState("time went backwards (" + std::to_string(header.stamp.toSec()) + " after " +
               std::to_string(last_stamp_->toSec()) + " s): a looping bag? odometry reset");
  } else if (last_stamp_ && header.stamp == *last_stamp_) {
    skipFrame("a second frame with stamp " + std::to_string(header.stamp.toSec()));
    return;
  }
  if (!base_from_camera_) base_from_camera_ = baseFromCamera(header.frame_id);
  // The reference is replaced when the frame is good: copy it only for a subscriber.
  std::optional<LabeledCloud> reference;
  if (odometry_->referenceCloud() && previous_cloud_pub_.getNumSubscribers() > 0) {
    reference = *odometry_->referenceCloud();
  }
  OdometryUpdate update;
  try {
    update = cloud ? odometry_->process(header.stamp.toSec(), *cloud)
                   : odometry_->processLostFrame(header.stamp.toSec(), why_no_cloud);
  } catch (const std::invalid_argument& e) {
    skipFrame(std::string("registration rejected the frame: ") + e.what());
    return;
  }
  last_stamp_ = header.stamp;
  ++frames_;
  count(update);
  publish(header, update, cloud ? &*cloud : nullptr, stats);
  if (reference) {
    std_msgs::Header reference_header = header;
    reference_header.stamp = ros::Time(update.stamp - update.dt);
    previous_cloud_pub_.publish(
        cloudToMsg(*reference, Eigen::Isometry3f::Identity(), reference_header));
  }
}

void CvoOdometryRos::count(const OdometryUpdate& update) {
  switch (update.state) {
    case TrackingState::kRecovered:
      ++recovered_;
      break;
    case TrackingState::kLost:
      ++lost_;
      break;
    case TrackingState::kReset:
      ++lost_;
      ++tracking_resets_;
      break;
    default:
      break;
  }
  lost_now_ = update.state == TrackingState::kLost || update.state == TrackingState::kReset;
  if (lost_now_) lost_problem_ = update.problem;
  if (!update.problem.empty()) {
    last_problem_ = toString(update.state) + ": " + update.problem;
    ROS_WARN_STREAM_THROTTLE(
        2.0, "cvo_odometry: frame " << toString(update.state) << ": " << update.problem);
  }
  if (!update.report.warning.empty()) {
    ++backend_fallbacks_;
    ROS_WARN_STREAM_THROTTLE(5.0, "cvo_odometry: " << update.report.warning);
  }
}

void CvoOdometryRos::publish(const std_msgs::Header& header, const OdometryUpdate& update,
                             const LabeledCloud* cloud, const FrontendStats& stats) {
  const Eigen::Isometry3d& base_T_camera = *base_from_camera_;
  const Eigen::Isometry3d pose = base_T_camera * update.pose * base_T_camera.inverse();
  const Eigen::Isometry3d motion = base_T_camera * update.motion * base_T_camera.inverse();
  const bool trusted = update.trusted();

  // Motion covariance in the base frame, accumulated along the path (dead reckoning). A motion
  // that was guessed (lost frame, reset) is known only to the plausible maxima.
  Eigen::Matrix<double, 6, 6> motion_covariance = Eigen::Matrix<double, 6, 6>::Zero();
  if (!update.firstFrame()) {
    Eigen::Matrix<double, 6, 6> rotate = Eigen::Matrix<double, 6, 6>::Zero();
    rotate.topLeftCorner<3, 3>() = rotate.bottomRightCorner<3, 3>() = base_T_camera.rotation();
    const Eigen::Matrix<double, 6, 6> camera_covariance =
        trusted && cloud ? registrationCovariance(*cloud, update.motion,
                                                  update.report.final_lengthscale, update.cosine)
                         : guessedMotionCovariance(params_, update.dt);
    motion_covariance = rotate * camera_covariance * rotate.transpose();
    pose_covariance_ += motion_covariance;
  }

  cvo_odometry::CvoIndicator indicator;
  indicator.header.stamp = header.stamp;
  indicator.header.frame_id = odom_frame_;
  indicator.first_frame = update.firstFrame();
  indicator.state = toString(update.state);
  indicator.trusted = trusted;
  indicator.published = update.has_pose;
  indicator.lost_frames = static_cast<uint32_t>(update.lost_frames);
  indicator.attempts = static_cast<uint8_t>(update.attempts);
  indicator.problem = update.problem;
  indicator.indicator = update.report.indicator_after;
  indicator.indicator_before = update.report.indicator_before;
  indicator.cosine = update.firstFrame() ? 1.0 : update.cosine;
  indicator.iterations = update.report.iterations;
  indicator.initial_lengthscale = update.report.initial_lengthscale;
  indicator.final_lengthscale = update.report.final_lengthscale;
  indicator.converged = update.firstFrame() || update.report.converged;
  indicator.photometric_applied = update.photometric.applied;
  indicator.photometric_correction_deg = update.photometric.correction_deg;
  indicator.photometric_skipped = update.photometric.skipped;
  indicator.registration_ms = update.report.time_ms;
  indicator.frontend_ms = stats.time_ms;
  indicator.source_points = static_cast<uint32_t>(cloud ? cloud->size() : 0);
  indicator.target_points = static_cast<uint32_t>(update.reference_points);
  indicator.backend = update.report.backend;
  indicator.message = update.firstFrame() ? "first frame"
                      : !update.report.warning.empty()
                          ? update.report.message + "; " + update.report.warning
                          : update.report.message;
  indicator_pub_.publish(indicator);
  if (!update.has_pose) return;  // lost_frame_policy publish_nothing

  nav_msgs::Odometry odom;
  odom.header.stamp = header.stamp;
  odom.header.frame_id = odom_frame_;
  odom.child_frame_id = base_frame_;
  odom.pose.pose = toPoseMsg(pose);
  if (!update.firstFrame() && update.dt > 0.0) {
    // The motion since the reference frame over its interval, in the base frame.
    const Eigen::Vector3d omega = lie::logSO3(motion.rotation());
    odom.twist.twist.linear.x = motion.translation().x() / update.dt;
    odom.twist.twist.linear.y = motion.translation().y() / update.dt;
    odom.twist.twist.linear.z = motion.translation().z() / update.dt;
    odom.twist.twist.angular.x = omega.x() / update.dt;
    odom.twist.twist.angular.y = omega.y() / update.dt;
    odom.twist.twist.angular.z = omega.z() / update.dt;
  }
  for (int r = 0; r < 6; ++r) {
    for (int c = 0; c < 6; ++c) {
      odom.pose.covariance[6 * r + c] = pose_covariance_(r, c);
      odom.twist.covariance[6 * r + c] =
          update.dt > 0.0 ? motion_covariance(r, c) / (update.dt * update.dt) : 0.0;
    }
  }
  odom_pub_.publish(odom);
  rate_diagnostic_->tick();

  if (publish_tf_) {
    geometry_msgs::TransformStamped tf;
    tf.header = odom.header;
    tf.child_frame_id = base_frame_;
    tf.transform = toTransformMsg(pose);
    tf_broadcaster_.sendTransform(tf);
  }

  geometry_msgs::PoseStamped stamped;
  stamped.header = odom.header;
  stamped.pose = odom.pose.pose;
  path_.header = odom.header;
  path_.poses.push_back(stamped);
  // Bounded: a long run must not grow memory or the message without limit.
  if (path_.poses.size() > static_cast<std::size_t>(max_path_poses_)) {
    path_.poses.erase(path_.poses.begin(),
                      path_.poses.end() - static_cast<std::ptrdiff_t>(max_path_poses_));
  }
  if (!trajectory_file_.empty()) trajectory_.append(header.stamp.toSec(), pose);
  if (path_pub_.getNumSubscribers() > 0) path_pub_.publish(path_);
  if (cloud) publishDebugClouds(header, update, *cloud);
}

void CvoOdometryRos::publishDebugClouds(const std_msgs::Header& header,
                                        const OdometryUpdate& update, const LabeledCloud& cloud) {
  if (current_cloud_pub_.getNumSubscribers() > 0) {
    current_cloud_pub_.publish(cloudToMsg(cloud, Eigen::Isometry3f::Identity(), header));
  }
  // The current cloud moved into the previous camera frame: it should overlay cloud/previous.
  if (!update.firstFrame() && aligned_cloud_pub_.getNumSubscribers() > 0) {
    aligned_cloud_pub_.publish(cloudToMsg(cloud, update.motion.cast<float>(), header));
  }
}

void CvoOdometryRos::skipFrame(const std::string& why) {
  ++skipped_;
  last_problem_ = why;
  ROS_WARN_STREAM_THROTTLE(2.0, "cvo_odometry: frame skipped: " << why);
}

void CvoOdometryRos::resetState(const std::string& why) {
  ROS_WARN_STREAM("cvo_odometry: " << why);
  odometry_->reset();
  last_stamp_.reset();
  pose_covariance_.setZero();
  path_.poses.clear();
  trajectory_ = Trajectory();
  lost_now_ = false;
  ++resets_;
}

bool CvoOdometryRos::onReset(std_srvs::Empty::Request&, std_srvs::Empty::Response&) {
  std::lock_guard<std::mutex> lock(mutex_);
  resetState("reset requested: the next frame starts a new odometry");
  return true;
}

void CvoOdometryRos::onReconfigure(CvoOdometryConfig& config, uint32_t) {
  CvoParams next = params_;
  next.ell_init = config.ell_init, next.ell_min = config.ell_min;
  next.ell_first_frame = config.ell_first_frame, next.schedule_decay = config.schedule_decay;
  next.sigma = config.sigma, next.sp_thres = config.sp_thres;
  next.use_color = config.use_color, next.color_ell = config.color_ell;
  next.color_sigma = config.color_sigma, next.use_semantics = config.use_semantics;
  next.semantic_ell = config.semantic_ell, next.semantic_sigma = config.semantic_sigma;
  next.max_iterations = config.max_iterations, next.min_step = config.min_step;
  next.max_step = config.max_step;
  next.min_cosine = config.min_cosine;
  next.min_tracking_points = config.min_tracking_points;
  next.max_linear_speed = config.max_linear_speed;
  next.max_angular_speed = config.max_angular_speed;
  next.max_lost_frames = config.max_lost_frames;
  next.photometric_rotation = config.photometric_rotation;
  next.photometric_iterations = config.photometric_iterations;
  next.photometric_max_correction = config.photometric_max_correction;
  CloudBuilderOptions cloud = cloud_options_;
  cloud.selector.min_points = config.min_points;
  cloud.selector.max_points = config.max_points;
  try {
    next.backend = parseBackendChoice(config.backend);
    next.lost_frame_policy = parseLostFramePolicy(config.lost_frame_policy);
    next.validate();
    cloud.validate();
  } catch (const std::invalid_argument& e) {
    ROS_ERROR_STREAM("cvo_odometry: reconfigure rejected: " << e.what());
    return;
  }
  std::lock_guard<std::mutex> lock(mutex_);
  pending_params_ = next;
  pending_cloud_options_ = cloud;
}

void CvoOdometryRos::applyPendingConfig() {
  bool new_builders = false;
  if (pending_cloud_options_) {
    const auto& next = *pending_cloud_options_;
    new_builders = next.selector.min_points != cloud_options_.selector.min_points ||
                   next.selector.max_points != cloud_options_.selector.max_points;
    cloud_options_ = next;
    pending_cloud_options_.reset();
  }
  if (pending_params_) {
    const bool new_backend = pending_params_->backend != params_.backend;
    // The front end attaches the grey image levels only while the photometric stage is on.
    new_builders |= pending_params_->photometric_rotation != params_.photometric_rotation;
    params_ = *pending_params_;
    pending_params_.reset();
    if (new_backend) {
      makeOdometry();
      resetState("backend now " + odometry_->registration().backend().name() +
                 "; odometry restarted");
    } else {
      odometry_->setParams(params_);
    }
    ROS_INFO_STREAM("cvo_odometry: parameters updated:\n" << describe(params_, cloud_options_));
  }
  if (new_builders) makeCloudBuilders();
}

void CvoOdometryRos::makeOdometry() {
  std::string why_cpu;
  std::unique_ptr<RegistrationBackend> backend =
      makeBackend(params_.backend, params_.num_threads, &why_cpu);
  if (!why_cpu.empty()) ROS_INFO_STREAM("cvo_odometry: " << why_cpu);
  if (inject_backend_fault_after_ >= 0) {
    // Test hook: the backend fails from then on, as a GPU lost mid-run; the CPU takes over.
    ROS_WARN_STREAM("cvo_odometry: the backend will fail after " << inject_backend_fault_after_
                                                                 << " evaluations (test hook)");
    backend = std::make_unique<FailoverBackend>(
        std::make_unique<FaultInjectionBackend>(std::move(backend), inject_backend_fault_after_),
        std::make_unique<CpuBackend>(params_.num_threads));
  }
  odometry_ = std::make_unique<FrameToFrameOdometry>(params_, std::move(backend));
}

Eigen::Isometry3d CvoOdometryRos::baseFromCamera(const std::string& camera_frame) {
  if (camera_frame.empty() || camera_frame == base_frame_) return Eigen::Isometry3d::Identity();
  try {
    const auto tf =
        tf_buffer_.lookupTransform(base_frame_, camera_frame, ros::Time(0), ros::Duration(0.5));
    return fromTransformMsg(tf.transform);
  } catch (const tf2::TransformException& e) {
    ROS_WARN_STREAM("cvo_odometry: no transform " << base_frame_ << " <- " << camera_frame << " ("
                                                  << e.what()
                                                  << "); using identity: odometry of the camera");
    return Eigen::Isometry3d::Identity();
  }
}

void CvoOdometryRos::diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) {
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
  status.add("frames", frames_);
  status.add("skipped frames", skipped_);
  const std::size_t handled = frames_ + skipped_;
  const std::size_t arrived = rgbd_sync_ ? rgbd_sync_->arrived() : arrived_.load();
  status.add("frames not synchronized", arrived > handled ? arrived - handled : 0);
  if (const auto offset = rgbd_sync_ ? rgbd_sync_->learnedOffset() : std::nullopt) {
    status.add("depth - colour stamp offset (ms)", *offset * 1000.0);
  }
  status.add("lost frames", lost_);
  status.add("recovered frames", recovered_);
  status.add("tracking restarts", tracking_resets_);
  status.add("backend fallbacks", backend_fallbacks_);
  status.add("resets", resets_);
  status.add("backend", odometry_->registration().backend().name());
  if (mode_ == Mode::kRgbd) {
    // The stamp of the latest rgb/camera_info (it is not synchronized with the images): shows
    // that one arrives, and lets a test wait until the nodelet has the one it sent.
    std::lock_guard<std::mutex> info_lock(info_mutex_);
    char stamp[32] = "none yet";
    if (rgb_info_) std::snprintf(stamp, sizeof stamp, "%.3f", rgb_info_->header.stamp.toSec());
    status.add("latest camera_info stamp", std::string(stamp));
  }
  last_problem_.clear();
}

}  // namespace cvo
