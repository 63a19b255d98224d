#include "cvo_odometry/tools/tool_options.hpp"

#include <memory>
#include <sstream>
#include <stdexcept>

#include <opencv2/imgcodecs.hpp>

#include "cvo_odometry/frontend/builtin_presets.hpp"
#include "cvo_odometry/frontend/dataset_files.hpp"
#include "cvo_odometry/frontend/kitti_sequence.hpp"
#include "cvo_odometry/frontend/seven_scenes_sequence.hpp"
#include "cvo_odometry/frontend/tum_sequence.hpp"

namespace cvo {

namespace {

const char* const kToolOptionsUsage =
    "  --preset NAME|FILE      parameters: a built-in preset (tum_rgbd, kitti_stereo) or a file;\n"
    "                          default: the dataset's (--kitti: kitti_stereo, else tum_rgbd)\n"
    "  --set k=v[,k=v...]      override parameters (any name of README \"Parameters\")\n"
    "  --NAME VALUE            the same for one parameter, '_' written '-' (--min-points 5000)\n"
    "  --tum DIR               TUM RGB-D folder (associations.txt or rgb.txt + depth.txt;\n"
    "                          depth PNGs 5000 per metre)\n"
    "  --kitti DIR             KITTI odometry folder (calib.txt, times.txt, image_0/1)\n"
    "    --kitti-camera 0|2    grey (image_0/1) or colour (image_2/3) pair (0)\n"
    "  --7scenes DIR           7-Scenes sequence (frame-NNNNNN.color|depth|pose; depth in mm,\n"
    "                          the poses are the ground truth)\n"
    "    --camera NAME         fr1 | fr2 | fr3 | fx,fy,cx,cy[,k1,k2,p1,p2,k3][,width,height]\n"
    "                          (TUM: fr1; 7-Scenes: 585,585,320,240); size from the images\n"
    "    --stamp depth|rgb     TUM: which image time stamps the pose (depth)\n"
    "  --segmentation DIR      segmentation images (with --semantic-classes N)\n";

std::string optionName(const std::string& setting) {
  std::string name = setting;
  for (char& c : name)
    if (c == '_') c = '-';
  return name;
}

std::string datasetKind(const CommandLine& cli) {
  const int given = cli.has("tum") + cli.has("kitti") + cli.has("7scenes");
  if (given != 1)
    throw std::invalid_argument("give one sequence: --tum DIR, --kitti DIR or --7scenes DIR");
  return cli.has("tum") ? "tum" : cli.has("kitti") ? "kitti" : "7scenes";
}

// A path of the dataset: relative ones are below the dataset folder.
std::string datasetPath(const std::string& folder, const std::string& path) {
  return path.empty() || path.front() == '/' ? path : folder + "/" + path;
}

// fr1, fr2, fr3 or numbers; without a size in `name`, the size of the image `sample`.
PinholeIntrinsics cameraIntrinsics(const std::string& name, const cv::Mat& sample) {
  if (name == "fr1" || name == "fr2" || name == "fr3") {
    return tumIntrinsics(name, sample.cols, sample.rows);
  }
  std::vector<double> v;
  std::stringstream items(name);
  std::string item;
  while (std::getline(items, item, ','))
    v.push_back(parseSettingNumber("--camera", item));
  const bool sized = v.size() == 6 || v.size() == 11;
  const int width = sized ? static_cast<int>(v[v.size() - 2]) : sample.cols;
  const int height = sized ? static_cast<int>(v.back()) : sample.rows;
  if (v.size() != 4 && v.size() != 6 && v.size() != 9 && v.size() != 11) {
    throw std::invalid_argument("--camera '" + name +
                                "': fr1, fr2, fr3 or fx,fy,cx,cy[,k1,k2,p1,p2,k3][,width,height]");
  }
  PinholeIntrinsics K;
  K.fx = v[0], K.fy = v[1], K.cx = v[2], K.cy = v[3];
  if (v.size() >= 9) K.distortion.assign(v.begin() + 4, v.begin() + 9);
  K.width = width, K.height = height;
  K.validate();
  return K;
}

}  // namespace

std::string sharedOptionsUsage() {
  return kToolOptionsUsage;
}

std::vector<std::string> sharedOptionNames() {
  std::vector<std::string> names{"preset", "set",          "tum",     "camera",      "stamp",
                                 "kitti",  "kitti-camera", "7scenes", "segmentation"};
  for (const auto& row : settingRows(OdometrySettings()))
    names.push_back(optionName(row.name));
  return names;
}

OdometrySettings settingsFrom(const CommandLine& cli, std::string* preset_note) {
  const std::string kind = datasetKind(cli);
  OdometrySettings settings;
  // The formats' own depth scales (TUM PNGs 5000 per metre, 7-Scenes millimetres).
  if (kind == "tum") settings.depth_scale = 5000.0;
  if (kind == "7scenes") settings.depth_scale = SevenScenesSequence::kDepthScale;
  const std::string fallback = kind == "kitti" ? "kitti_stereo" : "tum_rgbd";
  const std::string preset = cli.get("preset", fallback);
  applyPreset(preset, &settings);
  if (preset_note) {
    *preset_note =
        "preset " + preset +
        (cli.has("preset") ? "" : " (the default for --" + kind + "; --preset to change)");
  }
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

SequenceInput openSequence(const CommandLine& cli) {
  SequenceInput input;
  input.kind = datasetKind(cli);
  const std::string folder = cli.get(input.kind);
  const std::string segmentation = datasetPath(folder, cli.get("segmentation"));
  if (!segmentation.empty() && !fileExists(segmentation + "/.")) {
    throw std::invalid_argument("--segmentation: no folder '" + segmentation + "'");
  }
  const auto labelsOf = [segmentation](const std::string& colour_relative) {
    return segmentation.empty() ? cv::Mat() : readSegmentation(segmentation, colour_relative);
  };
  if (input.kind == "tum") {
    auto sequence = std::make_shared<TumSequence>(folder);
    cv::Mat image, depth;
    sequence->load(0, &image, &depth);
    const PinholeIntrinsics intrinsics = cameraIntrinsics(cli.get("camera", "fr1"), image);
    const std::string stamp = cli.get("stamp", "depth");
    if (stamp != "depth" && stamp != "rgb") throw std::invalid_argument("--stamp: depth or rgb");
    for (const auto& f : sequence->frames())
      input.stamps.push_back(stamp == "depth" ? f.depth_stamp : f.rgb_stamp);
    input.frame = [sequence, intrinsics, labelsOf](std::size_t k) {
      RgbdFrame frame;
      frame.intrinsics = intrinsics;
      sequence->load(k, &frame.image, &frame.depth);
      frame.semantics = labelsOf(sequence->frames()[k].rgb_listed);
      frame.depth_after_colour =
          sequence->frames()[k].depth_stamp - sequence->frames()[k].rgb_stamp;
      return CameraFrame(frame);
    };
    return input;
  }
  if (input.kind == "7scenes") {
    auto sequence = std::make_shared<SevenScenesSequence>(folder);
    cv::Mat image, depth;
    sequence->load(0, &image, &depth);
    const PinholeIntrinsics intrinsics = cli.has("camera")
                                             ? cameraIntrinsics(cli.get("camera"), image)
                                             : sevenScenesIntrinsics(image.cols, image.rows);
    for (std::size_t k = 0; k < sequence->size(); ++k)
      input.stamps.push_back(sequence->stamp(k));
    input.ground_truth = sequence->groundTruth();
    input.frame = [sequence, intrinsics, labelsOf](std::size_t k) {
      RgbdFrame frame;
      frame.intrinsics = intrinsics;
      sequence->load(k, &frame.image, &frame.depth);
      frame.semantics = labelsOf(sequence->colourName(k));
      return CameraFrame(frame);
    };
    return input;
  }
  const int camera = cli.getInt("kitti-camera", 0);
  auto sequence = std::make_shared<KittiSequence>(folder, camera);
  input.stamps = sequence->stamps();
  input.trajectory_format = TrajectoryFormat::kKitti;
  input.times_path = folder + "/times.txt";
  const std::string left_dir = "image_" + std::to_string(camera);
  input.frame = [sequence, labelsOf, left_dir](std::size_t k) {
    StereoFrame frame;
    sequence->load(k, &frame.left, &frame.right, nullptr);
    frame.intrinsics = sequence->calibration().left;
    frame.baseline = sequence->calibration().baseline;
    frame.semantics = labelsOf(left_dir + "/" + sequence->imageName(k));
    return CameraFrame(frame);
  };
  return input;
}

cv::Mat readSegmentation(const std::string& dir, const std::string& colour_relative) {
  const std::string name = colour_relative.substr(colour_relative.find_last_of('/') + 1);
  for (const std::string& candidate : {dir + "/" + colour_relative, dir + "/" + name}) {
    if (!fileExists(candidate)) continue;
    cv::Mat labels = cv::imread(candidate, cv::IMREAD_UNCHANGED);
    if (labels.empty()) throw std::runtime_error("cannot read segmentation '" + candidate + "'");
    return labels;
  }
  throw std::runtime_error("no segmentation image for '" + colour_relative + "': neither " + dir +
                           "/" + colour_relative + " nor " + dir + "/" + name);
}

LabeledCloud buildCloud(const OdometrySettings& settings, const CameraFrame& frame) {
  if (const auto* rgbd = std::get_if<RgbdFrame>(&frame)) {
    return RgbdCloudBuilder(settings.rgbdOptions()).build(*rgbd);
  }
  return StereoCloudBuilder(settings.stereoOptions()).build(std::get<StereoFrame>(frame));
}

}  // namespace cvo
