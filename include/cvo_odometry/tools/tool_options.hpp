// Options the command-line tools share: CVO parameters (--preset, --backend, --set k=v,...), the
// front ends (point selection, depth and stereo options) and the recorded sequence to read
// (--tum DIR or --kitti DIR).
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "cvo_odometry/core/trajectory_io.hpp"
#include "cvo_odometry/frontend/odometry_pipeline.hpp"
#include "cvo_odometry/frontend/odometry_settings.hpp"
#include "cvo_odometry/tools/command_line.hpp"

namespace cvo {

// The settings in effect: the defaults with the dataset format's own (the TUM depth scale), then
// the preset (--preset, or the dataset's: kitti_stereo for
// --kitti), then --set k=v,..., then --NAME VALUE for single settings. Throws
// std::invalid_argument / FormatError naming a bad option or value.
OdometrySettings settingsFrom(const CommandLine& cli);

// The option names the helpers here read: the tools' own and one per setting.
std::vector<std::string> sharedOptionNames();
std::string sharedOptionsUsage();

// A recorded sequence ready to run: frame stamps and a cloud builder per frame.
struct SequenceInput {
  std::string kind;  // "tum" or "kitti"
  std::vector<double> stamps;
  std::function<CameraFrame(std::size_t index)> frame;  // decoded images of frame `index`
  TrajectoryFormat trajectory_format = TrajectoryFormat::kTum;
  std::string times_path;  // KITTI: times.txt, which stamps KITTI-format ground truth
};

// From --tum DIR (with --camera, --stamp depth|rgb) or --kitti DIR (with --kitti-camera 0|2);
// --segmentation DIR and --semantic-classes N add a segmentation image per frame.
SequenceInput openSequence(const CommandLine& cli);

// The labeled cloud of one frame by the front end of `settings`.
LabeledCloud buildCloud(const OdometrySettings& settings, const CameraFrame& frame);

}  // namespace cvo
