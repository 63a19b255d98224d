#include "cvo_odometry/ros/ros_conversions.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <stdexcept>

#include <cv_bridge/cv_bridge.h>
#include <sensor_msgs/image_encodings.h>
#include <sensor_msgs/point_cloud2_iterator.h>
#include <opencv2/imgproc.hpp>

namespace cvo {

namespace enc = sensor_msgs::image_encodings;

namespace {

void checkImage(const sensor_msgs::Image& msg, const char* what) {
  if (msg.width == 0 || msg.height == 0 || msg.data.empty()) {
    throw std::invalid_argument(std::string(what) + " image is empty");
  }
  if (msg.step < msg.width || msg.data.size() < static_cast<std::size_t>(msg.step) * msg.height) {
    throw std::invalid_argument(std::string(what) + " image data is shorter than height * step");
  }
}

cv::Mat copyToMat(const sensor_msgs::Image& msg, const char* what) {
  try {
    return cv_bridge::toCvCopy(msg)->image;
  } catch (const cv_bridge::Exception& e) {
    throw std::invalid_argument(std::string(what) + " image: " + e.what());
  }
}

}  // namespace

PinholeIntrinsics intrinsicsFromCameraInfo(const sensor_msgs::CameraInfo& info) {
  PinholeIntrinsics K;
  K.width = static_cast<int>(info.width);
  K.height = static_cast<int>(info.height);
  const auto finite = [](const auto& values) {
    return std::all_of(values.begin(), values.end(), [](double v) { return std::isfinite(v); });
  };
  if (!finite(info.K) || !finite(info.P) || !finite(info.D)) {
    throw std::invalid_argument("camera_info has non-finite values in K, P or D");
  }
  if (info.P[0] > 0.0) {
    K.fx = info.P[0], K.fy = info.P[5], K.cx = info.P[2], K.cy = info.P[6];
  } else if (info.K[0] > 0.0) {
    K.fx = info.K[0], K.fy = info.K[4], K.cx = info.K[2], K.cy = info.K[5];
    if (std::any_of(info.D.begin(), info.D.end(), [](double d) { return d != 0.0; })) {
      if (info.distortion_model != "plumb_bob" && info.distortion_model != "rational_polynomial") {
        throw std::invalid_argument("camera_info distortion model '" + info.distortion_model +
                                    "' is not supported (plumb_bob or rational_polynomial)");
      }
      K.distortion.assign(info.D.begin(), info.D.end());
    }
  } else {
    throw std::invalid_argument("camera_info has no calibration (K and P are zero)");
  }
  K.validate();
  return K;
}

double stereoBaseline(const sensor_msgs::CameraInfo& left, const sensor_msgs::CameraInfo& right) {
  if (!(right.P[0] > 0.0)) throw std::invalid_argument("right camera_info has no P");
  const double baseline = (left.P[3] - right.P[3]) / right.P[0];
  if (!(baseline > 0.0) || !std::isfinite(baseline)) {
    throw std::invalid_argument("right camera_info P gives baseline " + std::to_string(baseline) +
                                " m; expected a rectified pair with the right camera at +x");
  }
  return baseline;
}

cv::Mat colorImageFromMsg(const sensor_msgs::Image& msg) {
  checkImage(msg, "colour");
  const std::string& e = msg.encoding;
  if (e != enc::BGR8 && e != enc::RGB8 && e != enc::BGRA8 && e != enc::RGBA8 && e != enc::MONO8) {
    throw std::invalid_argument("colour image encoding '" + e +
                                "' is not supported (bgr8, rgb8, bgra8, rgba8 or mono8)");
  }
  try {
    const std::string target = e == enc::MONO8 ? enc::MONO8 : enc::BGR8;
    return cv_bridge::toCvCopy(msg, target)->image;
  } catch (const cv_bridge::Exception& ex) {
    throw std::invalid_argument(std::string("colour image: ") + ex.what());
  }
}

cv::Mat depthImageFromMsg(const sensor_msgs::Image& msg) {
  checkImage(msg, "depth");
  const std::string& e = msg.encoding;
  if (e != enc::TYPE_16UC1 && e != enc::MONO16 && e != enc::TYPE_32FC1) {
    throw std::invalid_argument("depth image encoding '" + e +
                                "' is not supported (16UC1 millimetres or 32FC1 metres)");
  }
  return copyToMat(msg, "depth");
}

cv::Mat labelImageFromMsg(const sensor_msgs::Image& msg) {
  checkImage(msg, "segmentation");
  const std::string& e = msg.encoding;
  const bool ids =
      e == enc::MONO8 || e == enc::MONO16 || e == enc::TYPE_8UC1 || e == enc::TYPE_16UC1;
  const bool probabilities = e.rfind("32FC", 0) == 0;
  if (!ids && !probabilities) {
    throw std::invalid_argument("segmentation encoding '" + e +
                                "' is not supported (8/16-bit class ids or 32FC<N>)");
  }
  return copyToMat(msg, "segmentation");
}

cv::Mat disparityImageFromMsg(const stereo_msgs::DisparityImage& msg) {
  checkImage(msg.image, "disparity");
  if (msg.image.encoding != enc::TYPE_32FC1) {
    throw std::invalid_argument("disparity image encoding '" + msg.image.encoding +
                                "' is not 32FC1");
  }
  return copyToMat(msg.image, "disparity");
}

CameraFrame rgbdFrameFromMsgs(const sensor_msgs::Image& image, const sensor_msgs::CameraInfo& info,
                              const sensor_msgs::Image& depth, const sensor_msgs::Image* labels) {
  RgbdFrame frame;
  frame.image = colorImageFromMsg(image);
  frame.depth = depthImageFromMsg(depth);
  frame.intrinsics = intrinsicsFromCameraInfo(info);
  if (labels) frame.semantics = labelImageFromMsg(*labels);
  // The labels are the colour image's: a moving object's depth lies off them by this much of
  // its motion.
  frame.depth_after_colour = (depth.header.stamp - image.header.stamp).toSec();
  return frame;
}

CameraFrame stereoFrameFromMsgs(const sensor_msgs::Image& left,
                                const sensor_msgs::CameraInfo& left_info,
                                const sensor_msgs::Image* right,
                                const sensor_msgs::CameraInfo* right_info,
                                const stereo_msgs::DisparityImage* disparity,
                                const sensor_msgs::Image* labels) {
  StereoFrame frame;
  frame.left = colorImageFromMsg(left);
  frame.intrinsics = intrinsicsFromCameraInfo(left_info);
  if (labels) frame.semantics = labelImageFromMsg(*labels);
  if (disparity) {
    frame.disparity = disparityImageFromMsg(*disparity);
    frame.baseline = disparity->T;
  } else {
    if (!right || !right_info) throw std::invalid_argument("no right image and no disparity");
    frame.right = colorImageFromMsg(*right);
    frame.baseline = stereoBaseline(left_info, *right_info);
  }
  return frame;
}

Eigen::Isometry3d opticalFrameInBase() {
  Eigen::Isometry3d base_from_optical = Eigen::Isometry3d::Identity();
  base_from_optical.linear() << 0, 0, 1,  // base x: optical z
      -1, 0, 0,                           // base y: optical -x
      0, -1, 0;                           // base z: optical -y
  return base_from_optical;
}

Eigen::Isometry3d fromPoseMsg(const geometry_msgs::Pose& p) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation() << p.position.x, p.position.y, p.position.z;
  const Eigen::Quaterniond q(p.orientation.w, p.orientation.x, p.orientation.y, p.orientation.z);
  if (!(q.norm() > 1e-9) || !pose.translation().allFinite()) {
    throw std::invalid_argument("the pose has no valid orientation or position");
  }
  pose.linear() = q.normalized().toRotationMatrix();
  return pose;
}

geometry_msgs::Pose toPoseMsg(const Eigen::Isometry3d& pose) {
  geometry_msgs::Pose msg;
  msg.position.x = pose.translation().x();
  msg.position.y = pose.translation().y();
  msg.position.z = pose.translation().z();
  const Eigen::Quaterniond q(pose.rotation());
  msg.orientation.x = q.x();
  msg.orientation.y = q.y();
  msg.orientation.z = q.z();
  msg.orientation.w = q.w();
  return msg;
}

geometry_msgs::Transform toTransformMsg(const Eigen::Isometry3d& pose) {
  const geometry_msgs::Pose p = toPoseMsg(pose);
  geometry_msgs::Transform msg;
  msg.translation.x = p.position.x;
  msg.translation.y = p.position.y;
  msg.translation.z = p.position.z;
  msg.rotation = p.orientation;
  return msg;
}

Eigen::Isometry3d fromTransformMsg(const geometry_msgs::Transform& t) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation() << t.translation.x, t.translation.y, t.translation.z;
  pose.linear() = Eigen::Quaterniond(t.rotation.w, t.rotation.x, t.rotation.y, t.rotation.z)
                      .normalized()
                      .toRotationMatrix();
  return pose;
}

sensor_msgs::PointCloud2 cloudToMsg(const LabeledCloud& cloud, const Eigen::Isometry3f& transform,
                                    const std_msgs::Header& header) {
  sensor_msgs::PointCloud2 msg;
  msg.header = header;
  sensor_msgs::PointCloud2Modifier modifier(msg);
  const bool labels = cloud.semanticClasses() > 0;
  if (labels) {
    modifier.setPointCloud2Fields(
        5, "x", 1, sensor_msgs::PointField::FLOAT32, "y", 1, sensor_msgs::PointField::FLOAT32, "z",
        1, sensor_msgs::PointField::FLOAT32, "rgb", 1, sensor_msgs::PointField::FLOAT32, "label", 1,
        sensor_msgs::PointField::UINT16);
  } else {
    modifier.setPointCloud2FieldsByString(2, "xyz", "rgb");
  }
  modifier.resize(cloud.size());
  sensor_msgs::PointCloud2Iterator<float> x(msg, "x"), y(msg, "y"), z(msg, "z");
  sensor_msgs::PointCloud2Iterator<std::uint8_t> rgb(msg, "rgb");  // b, g, r, a bytes
  for (std::size_t i = 0; i < cloud.size(); ++i, ++x, ++y, ++z, ++rgb) {
    const Eigen::Vector3f p = transform * cloud.position(i);
    *x = p.x(), *y = p.y(), *z = p.z();
    for (int c = 0; c < 3; ++c) {
      const float value = cloud.hasColor() ? cloud.color(i)[c] : 1.0f;  // features hold B, G, R
      rgb[c] = static_cast<std::uint8_t>(std::clamp(value, 0.0f, 1.0f) * 255.0f + 0.5f);
    }
    rgb[3] = 255;
  }
  if (labels) {
    sensor_msgs::PointCloud2Iterator<std::uint16_t> label(msg, "label");
    for (std::size_t i = 0; i < cloud.size(); ++i, ++label) {
      const float* p = cloud.semantics(i);
      *label = static_cast<std::uint16_t>(std::max_element(p, p + cloud.semanticClasses()) - p);
    }
  }
  return msg;
}

nav_msgs::Odometry odometryMsg(const OdometryUpdate& update, const ros::Time& stamp,
                               const std::string& odom_frame, const std::string& base_frame) {
  nav_msgs::Odometry odom;
  odom.header.stamp = stamp;
  odom.header.frame_id = odom_frame;
  odom.child_frame_id = base_frame;
  odom.pose.pose = toPoseMsg(update.base_pose);
  const Vector6d twist = update.baseTwist();
  odom.twist.twist.linear.x = twist[0];
  odom.twist.twist.linear.y = twist[1];
  odom.twist.twist.linear.z = twist[2];
  odom.twist.twist.angular.x = twist[3];
  odom.twist.twist.angular.y = twist[4];
  odom.twist.twist.angular.z = twist[5];
  for (int r = 0; r < 6; ++r) {
    for (int c = 0; c < 6; ++c) {
      odom.pose.covariance[6 * r + c] = update.pose_covariance(r, c);
      odom.twist.covariance[6 * r + c] = update.twist_covariance(r, c);
    }
  }
  return odom;
}

geometry_msgs::TransformStamped odometryTransformMsg(const nav_msgs::Odometry& odometry) {
  geometry_msgs::TransformStamped tf;
  tf.header = odometry.header;
  tf.child_frame_id = odometry.child_frame_id;
  tf.transform.translation.x = odometry.pose.pose.position.x;
  tf.transform.translation.y = odometry.pose.pose.position.y;
  tf.transform.translation.z = odometry.pose.pose.position.z;
  tf.transform.rotation = odometry.pose.pose.orientation;
  return tf;
}

cvo_odometry::CvoIndicator indicatorMsg(const PipelineResult& result, const ros::Time& stamp,
                                        const std::string& odom_frame,
                                        const IndicatorExtras& extras) {
  const OdometryUpdate& update = result.update;
  cvo_odometry::CvoIndicator indicator;
  indicator.header.stamp = stamp;
  indicator.header.frame_id = odom_frame;
  indicator.first_frame = update.firstFrame();
  indicator.state = toString(update.state);
  indicator.trusted = update.trusted();
  indicator.published = update.has_pose;
  indicator.lost_frames = static_cast<uint32_t>(update.lost_frames);
  indicator.attempts = static_cast<uint8_t>(update.attempts);
  indicator.problem = update.problem;
  indicator.guess = toString(update.guess);
  if (result.prior) {
    indicator.prior_tracks = static_cast<uint32_t>(result.prior->tracks);
    indicator.prior_inliers = static_cast<uint32_t>(result.prior->inliers);
    indicator.prior_inlier_ratio = result.prior->inlier_ratio;
    indicator.prior_problem = result.prior->problem;
    indicator.prior_ms = result.prior->time_ms;
  }
  indicator.track_agreement = update.track_agreement;
  indicator.track_error_px = update.track_error_px;
  indicator.track_rotation_gap_deg = update.track_rotation_gap_deg;
  indicator.second_motion_tracks =
      static_cast<std::uint32_t>(std::max(update.second_motion_tracks, 0));
  indicator.motion_split = update.motion_split;
  indicator.left_out_share = update.left_out_share;
  indicator.new_keyframe = update.new_keyframe;
  indicator.reference_stamp = update.stamp - update.dt;
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
  indicator.photometric_tracks = static_cast<uint32_t>(update.photometric.tracks);
  indicator.registration_ms = update.report.time_ms;
  indicator.frontend_ms = result.stats.time_ms;
  indicator.total_ms = result.total_ms;
  indicator.latency_ms = extras.latency_ms;
  indicator.dropped_frames = static_cast<uint32_t>(extras.dropped_frames);
  indicator.source_points = static_cast<uint32_t>(result.cloud ? result.cloud->size() : 0);
  indicator.target_points = static_cast<uint32_t>(update.reference_points);
  indicator.backend = update.report.backend;
  indicator.message = update.firstFrame() ? "first frame"
                      : !update.report.warning.empty()
                          ? update.report.message + "; " + update.report.warning
                          : update.report.message;
  return indicator;
}

}  // namespace cvo
