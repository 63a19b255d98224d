// Conversions between ROS messages and the core / front-end types. Every function that reads a
// message throws std::invalid_argument naming what is wrong with it.
#pragma once

#include <geometry_msgs/Pose.h>
#include <geometry_msgs/Transform.h>
#include <geometry_msgs/TransformStamped.h>
#include <nav_msgs/Odometry.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/PointCloud2.h>
#include <stereo_msgs/DisparityImage.h>
#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "cvo_odometry/CvoIndicator.h"
#include "cvo_odometry/core/labeled_cloud.hpp"
#include "cvo_odometry/frontend/odometry_pipeline.hpp"
#include "cvo_odometry/frontend/pinhole_intrinsics.hpp"

namespace cvo {

// Rectified intrinsics from P (K when P is unset: an unrectified camera, with D as plumb_bob
// distortion). Throws for an all-zero, non-finite or size-less camera_info.
PinholeIntrinsics intrinsicsFromCameraInfo(const sensor_msgs::CameraInfo& info);

// Baseline (m) of a rectified pair from the right camera's P (Tx = -fx * baseline).
double stereoBaseline(const sensor_msgs::CameraInfo& left, const sensor_msgs::CameraInfo& right);

// 8-bit BGR or grey image of a colour or mono image (bgr8, rgb8, bgra8, rgba8, mono8).
cv::Mat colorImageFromMsg(const sensor_msgs::Image& msg);
// Depth as sent: 16UC1 / mono16 (millimetres) or 32FC1 (metres).
cv::Mat depthImageFromMsg(const sensor_msgs::Image& msg);
// Segmentation: 8/16-bit class ids (mono8, mono16, 8UC1, 16UC1) or 32FC<N> probabilities.
cv::Mat labelImageFromMsg(const sensor_msgs::Image& msg);
// The 32FC1 disparity (pixels) of stereo_image_proc's DisparityImage.
cv::Mat disparityImageFromMsg(const stereo_msgs::DisparityImage& msg);

// A pipeline frame from the synchronized messages (labels may be null; right and right_info are
// null with a disparity image, disparity null without; stereo labels are the left image's).
// Throws std::invalid_argument naming what is wrong with a message.
CameraFrame rgbdFrameFromMsgs(const sensor_msgs::Image& image, const sensor_msgs::CameraInfo& info,
                              const sensor_msgs::Image& depth, const sensor_msgs::Image* labels);
CameraFrame stereoFrameFromMsgs(const sensor_msgs::Image& left,
                                const sensor_msgs::CameraInfo& left_info,
                                const sensor_msgs::Image* right,
                                const sensor_msgs::CameraInfo* right_info,
                                const stereo_msgs::DisparityImage* disparity,
                                const sensor_msgs::Image* labels = nullptr);

// base <- camera optical frame for a camera looking along the base's x axis (REP-103: the
// optical frame is z forward, x right, y down; the body frame x forward, y left, z up).
Eigen::Isometry3d opticalFrameInBase();

geometry_msgs::Pose toPoseMsg(const Eigen::Isometry3d& pose);
Eigen::Isometry3d fromPoseMsg(const geometry_msgs::Pose& pose);
geometry_msgs::Transform toTransformMsg(const Eigen::Isometry3d& pose);
Eigen::Isometry3d fromTransformMsg(const geometry_msgs::Transform& transform);

// The odometry of a processed frame: pose and covariance of the base in `odom_frame`, twist and
// its covariance in `base_frame` (REP-105).
nav_msgs::Odometry odometryMsg(const OdometryUpdate& update, const ros::Time& stamp,
                               const std::string& odom_frame, const std::string& base_frame);
// The TF odom_frame -> base_frame of the same.
geometry_msgs::TransformStamped odometryTransformMsg(const nav_msgs::Odometry& odometry);

// What the nodelet adds to a pipeline result for the indicator.
struct IndicatorExtras {
  double latency_ms = 0.0;
  std::size_t dropped_frames = 0;
};
cvo_odometry::CvoIndicator indicatorMsg(const PipelineResult& result, const ros::Time& stamp,
                                        const std::string& odom_frame,
                                        const IndicatorExtras& extras);

// x, y, z, rgb (packed float, as rviz reads it) and, with semantics, label (argmax class, uint16)
// of every point moved by `transform`.
sensor_msgs::PointCloud2 cloudToMsg(const LabeledCloud& cloud, const Eigen::Isometry3f& transform,
                                    const std_msgs::Header& header);

}  // namespace cvo
