// The nodelet's rows of the settings table (settings_table.hpp) beside the odometry's: topics,
// frames, synchronization, latency, and how the nodelet starts; and reading them all from ROS
// parameters.
#pragma once

#include <string>
#include <vector>

#include <ros/node_handle.h>

#include "cvo_odometry/frontend/odometry_settings.hpp"
#include "cvo_odometry/ros/policy_synchronizer.hpp"

namespace cvo {

enum class CameraMode { kRgbd, kStereo, kDisparity };
const std::vector<EnumName<CameraMode>>& enumNames(CameraMode);

struct NodeOptions {
  CameraMode mode = CameraMode::kRgbd;
  std::string preset;  // "": the mode's (stereo, disparity: kitti_stereo)
  std::string odom_frame = "odom";
  std::string base_frame = "base_link";
  std::string camera_frame;  // "": the images' frame_id
  bool publish_tf = true;
  double tf_wait = 2.0;  // s
  std::vector<double> initial_pose;
  std::vector<double> camera_transform;  // [] : base <- camera from TF
  SyncPolicy sync_policy = SyncPolicy::kAuto;
  int queue_size = 5;
  double sync_tolerance = 0.0;
  double min_frame_interval = 0.0;
  bool process_every_frame = false;
  bool use_segmentation = false;
  std::string trajectory_file;
  int max_path_poses = 10000;
  int inject_backend_fault_after = -1;  // test hook: see README "GPU failures"

  void validate() const;
};

struct NodeSettings {
  OdometrySettings odometry;
  NodeOptions node;
  void validate() const;
};

template <class V>
void visitSettings(NodeSettings& s, V&& v) {
  NodeOptions& n = s.node;
  v(SettingInfo{"mode", "node",
                "rgbd (colour + depth), stereo (left + right, SGBM here) or disparity (left + "
                "stereo_msgs/DisparityImage)"},
    n.mode);
  v(SettingInfo{"preset", "node",
                "a built-in preset (tum_rgbd, kitti_stereo) or a file; \"\": the mode's"},
    n.preset);
  visitSettings(s.odometry, v);
  v(SettingInfo{"odom_frame", "frames", "the odometry's fixed frame (REP-105)"}, n.odom_frame);
  v(SettingInfo{"base_frame", "frames", "the robot's frame the odometry moves (REP-105)"},
    n.base_frame);
  v(SettingInfo{"camera_frame", "frames", "the camera's optical frame; \"\": the images' frame_id"},
    n.camera_frame);
  v(SettingInfo{"publish_tf", "frames", "broadcast odom_frame -> base_frame"}, n.publish_tf);
  v(SettingInfo{"tf_wait", "frames",
                "seconds to wait for base_frame <- camera at start and after a reset", 0.0, 600.0},
    n.tf_wait);
  v(SettingInfo{"initial_pose", "frames",
                "the base's pose in odom at start: x, y, z (m), roll, pitch, yaw (rad); [] origin",
                -1e6, 1e6},
    n.initial_pose);
  v(SettingInfo{"camera_transform", "frames",
                "the camera's optical frame in base_frame: x, y, z (m), roll, pitch, yaw (rad), "
                "used and published on /tf_static; [] from TF",
                -1e6, 1e6},
    n.camera_transform);
  v(SettingInfo{"sync_policy", "sync", "auto: ordered for RGB-D, exact for stereo"}, n.sync_policy);
  v(SettingInfo{"queue_size", "sync", "subscriber and synchronizer queues (frames)", 1, 1000},
    n.queue_size);
  v(SettingInfo{"sync_tolerance", "sync",
                "ordered: largest distance (s) of a depth stamp from colour + offset; 0: 0.4 "
                "frame period",
                0.0, 10.0},
    n.sync_tolerance);
  v(SettingInfo{"min_frame_interval", "sync",
                "approximate: the frame period's lower bound (s); 0: unknown", 0.0, 10.0},
    n.min_frame_interval);
  v(SettingInfo{"process_every_frame", "latency",
                "false (live): only the newest complete frame, older ones dropped and counted; "
                "true (bag replay): every frame, in order"},
    n.process_every_frame);
  v(SettingInfo{"use_segmentation", "semantics", "subscribe segmentation/image"},
    n.use_segmentation);
  v(SettingInfo{"trajectory_file", "output",
                "write the camera's trajectory (TUM format; the ground truth's frame) at shutdown"},
    n.trajectory_file);
  v(SettingInfo{"max_path_poses", "output", "the path topic keeps this many latest poses", 1,
                10000000},
    n.max_path_poses);
  v(SettingInfo{"inject_backend_fault_after", "test",
                "test hook: the backend fails after N evaluations (-1: off)", -1, 1000000000},
    n.inject_backend_fault_after);
}

// Defaults, then the preset (the `preset` parameter, else the mode's), then every private
// parameter of a table name. Throws std::invalid_argument / FormatError naming a bad one.
NodeSettings readNodeSettings(const ros::NodeHandle& pnh);

// x, y, z, roll, pitch, yaw (REP-103: fixed-axis roll about x, then pitch, then yaw) as a pose;
// identity when empty.
Eigen::Isometry3d poseFromXyzRpy(const std::vector<double>& xyz_rpy);

// The base's initial pose from NodeOptions::initial_pose (identity when empty).
Eigen::Isometry3d initialPose(const NodeOptions& options);

}  // namespace cvo
