#include "cvo_odometry/tools/tool_options.hpp"

#include <memory>
#include <sstream>
#include <stdexcept>

#include <opencv2/imgcodecs.hpp>

#include "cvo_odometry/core/params_io.hpp"
#include "cvo_odometry/frontend/frontend_params.hpp"
#include "cvo_odometry/frontend/kitti_sequence.hpp"
#include "cvo_odometry/frontend/tum_sequence.hpp"

namespace cvo {

const char* const kSharedOptionsUsage =
    "  --preset FILE           CVO parameters (config/tum_rgbd.yaml, config/kitti_stereo.yaml)\n"
    "  --set k=v[,k=v...]      override parameters of the preset\n"
    "  --backend auto|cpu|cuda|device_cpu\n"
    "  --tum DIR               TUM RGB-D folder (associations.txt or rgb.txt + depth.txt)\n"
    "    --camera NAME         fr1 | fr2 | fr3 | fx,fy,cx,cy[,k1,k2,p1,p2,k3] (fr1)\n"
    "    --depth-scale N       depth PNG units per metre (5000)\n"
    "    --stamp depth|rgb     which image time stamps the pose (depth)\n"
    "  --kitti DIR             KITTI odometry folder (calib.txt, times.txt, image_0/1)\n"
    "    --kitti-camera 0|2    grey (image_0/1) or colour (image_2/3) pair (0)\n"
    "    --crop-top N          rows at the top never used (KITTI 100)\n"
    "    --num-disparities N --block-size N --sgbm-mode sgbm|hh|sgbm_3way   matching\n"
    "  --min-depth M --max-depth M   depth range (TUM 0.1..10, KITTI 1..55)\n"
    "  --selector fast|grid|mixed   point selection (preset's point_selector, else fast)\n"
    "  --min-points N --max-points N   selected point range (3000, 15000)\n"
    "  --segmentation DIR --semantic-classes N [--ignore-classes a,b]   segmentation images\n";

std::vector<std::string> sharedOptionNames() {
  return {"preset",          "set",        "backend",    "tum",          "camera",
          "depth-scale",     "stamp",      "kitti",      "kitti-camera", "crop-top",
          "num-disparities", "block-size", "sgbm-mode",  "min-depth",    "max-depth",
          "selector",        "min-points", "max-points", "segmentation", "semantic-classes",
          "ignore-classes"};
}

CvoParams cvoParamsFrom(const CommandLine& cli) {
  CvoParams params;
  if (cli.has("preset")) params = loadCvoParams(cli.get("preset"), params);
  if (cli.has("backend")) params.backend = parseBackendChoice(cli.get("backend"));
  std::stringstream overrides(cli.get("set"));
  std::string item;
  while (std::getline(overrides, item, ',')) {
    const auto eq = item.find('=');
    if (eq == std::string::npos) {
      throw std::invalid_argument("--set expects key=value, got '" + item + "'");
    }
    setCvoParam(params, item.substr(0, eq), item.substr(eq + 1));
  }
  params.validate();
  return params;
}

namespace {

// Preset values first, then the command line's.
void readCloudOptions(const CommandLine& cli, CloudBuilderOptions* cloud) {
  if (cli.has("preset")) loadFrontendParams(cli.get("preset"), cloud);
  cloud->min_depth = cli.getDouble("min-depth", cloud->min_depth);
  cloud->max_depth = cli.getDouble("max-depth", cloud->max_depth);
  if (cli.has("selector")) cloud->selector.kind = parseSelectorKind(cli.get("selector"));
  cloud->selector.min_points = cli.getInt("min-points", cloud->selector.min_points);
  cloud->selector.max_points = cli.getInt("max-points", cloud->selector.max_points);
  cloud->crop_top_rows = cli.getInt("crop-top", cloud->crop_top_rows);
  cloud->semantic_classes = cli.getInt("semantic-classes", 0);
  for (double c : cli.getDoubleList("ignore-classes", {}))
    cloud->ignore_classes.push_back(static_cast<int>(c));
  if (cloud->semantic_classes > 0 && !cli.has("segmentation")) {
    throw std::invalid_argument("--semantic-classes needs --segmentation DIR");
  }
  *cloud = frontendOptionsFor(*cloud, cvoParamsFrom(cli));
  cloud->validate();
}

cv::Mat readSegmentation(const std::string& folder, const std::string& image_path) {
  const std::string name = image_path.substr(image_path.find_last_of('/') + 1);
  cv::Mat segmentation = cv::imread(folder + "/" + name, cv::IMREAD_UNCHANGED);
  if (segmentation.empty()) {
    throw std::runtime_error("cannot read segmentation '" + folder + "/" + name + "'");
  }
  return segmentation;
}

}  // namespace

RgbdFrontendOptions rgbdFrontendOptionsFrom(const CommandLine& cli) {
  RgbdFrontendOptions options;
  options.depth_units_per_metre = cli.getDouble("depth-scale", 5000.0);  // TUM PNGs
  readCloudOptions(cli, &options.cloud);
  return options;
}

StereoFrontendOptions stereoFrontendOptionsFrom(const CommandLine& cli) {
  StereoFrontendOptions options = kittiStereoFrontendOptions();
  options.matcher.num_disparities = cli.getInt("num-disparities", options.matcher.num_disparities);
  options.matcher.block_size = cli.getInt("block-size", options.matcher.block_size);
  options.matcher.mode = cli.get("sgbm-mode", options.matcher.mode);
  readCloudOptions(cli, &options.cloud);
  return options;
}

SequenceInput openSequence(const CommandLine& cli) {
  if (cli.has("tum") == cli.has("kitti")) {
    throw std::invalid_argument("give one sequence: --tum DIR or --kitti DIR");
  }
  SequenceInput input;
  const std::string segmentation = cli.get("segmentation");
  if (cli.has("tum")) {
    auto sequence = std::make_shared<TumSequence>(cli.get("tum"));
    auto builder = std::make_shared<RgbdCloudBuilder>(rgbdFrontendOptionsFrom(cli));
    const PinholeIntrinsics intrinsics = tumIntrinsics(cli.get("camera", "fr1"));
    const std::string stamp = cli.get("stamp", "depth");
    if (stamp != "depth" && stamp != "rgb") throw std::invalid_argument("--stamp: depth or rgb");
    input.kind = "tum";
    for (const auto& f : sequence->frames())
      input.stamps.push_back(stamp == "depth" ? f.depth_stamp : f.rgb_stamp);
    input.cloud = [sequence, builder, intrinsics, segmentation](std::size_t k,
                                                                FrontendStats* stats) {
      RgbdFrame frame;
      frame.intrinsics = intrinsics;
      sequence->load(k, &frame.image, &frame.depth);
      if (!segmentation.empty()) {
        frame.semantics = readSegmentation(segmentation, sequence->frames()[k].rgb_path);
      }
      return builder->build(frame, stats);
    };
    return input;
  }
  auto sequence = std::make_shared<KittiSequence>(cli.get("kitti"), cli.getInt("kitti-camera", 0),
                                                  segmentation);
  auto builder = std::make_shared<StereoCloudBuilder>(stereoFrontendOptionsFrom(cli));
  input.kind = "kitti";
  input.stamps = sequence->stamps();
  input.trajectory_format = TrajectoryFormat::kKitti;
  input.times_path = cli.get("kitti") + "/times.txt";
  input.cloud = [sequence, builder](std::size_t k, FrontendStats* stats) {
    StereoFrame frame;
    sequence->load(k, &frame.left, &frame.right, &frame.semantics);
    frame.intrinsics = sequence->calibration().left;
    frame.baseline = sequence->calibration().baseline;
    return builder->build(frame, stats);
  };
  return input;
}

}  // namespace cvo
