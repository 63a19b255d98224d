// dynamic_reconfigure through the settings table: the server's config from settings, and
// settings from a config, by the names of cfg/CvoOdometry.cfg (each a table row: see the test
// that checks their defaults and ranges).
#pragma once

#include "cvo_odometry/CvoOdometryConfig.h"
#include "cvo_odometry/ros/node_settings.hpp"

namespace cvo {

cvo_odometry::CvoOdometryConfig toConfig(const NodeSettings& settings);

// `settings` with the config's values, validated; throws std::invalid_argument naming the value
// refused (the settings given are then unchanged).
NodeSettings applyConfig(const cvo_odometry::CvoOdometryConfig& config, NodeSettings settings);

}  // namespace cvo
