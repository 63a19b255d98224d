// cvo_make_dynamic: a recorded sequence with a moving object composited into it, and the object's
// exact labels (tools/moving_object.hpp): the dynamic-scene cases of bench/dynamic_table.sh.
// Writes a folder the runner and cvo_make_bag read like the original (TUM: rgb/, depth/,
// associations.txt, groundtruth.txt; KITTI: image_0/, image_1/, calib.txt, times.txt, poses.txt),
// the labels below labels/ (8-bit: the object's class, 0 elsewhere) and object.txt (per frame:
// the share of the image it covers and how far its centre moved, px). Made from such a folder,
// the objects before keep their labels where the new one leaves them in view.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <vector>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "cvo_odometry/core/trajectory_io.hpp"
#include "cvo_odometry/frontend/depth_conversion.hpp"
#include "cvo_odometry/frontend/kitti_sequence.hpp"
#include "cvo_odometry/frontend/tum_sequence.hpp"
#include "cvo_odometry/tools/command_line.hpp"
#include "cvo_odometry/tools/moving_object.hpp"

namespace {

namespace fs = std::filesystem;

const char* kUsage =
    "usage: cvo_make_dynamic (--tum DIR | --kitti DIR) --out DIR [object options]\n"
    "  a moving textured board composited into every frame, with its labels in OUT/labels\n"
    "  (run with --segmentation OUT/labels --semantic-classes 2 --ignore-classes 1); made from\n"
    "  such a folder, a second object, the first one's labels kept where it leaves them in view\n"
    "  --area F            share of the image it covers in the first frame (0.3)\n"
    "  --aspect A          width / height (0.75)\n"
    "  --depth Z           metres from the first camera (0.6); TUM: the scene hides it where\n"
    "                      nearer (its recorded depth); KITTI: painted over the scene\n"
    "  --start U,V         its centre in the first image, fractions of width and height "
    "(0.25,0.5)\n"
    "  --velocity X,Y,Z    m/s in the first camera's axes (x right, y down, z forward; "
    "0.25,0,0)\n"
    "  --with-camera       the velocity is relative to the moving camera (a car driving along)\n"
    "  --shape rect|ellipse\n"
    "  --texture plain|stripes|checker|blocks|scene   (blocks; scene: a mirrored crop of the\n"
    "                      first frame)\n"
    "  --seed N            texture seed (1)\n"
    "  --label N           its class id (1)\n"
    "  --label-error PX    > 0: the labels miss PX of its outline; < 0: they spill PX over (0)\n"
    "  --camera NAME       TUM intrinsics as for cvo_run_sequence (fr1)\n"
    "  --max-gap S         ground truth at most this far from a frame's stamp (0.05)\n"
    "  --labels-only       the labels of the object, the images left as recorded (the error of\n"
    "                      a labelled run with that part of the view hidden and nothing moving)\n";

struct Summary {
  std::vector<double> coverage;
  std::vector<double> flow;
  cv::Point2d last_centre{-1.0, -1.0};
  std::ofstream table;

  void add(double stamp, const cv::Mat& mask) {
    const double share = cv::countNonZero(mask) / static_cast<double>(mask.total());
    coverage.push_back(share);
    const cv::Moments m = cv::moments(mask, true);
    cv::Point2d centre(-1.0, -1.0);
    double moved = std::nan("");
    if (m.m00 > 0.0) {
      centre = cv::Point2d(m.m10 / m.m00, m.m01 / m.m00);
      if (last_centre.x >= 0.0) {
        moved = std::hypot(centre.x - last_centre.x, centre.y - last_centre.y);
        flow.push_back(moved);
      }
    }
    last_centre = centre;
    table << std::fixed << std::setprecision(6) << stamp << " " << std::setprecision(4) << share
          << " " << std::setprecision(1) << centre.x << " " << centre.y << " " << moved << "\n";
  }
};

double median(std::vector<double> v) {
  if (v.empty()) return std::nan("");
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

Eigen::Isometry3d poseAt(const cvo::Trajectory& truth, double stamp, double max_gap) {
  Eigen::Isometry3d pose;
  if (!truth.interpolate(stamp, max_gap, &pose)) {
    std::ostringstream why;
    why << std::fixed << std::setprecision(6) << "no ground truth within " << max_gap
        << " s of frame time " << stamp;
    throw std::runtime_error(why.str());
  }
  return pose;
}

void writeImage(const fs::path& path, const cv::Mat& image) {
  fs::create_directories(path.parent_path());
  if (!cv::imwrite(path.string(), image)) throw std::runtime_error("cannot write " + path.string());
}

// The frame's labels: those of the objects composited before (`earlier`, the source folder's
// labels, when it has them) where the new object does not cover them, and the new one's.
cv::Mat withEarlierLabels(const fs::path& earlier, const cv::Mat& labels, const cv::Mat& covered) {
  if (!fs::exists(earlier)) return labels;
  cv::Mat out = cv::imread(earlier.string(), cv::IMREAD_UNCHANGED);
  if (out.type() != CV_8UC1 || out.size() != labels.size()) {
    throw std::runtime_error(earlier.string() + ": not an 8-bit label image of the frames' size");
  }
  if (!covered.empty()) out.setTo(0, covered);
  labels.copyTo(out, labels);
  return out;
}

cvo::MovingObjectSpec specFrom(const cvo::CommandLine& cli) {
  cvo::MovingObjectSpec spec;
  spec.area = cli.getDouble("area", spec.area);
  spec.aspect = cli.getDouble("aspect", spec.aspect);
  spec.depth = cli.getDouble("depth", spec.depth);
  const std::vector<double> start = cli.getDoubleList("start", {spec.start_u, spec.start_v});
  if (start.size() != 2) throw std::invalid_argument("--start: U,V");
  spec.start_u = start[0], spec.start_v = start[1];
  const std::vector<double> velocity = cli.getDoubleList("velocity", {0.25, 0.0, 0.0});
  if (velocity.size() != 3) throw std::invalid_argument("--velocity: X,Y,Z");
  spec.velocity = Eigen::Vector3d(velocity[0], velocity[1], velocity[2]);
  spec.with_camera = cli.has("with-camera");
  const std::string shape = cli.get("shape", "rect");
  if (shape != "rect" && shape != "ellipse") throw std::invalid_argument("--shape: rect|ellipse");
  spec.ellipse = shape == "ellipse";
  spec.texture = cvo::parseObjectTexture(cli.get("texture", "blocks"));
  spec.seed = static_cast<unsigned>(cli.getInt("seed", 1));
  spec.label = cli.getInt("label", spec.label);
  spec.label_error_px = cli.getInt("label-error", 0);
  spec.validate();
  return spec;
}

std::string relativeTo(const std::string& folder, const std::string& path) {
  return fs::relative(fs::path(path), fs::path(folder)).generic_string();
}

void makeTum(const cvo::CommandLine& cli, const cvo::MovingObjectSpec& spec, const fs::path& out,
             Summary* summary) {
  const std::string folder = cli.get("tum");
  const cvo::TumSequence sequence(folder);
  const double max_gap = cli.getDouble("max-gap", 0.05);
  const cvo::Trajectory truth = cvo::readTumTrajectory(folder + "/groundtruth.txt");
  cv::Mat image, depth;
  sequence.load(0, &image, &depth);
  const cvo::PinholeIntrinsics K =
      cvo::tumIntrinsics(cli.get("camera", "fr1"), image.cols, image.rows);
  const auto& frames = sequence.frames();
  const cvo::MovingObject object(spec, K, poseAt(truth, frames[0].rgb_stamp, max_gap),
                                 frames[0].rgb_stamp, image);
  std::ofstream associations(out / "associations.txt"), rgb_list(out / "rgb.txt"),
      depth_list(out / "depth.txt");
  rgb_list << "# timestamp filename\n";
  depth_list << "# timestamp filename\n";
  constexpr double kUnitsPerMetre = 5000.0;  // TUM's depth PNGs
  const bool labels_only = cli.has("labels-only");
  for (std::size_t k = 0; k < frames.size(); ++k) {
    const cvo::TumFramePaths& f = frames[k];
    sequence.load(k, &image, &depth);
    // Colour and labels at the colour image's time, depth at the depth image's: each shows the
    // object where it was when that image was taken.
    // The recorded scene hides the object where it is nearer.
    const cv::Mat scene_depth = cvo::depthToMetres(depth, kUnitsPerMetre, 0.0, INFINITY);
    cv::Mat mask;
    cv::Mat painted = labels_only ? image.clone() : image;  // a scratch canvas for labels only
    object.render(object.cameraFromObject(f.rgb_stamp, poseAt(truth, f.rgb_stamp, max_gap)),
                  &painted, nullptr, &mask, 0.0, &scene_depth);
    if (!labels_only) {
      cv::Mat object_depth;
      cv::Mat depth_image = image.clone();  // a scratch canvas; only the depth is kept
      object.render(object.cameraFromObject(f.depth_stamp, poseAt(truth, f.depth_stamp, max_gap)),
                    &depth_image, &object_depth, nullptr, 0.0, &scene_depth);
      for (int v = 0; v < depth.rows; ++v) {
        for (int u = 0; u < depth.cols; ++u) {
          const float z = object_depth.at<float>(v, u);
          if (std::isfinite(z)) {
            depth.at<std::uint16_t>(v, u) = cv::saturate_cast<std::uint16_t>(z * kUnitsPerMetre);
          }
        }
      }
    }
    const std::string depth_listed = relativeTo(folder, f.depth_path);
    writeImage(out / f.rgb_listed, image);
    writeImage(out / depth_listed, depth);
    writeImage(out / "labels" / f.rgb_listed,
               withEarlierLabels(fs::path(folder) / "labels" / f.rgb_listed, object.labels(mask),
                                 labels_only ? cv::Mat() : mask));
    associations << std::fixed << std::setprecision(6) << f.rgb_stamp << " " << f.rgb_listed << " "
                 << f.depth_stamp << " " << depth_listed << "\n";
    rgb_list << std::fixed << std::setprecision(6) << f.rgb_stamp << " " << f.rgb_listed << "\n";
    depth_list << std::fixed << std::setprecision(6) << f.depth_stamp << " " << depth_listed
               << "\n";
    summary->add(f.rgb_stamp, mask);
  }
  fs::copy_file(folder + "/groundtruth.txt", out / "groundtruth.txt",
                fs::copy_options::overwrite_existing);
}

void makeKitti(const cvo::CommandLine& cli, const cvo::MovingObjectSpec& spec, const fs::path& out,
               Summary* summary) {
  const std::string folder = cli.get("kitti");
  const cvo::KittiSequence sequence(folder);
  const cvo::Trajectory truth =
      cvo::readKittiTrajectory(folder + "/poses.txt", folder + "/times.txt");
  const double max_gap = cli.getDouble("max-gap", 0.05);
  cv::Mat left, right;
  sequence.load(0, &left, &right, nullptr);
  const cvo::KittiStereoCalibration& calibration = sequence.calibration();
  const double first = sequence.stamps()[0];
  const cvo::MovingObject object(spec, calibration.left, poseAt(truth, first, max_gap), first,
                                 left);
  // The sequence is read in colour; a grey one is written grey again.
  const bool grey =
      cv::imread(folder + "/image_0/" + sequence.imageName(0), cv::IMREAD_UNCHANGED).channels() ==
      1;
  const bool labels_only = cli.has("labels-only");
  for (std::size_t k = 0; k < sequence.size(); ++k) {
    sequence.load(k, &left, &right, nullptr);
    if (grey) {
      cv::cvtColor(left, left, cv::COLOR_BGR2GRAY);
      cv::cvtColor(right, right, cv::COLOR_BGR2GRAY);
    }
    const double stamp = sequence.stamps()[k];
    const Eigen::Isometry3d camera_from_object =
        object.cameraFromObject(stamp, poseAt(truth, stamp, max_gap));
    // Both cameras see the same board: a disparity consistent with its depth.
    cv::Mat mask;
    if (labels_only) {
      cv::Mat scratch = left.clone();
      object.render(camera_from_object, &scratch, nullptr, &mask);
    } else {
      object.render(camera_from_object, &left, nullptr, &mask);
      object.render(camera_from_object, &right, nullptr, nullptr, calibration.baseline);
    }
    const std::string name = sequence.imageName(k);
    writeImage(out / "image_0" / name, left);
    writeImage(out / "image_1" / name, right);
    writeImage(out / "labels" / "image_0" / name,
               withEarlierLabels(fs::path(folder) / "labels" / "image_0" / name,
                                 object.labels(mask), labels_only ? cv::Mat() : mask));
    summary->add(stamp, mask);
  }
  for (const char* file : {"calib.txt", "times.txt", "poses.txt"}) {
    if (fs::exists(folder + "/" + file)) {
      fs::copy_file(folder + "/" + file, out / file, fs::copy_options::overwrite_existing);
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  try {
    const cvo::CommandLine cli(
        argc, argv,
        {"tum", "kitti", "out", "area", "aspect", "depth", "start", "velocity", "shape", "texture",
         "seed", "label", "label-error", "camera", "max-gap"},
        {"help", "with-camera", "labels-only"});
    if (cli.has("help")) {
      std::cout << kUsage;
      return 0;
    }
    if (cli.has("tum") == cli.has("kitti") || !cli.has("out")) {
      std::cerr << kUsage;
      return 2;
    }
    const cvo::MovingObjectSpec spec = specFrom(cli);
    const fs::path out = cli.require("out");
    fs::create_directories(out);
    Summary summary;
    summary.table.open(out / "object.txt");
    summary.table << "# stamp share_of_image centre_u centre_v moved_px\n";
    if (cli.has("tum")) {
      makeTum(cli, spec, out, &summary);
    } else {
      makeKitti(cli, spec, out, &summary);
    }
    std::cout << std::fixed << std::setprecision(2)
              << "cvo_make_dynamic: " << summary.coverage.size() << " frames -> " << out.string()
              << "; " << toString(spec.texture) << " board, covers "
              << 100.0 * summary.coverage.front() << " % of the first image (median "
              << 100.0 * median(summary.coverage) << " %), moves " << median(summary.flow)
              << " px a frame (median)\n";
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "cvo_make_dynamic: " << e.what() << "\n";
    return 2;
  }
}
