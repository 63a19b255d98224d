// Options the command-line tools share: CVO parameters (--preset, --backend, --set k=v,...) and
// the RGB-D front end (--depth-scale, --selector, --min-points, --max-points).
#pragma once

#include "cvo_odometry/core/cvo_params.hpp"
#include "cvo_odometry/frontend/rgbd_cloud_builder.hpp"
#include "cvo_odometry/tools/command_line.hpp"

namespace cvo {

// Throws std::invalid_argument for a malformed override or parameters that make no sense.
CvoParams cvoParamsFrom(const CommandLine& cli);
RgbdFrontendOptions rgbdFrontendOptionsFrom(const CommandLine& cli);

}  // namespace cvo
