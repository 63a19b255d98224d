// Conversions between ROS messages and the core / front-end types. Every function that reads a
// message throws std::invalid_argument naming what is wrong with it.
#pragma once

#include <geometry_msgs/Pose.h>
#include <geometry_msgs/Transform.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/PointCloud2.h>
#include <stereo_msgs/DisparityImage.h>
#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "cvo_odometry/core/labeled_cloud.hpp"
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

geometry_msgs::Pose toPoseMsg(const Eigen::Isometry3d& pose);
geometry_msgs::Transform toTransformMsg(const Eigen::Isometry3d& pose);
Eigen::Isometry3d fromTransformMsg(const geometry_msgs::Transform& transform);

// x, y, z, rgb (packed float, as rviz reads it) and, with semantics, label (argmax class, uint16)
// of every point moved by `transform`.
sensor_msgs::PointCloud2 cloudToMsg(const LabeledCloud& cloud, const Eigen::Isometry3f& transform,
                                    const std_msgs::Header& header);

}  // namespace cvo
