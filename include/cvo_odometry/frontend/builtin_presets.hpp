// The presets of config/, compiled in, so that the tools and the nodelet find them by name
// (tum_rgbd, kitti_stereo) wherever they run; a path to a preset file works too.
#pragma once

#include <map>
#include <string>

#include "cvo_odometry/frontend/odometry_settings.hpp"

namespace cvo {

// Preset name (the file name without .yaml) -> its text.
const std::map<std::string, std::string>& builtInPresets();

// Applies the preset `name_or_path` (a built-in name or a file) to `settings` and validates;
// FormatError names the preset and line of a bad key or value, std::runtime_error an unknown
// name or unreadable file.
void applyPreset(const std::string& name_or_path, OdometrySettings* settings);

}  // namespace cvo
