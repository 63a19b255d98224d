// The front end's keys in the flat YAML presets of config/ (beside the CVO parameters; the same
// keys the nodelet reads as ROS parameters). The list itself is core's frontendPresetKeys(),
// which the CVO preset reader skips.
#pragma once

#include <iosfwd>
#include <string>
#include <vector>

#include "cvo_odometry/core/cvo_params.hpp"
#include "cvo_odometry/frontend/depth_cloud_builder.hpp"

namespace cvo {

// Throws std::invalid_argument for an unknown key or a bad value.
void setFrontendParam(CloudBuilderOptions& options, const std::string& key,
                      const std::string& value);

// Applies the front-end keys of preset text (CVO keys skipped) and validates; FormatError names
// `source_name` and the line of a bad value.
void parseFrontendParams(std::istream& in, const std::string& source_name,
                         CloudBuilderOptions* options);
// Applies the front-end keys of a preset file (CVO keys skipped) and validates; FormatError
// names the file and line of a bad value.
void loadFrontendParams(const std::string& path, CloudBuilderOptions* options);

// The options a front end should run with for these CVO parameters: the grey image levels only
// when the photometric stage, their one user, is on (they cost a few ms a frame).
CloudBuilderOptions frontendOptionsFor(CloudBuilderOptions options, const CvoParams& params);

}  // namespace cvo
