#include "cvo_odometry/tools/tool_options.hpp"

#include <memory>
#include <sstream>
#include <stdexcept>

#include <opencv2/imgcodecs.hpp>

#include "cvo_odometry/frontend/builtin_presets.hpp"
#include "cvo_odometry/frontend/kitti_sequence.hpp"
#include "cvo_odometry/frontend/tum_sequence.hpp"

namespace cvo {

namespace {

const char* const kToolOptionsUsage =
    "  --preset NAME|FILE      parameters: a built-in preset (tum_rgbd, kitti_stereo) or a file;\n"
    "                          default: the one for the dataset (--kitti: kitti_stereo)\n"
    "  --set k=v[,k=v...]      override parameters (any name of README \"Parameters\")\n"
    "  --NAME VALUE            the same for one parameter, '_' written '-' (--min-points 5000)\n"
    "  --tum DIR               TUM RGB-D folder (associations.txt or rgb.txt + depth.txt)\n"
    "    --camera NAME         fr1 | fr2 | fr3 | fx,fy,cx,cy[,k1,k2,p1,p2,k3] (fr1)\n"
    "    --stamp depth|rgb     which image time stamps the pose (depth)\n"
    "  --kitti DIR             KITTI odometry folder (calib.txt, times.txt, image_0/1)\n"
    "    --kitti-camera 0|2    grey (image_0/1) or colour (image_2/3) pair (0)\n"
    "  --segmentation DIR      segmentation images (with --semantic-classes N)\n";

std::string optionName(const std::string& setting) {
  std::string name = setting;
  for (char& c : name)
    if (c == '_') c = '-';
  return name;
}

}  // namespace

std::string sharedOptionsUsage() {
  return kToolOptionsUsage;
}

std::vector<std::string> sharedOptionNames() {
  std::vector<std::string> names{"preset", "set",   "tum",          "camera",
                                 "stamp",  "kitti", "kitti-camera", "segmentation"};
  for (const auto& row : settingRows(OdometrySettings()))
    names.push_back(optionName(row.name));
  return names;
}

OdometrySettings settingsFrom(const CommandLine& cli) {
  OdometrySettings settings;
  if (cli.has("tum")) settings.depth_scale = 5000.0;  // the TUM format's depth PNGs
  const std::string preset = cli.get("preset", cli.has("kitti") ? "kitti_stereo" : "");
  if (!preset.empty()) applyPreset(preset, &settings);
  std::stringstream overrides(cli.get("set"));
  std::string item;
  while (std::getline(overrides, item, ',')) {
    const auto eq = item.find('=');
    if (eq == std::string::npos) {
      throw std::invalid_argument("--set expects key=value, got '" + item + "'");
    }
    setSetting(settings, item.substr(0, eq), item.substr(eq + 1));
  }
  for (const auto& row : settingRows(settings)) {
    const std::string option = optionName(row.name);
    if (cli.has(option)) setSetting(settings, row.name, cli.get(option));
  }
  if (settings.cloud.semantic_classes > 0 && !cli.has("segmentation")) {
    throw std::invalid_argument("semantic_classes needs --segmentation DIR");
  }
  settings.validate();
  return settings;
}

namespace {

cv::Mat readSegmentation(const std::string& folder, const std::string& image_path) {
  const std::string name = image_path.substr(image_path.find_last_of('/') + 1);
  cv::Mat segmentation = cv::imread(folder + "/" + name, cv::IMREAD_UNCHANGED);
  if (segmentation.empty()) {
    throw std::runtime_error("cannot read segmentation '" + folder + "/" + name + "'");
  }
  return segmentation;
}

}  // namespace

SequenceInput openSequence(const CommandLine& cli) {
  if (cli.has("tum") == cli.has("kitti")) {
    throw std::invalid_argument("give one sequence: --tum DIR or --kitti DIR");
  }
  SequenceInput input;
  const std::string segmentation = cli.get("segmentation");
  if (cli.has("tum")) {
    auto sequence = std::make_shared<TumSequence>(cli.get("tum"));
    const PinholeIntrinsics intrinsics = tumIntrinsics(cli.get("camera", "fr1"));
    const std::string stamp = cli.get("stamp", "depth");
    if (stamp != "depth" && stamp != "rgb") throw std::invalid_argument("--stamp: depth or rgb");
    input.kind = "tum";
    for (const auto& f : sequence->frames())
      input.stamps.push_back(stamp == "depth" ? f.depth_stamp : f.rgb_stamp);
    input.frame = [sequence, intrinsics, segmentation](std::size_t k) {
      RgbdFrame frame;
      frame.intrinsics = intrinsics;
      sequence->load(k, &frame.image, &frame.depth);
      if (!segmentation.empty()) {
        frame.semantics = readSegmentation(segmentation, sequence->frames()[k].rgb_path);
      }
      return CameraFrame(frame);
    };
    return input;
  }
  auto sequence = std::make_shared<KittiSequence>(cli.get("kitti"), cli.getInt("kitti-camera", 0),
                                                  segmentation);
  input.kind = "kitti";
  input.stamps = sequence->stamps();
  input.trajectory_format = TrajectoryFormat::kKitti;
  input.times_path = cli.get("kitti") + "/times.txt";
  input.frame = [sequence](std::size_t k) {
    StereoFrame frame;
    sequence->load(k, &frame.left, &frame.right, &frame.semantics);
    frame.intrinsics = sequence->calibration().left;
    frame.baseline = sequence->calibration().baseline;
    return CameraFrame(frame);
  };
  return input;
}

}  // namespace cvo

namespace cvo {

LabeledCloud buildCloud(const OdometrySettings& settings, const CameraFrame& frame) {
  if (const auto* rgbd = std::get_if<RgbdFrame>(&frame)) {
    return RgbdCloudBuilder(settings.rgbdOptions()).build(*rgbd);
  }
  return StereoCloudBuilder(settings.stereoOptions()).build(std::get<StereoFrame>(frame));
}

}  // namespace cvo
