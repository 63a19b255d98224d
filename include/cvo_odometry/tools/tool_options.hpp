// Options the command-line tools share: CVO parameters (--preset, --backend, --set k=v,...), the
// front ends (point selection, depth and stereo options) and the recorded sequence to read
// (--tum DIR or --kitti DIR).
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "cvo_odometry/core/cvo_params.hpp"
#include "cvo_odometry/core/trajectory_io.hpp"
#include "cvo_odometry/frontend/rgbd_cloud_builder.hpp"
#include "cvo_odometry/frontend/stereo_cloud_builder.hpp"
#include "cvo_odometry/tools/command_line.hpp"

namespace cvo {

// Throws std::invalid_argument for a malformed override or parameters that make no sense.
CvoParams cvoParamsFrom(const CommandLine& cli);
RgbdFrontendOptions rgbdFrontendOptionsFrom(const CommandLine& cli);
StereoFrontendOptions stereoFrontendOptionsFrom(const CommandLine& cli);

// The option names the helpers above and openSequence() read.
std::vector<std::string> sharedOptionNames();
extern const char* const kSharedOptionsUsage;

// A recorded sequence ready to run: frame stamps and a cloud builder per frame.
struct SequenceInput {
  std::string kind;  // "tum" or "kitti"
  std::vector<double> stamps;
  std::function<LabeledCloud(std::size_t index, FrontendStats* stats)> cloud;
  TrajectoryFormat trajectory_format = TrajectoryFormat::kTum;
  std::string times_path;  // KITTI: times.txt, which stamps KITTI-format ground truth
};

// From --tum DIR (with --camera, --stamp depth|rgb) or --kitti DIR (with --kitti-camera 0|2);
// --segmentation DIR and --semantic-classes N add a segmentation image per frame.
SequenceInput openSequence(const CommandLine& cli);

}  // namespace cvo
