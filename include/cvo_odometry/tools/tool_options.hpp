// Options the command-line tools share: the settings (--preset, --set k=v,..., --<name>), and the
// recorded sequence to read (--tum DIR, --kitti DIR or --7scenes DIR, laid out as their
// publishers ship them).
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "cvo_odometry/core/trajectory.hpp"
#include "cvo_odometry/core/trajectory_io.hpp"
#include "cvo_odometry/frontend/odometry_pipeline.hpp"
#include "cvo_odometry/frontend/odometry_settings.hpp"
#include "cvo_odometry/tools/command_line.hpp"

namespace cvo {

// The settings in effect: the defaults with the dataset format's own (its depth scale), then
// the preset (--preset, or the dataset's: kitti_stereo for --kitti, tum_rgbd otherwise), then
// --set k=v,..., then --NAME VALUE for single settings. Throws std::invalid_argument /
// FormatError naming a bad option or value. `preset_note`, when given, says which preset is in
// effect and why.
OdometrySettings settingsFrom(const CommandLine& cli, std::string* preset_note = nullptr);

// The option names the helpers here read: the tools' own and one per setting.
std::vector<std::string> sharedOptionNames();
std::string sharedOptionsUsage();

// A recorded sequence ready to run: frame stamps and the decoded images of each frame.
struct SequenceInput {
  std::string kind;  // "tum", "kitti" or "7scenes"
  std::vector<double> stamps;
  std::function<CameraFrame(std::size_t index)> frame;
  TrajectoryFormat trajectory_format = TrajectoryFormat::kTum;
  std::string times_path;   // KITTI: times.txt, which stamps KITTI-format ground truth
  Trajectory ground_truth;  // the dataset's own (7-Scenes pose files), else empty
};

// From --tum DIR (with --camera, --stamp depth|rgb), --kitti DIR (with --kitti-camera 0|2) or
// --7scenes DIR (with --camera); --segmentation DIR (relative to the dataset folder unless
// absolute) adds each frame's segmentation image, found by the colour image's path below the
// dataset folder, else its file name; a missing one is an error.
SequenceInput openSequence(const CommandLine& cli);

// The segmentation image of a frame: DIR/<colour path below the dataset folder>, else
// DIR/<colour file name>; a missing or unreadable one is an error naming both.
cv::Mat readSegmentation(const std::string& dir, const std::string& colour_relative);

// The labeled cloud of one frame by the front end of `settings`.
LabeledCloud buildCloud(const OdometrySettings& settings, const CameraFrame& frame);

}  // namespace cvo
