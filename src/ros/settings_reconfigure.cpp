#include "cvo_odometry/ros/settings_reconfigure.hpp"

#include <dynamic_reconfigure/config_tools.h>

namespace cvo {

using cvo_odometry::CvoOdometryConfig;

cvo_odometry::CvoOdometryConfig toConfig(const NodeSettings& settings) {
  dynamic_reconfigure::Config msg;
  for (const auto& description : CvoOdometryConfig::__getParamDescriptions__()) {
    const std::string& name = description->name;
    const std::string text = settingValue(settings, name);
    const SettingInfo info{name.c_str(), "", ""};
    if (description->type == "double") {
      double value = 0.0;
      parseSettingText(info, text, value);
      dynamic_reconfigure::ConfigTools::appendParameter(msg, name, value);
    } else if (description->type == "int") {
      int value = 0;
      parseSettingText(info, text, value);
      dynamic_reconfigure::ConfigTools::appendParameter(msg, name, value);
    } else if (description->type == "bool") {
      bool value = false;
      parseSettingText(info, text, value);
      dynamic_reconfigure::ConfigTools::appendParameter(msg, name, value);
    } else {
      dynamic_reconfigure::ConfigTools::appendParameter(msg, name, text);
    }
  }
  CvoOdometryConfig config = CvoOdometryConfig::__getDefault__();
  config.__fromMessage__(msg);
  return config;
}

NodeSettings applyConfig(const cvo_odometry::CvoOdometryConfig& config, NodeSettings settings) {
  dynamic_reconfigure::Config msg;
  config.__toMessage__(msg);
  for (const auto& p : msg.bools)
    setSetting(settings, p.name, p.value ? "true" : "false");
  for (const auto& p : msg.ints)
    setSetting(settings, p.name, std::to_string(p.value));
  for (const auto& p : msg.doubles)
    setSetting(settings, p.name, settingText(p.value));
  for (const auto& p : msg.strs)
    setSetting(settings, p.name, p.value);
  settings.validate();
  return settings;
}

}  // namespace cvo
