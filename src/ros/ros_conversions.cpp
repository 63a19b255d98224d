#include "cvo_odometry/ros/ros_conversions.hpp"

#include <algorithm>
#include <cmath>
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

}  // namespace cvo
