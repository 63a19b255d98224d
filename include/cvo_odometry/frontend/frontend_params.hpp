// The front end's keys in the flat YAML presets of config/ (beside the CVO parameters; the same
// keys the nodelet reads as ROS parameters): point_selector, min_points, max_points, min_depth,
// max_depth, crop_top_rows.
#pragma once

#include <string>
#include <vector>

#include "cvo_odometry/frontend/depth_cloud_builder.hpp"

namespace cvo {

std::vector<std::string> frontendParamNames();

// Throws std::invalid_argument for an unknown key or a bad value.
void setFrontendParam(CloudBuilderOptions& options, const std::string& key,
                      const std::string& value);

// Applies the front-end keys of a preset file (CVO keys skipped) and validates; FormatError
// names the file and line of a bad value.
void loadFrontendParams(const std::string& path, CloudBuilderOptions* options);

}  // namespace cvo
