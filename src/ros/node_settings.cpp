#include "cvo_odometry/ros/node_settings.hpp"

#include <sstream>
#include <stdexcept>

#include "cvo_odometry/core/lie_group.hpp"
#include "cvo_odometry/frontend/builtin_presets.hpp"

namespace cvo {

const std::vector<EnumName<CameraMode>>& enumNames(CameraMode) {
  static const std::vector<EnumName<CameraMode>> names{{CameraMode::kRgbd, "rgbd"},
                                                       {CameraMode::kStereo, "stereo"},
                                                       {CameraMode::kDisparity, "disparity"}};
  return names;
}

void NodeOptions::validate() const {
  if (odom_frame.empty() || base_frame.empty() || odom_frame == base_frame) {
    throw std::invalid_argument("odom_frame and base_frame must be two different names");
  }
  for (const auto& [name, values] : {std::pair{"initial_pose", &initial_pose},
                                     std::pair{"camera_transform", &camera_transform}}) {
    if (!values->empty() && values->size() != 6) {
      throw std::invalid_argument(std::string(name) +
                                  " needs x, y, z, roll, pitch, yaw (6 numbers), got " +
                                  std::to_string(values->size()));
    }
  }
  if (sync_policy == SyncPolicy::kOrdered && mode != CameraMode::kRgbd) {
    throw std::invalid_argument("sync_policy ordered is for RGB-D; use exact or approximate");
  }
}

void NodeSettings::validate() const {
  odometry.validate();
  node.validate();
  if (node.use_segmentation && odometry.cloud.semantic_classes < 1) {
    throw std::invalid_argument("use_segmentation needs semantic_classes >= 1");
  }
}

namespace {

// A ROS parameter's value in the settings table's text form.
std::string parameterText(const XmlRpc::XmlRpcValue& value) {
  std::ostringstream text;
  text.precision(17);
  switch (value.getType()) {
    case XmlRpc::XmlRpcValue::TypeBoolean:
      return static_cast<bool>(value) ? "true" : "false";
    case XmlRpc::XmlRpcValue::TypeString:
      return static_cast<std::string>(value);
    case XmlRpc::XmlRpcValue::TypeInt:
      return std::to_string(static_cast<int>(value));
    case XmlRpc::XmlRpcValue::TypeDouble:
      text << static_cast<double>(value);
      return text.str();
    case XmlRpc::XmlRpcValue::TypeArray: {
      for (int k = 0; k < value.size(); ++k)
        text << (k ? "," : "") << parameterText(value[k]);
      return text.str();
    }
    default:
      throw std::invalid_argument("a number, boolean, string or list was expected");
  }
}

}  // namespace

NodeSettings readNodeSettings(const ros::NodeHandle& pnh) {
  NodeSettings settings;
  const auto read = [&](const std::string& name) {
    XmlRpc::XmlRpcValue value;
    if (!pnh.getParam(name, value)) return;
    try {
      setSetting(settings, name, parameterText(value));
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument("parameter " + pnh.resolveName(name) + ": " + e.what());
    }
  };
  read("mode");
  read("preset");
  const std::string preset = !settings.node.preset.empty()             ? settings.node.preset
                             : settings.node.mode != CameraMode::kRgbd ? "kitti_stereo"
                                                                       : "";
  if (!preset.empty()) applyPreset(preset, &settings.odometry);
  for (const auto& row : settingRows(settings))
    read(row.name);
  settings.validate();
  return settings;
}

Eigen::Isometry3d poseFromXyzRpy(const std::vector<double>& p) {
  if (p.size() != 6) return Eigen::Isometry3d::Identity();
  return lie::fromXyzRpy(p[0], p[1], p[2], p[3], p[4], p[5]);
}

Eigen::Isometry3d initialPose(const NodeOptions& options) {
  return poseFromXyzRpy(options.initial_pose);
}

}  // namespace cvo
