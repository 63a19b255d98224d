// cvo_peers: the peers of the accuracy table on the same frames as cvo_run_sequence, frame to
// frame with the previous motion as the guess, poses stamped like ours (TUM: depth time).
//   --stride N: every N-th frame (frame k against frame k-N, like cvo_run_sequence --stride)
//   --format tum|kitti: the trajectory written (default: the dataset's)
// The time per frame (median, p95) runs from the decoded images to the pose, as the runner's
// `total` does: PNG decoding is outside it; depth to metres, grey conversion, PCL's cloud and
// voxel grid and the registration are inside.
//   OpenCV (contrib rgbd): opencv_rgbd (photometric), opencv_icp, opencv_rgbdicp (TUM only)
//   PCL: pcl_gicp, pcl_ndt on full depth clouds (TUM, 1 cm voxel grid) or on the stereo clouds
//   our front end builds (KITTI)
// Built only with -DCVO_BUILD_PEERS=ON (needs libpcl-dev and libopencv-contrib-dev).
#include <chrono>
#include <iomanip>
#include <iostream>
#include <optional>
#include <variant>

#include <pcl/filters/voxel_grid.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/registration/gicp.h>
#include <pcl/registration/ndt.h>
#include <Eigen/Core>
#include <opencv2/core/eigen.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/rgbd.hpp>

#include "cvo_odometry/core/trajectory_io.hpp"
#include "cvo_odometry/frontend/depth_conversion.hpp"
#include "cvo_odometry/frontend/rgbd_cloud_builder.hpp"
#include "cvo_odometry/frontend/stereo_cloud_builder.hpp"
#include "cvo_odometry/frontend/tum_sequence.hpp"
#include "cvo_odometry/tools/command_line.hpp"
#include "cvo_odometry/tools/stage_timer.hpp"
#include "cvo_odometry/tools/tool_options.hpp"

namespace {

using Cloud = pcl::PointCloud<pcl::PointXYZ>;

Cloud::Ptr toPcl(const cvo::LabeledCloud& cloud, double voxel) {
  Cloud::Ptr out(new Cloud);
  out->reserve(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const auto p = cloud.position(i);
    out->push_back(pcl::PointXYZ(p.x(), p.y(), p.z()));
  }
  if (voxel <= 0.0) return out;
  Cloud::Ptr filtered(new Cloud);
  pcl::VoxelGrid<pcl::PointXYZ> grid;
  grid.setLeafSize(voxel, voxel, voxel);
  grid.setInputCloud(out);
  grid.filter(*filtered);
  return filtered;
}

// previous <- current by PCL registration of the current cloud (source) to the previous.
Eigen::Matrix4d pclMotion(const std::string& method, const Cloud::Ptr& previous,
                          const Cloud::Ptr& current, const Eigen::Matrix4d& guess,
                          double resolution) {
  Cloud aligned;
  if (method == "pcl_gicp") {
    pcl::GeneralizedIterativeClosestPoint<pcl::PointXYZ, pcl::PointXYZ> gicp;
    gicp.setInputSource(current);
    gicp.setInputTarget(previous);
    gicp.setMaxCorrespondenceDistance(resolution);
    gicp.align(aligned, guess.cast<float>());
    return gicp.getFinalTransformation().cast<double>();
  }
  pcl::NormalDistributionsTransform<pcl::PointXYZ, pcl::PointXYZ> ndt;
  ndt.setResolution(static_cast<float>(resolution));
  ndt.setTransformationEpsilon(1e-4);
  ndt.setStepSize(0.1 * resolution);
  ndt.setMaximumIterations(50);
  ndt.setInputSource(current);
  ndt.setInputTarget(previous);
  ndt.align(aligned, guess.cast<float>());
  return ndt.getFinalTransformation().cast<double>();
}

cv::Ptr<cv::rgbd::Odometry> openCvOdometry(const std::string& method,
                                           const cvo::PinholeIntrinsics& K) {
  const cv::Mat camera = (cv::Mat_<float>(3, 3) << K.fx, 0, K.cx, 0, K.fy, K.cy, 0, 0, 1);
  if (method == "opencv_rgbd") return cv::rgbd::RgbdOdometry::create(camera);
  if (method == "opencv_icp") return cv::rgbd::ICPOdometry::create(camera);
  if (method == "opencv_rgbdicp") return cv::rgbd::RgbdICPOdometry::create(camera);
  throw std::invalid_argument("unknown method '" + method + "'");
}

}  // namespace

int main(int argc, char** argv) {
  try {
    auto names = cvo::sharedOptionNames();
    names.insert(names.end(), {"method", "out", "voxel", "resolution", "stride", "format"});
    const cvo::CommandLine cli(argc, argv, {names.begin(), names.end()}, {"help"});
    const std::string method = cli.require("method");
    const bool is_pcl = method.rfind("pcl_", 0) == 0;
    const cvo::SequenceInput input = cvo::openSequence(cli);
    // PCL's clouds come from our front end with the settings given (--preset, --set, --NAME).
    const cvo::OdometrySettings settings = cvo::settingsFrom(cli);
    const int stride = cli.getInt("stride", 1);
    if (stride < 1) throw std::invalid_argument("--stride must be >= 1");
    const auto format =
        cli.has("format") ? cvo::parseTrajectoryFormat(cli.get("format")) : input.trajectory_format;
    const bool tum = input.kind == "tum";
    // TUM: PCL on every valid depth pixel (then a voxel grid); KITTI: our stereo clouds.
    double voxel = cli.getDouble("voxel", tum ? 0.01 : 0.0);
    // NDT cell size, and the largest GICP correspondence distance (m).
    double resolution = cli.getDouble("resolution", tum ? 0.1 : 1.0);

    std::unique_ptr<cvo::TumSequence> tum_sequence;
    cv::Ptr<cv::rgbd::Odometry> odometry;
    cvo::PinholeIntrinsics K;
    if (!is_pcl) {
      if (!tum) throw std::invalid_argument("the OpenCV RGB-D peers run on TUM folders");
      tum_sequence = std::make_unique<cvo::TumSequence>(cli.get("tum"));
      K = cvo::tumIntrinsics(cli.get("camera", "fr1"));
      K.distortion.clear();  // OpenCV's odometry takes a pinhole camera
      odometry = openCvOdometry(method, K);
    }
    // PCL's front end, kept for the whole run as OdometryPipeline keeps its own: a fresh
    // StereoCloudBuilder reallocates SGBM's buffers (~10 ms a KITTI frame inside the timer).
    std::optional<cvo::RgbdCloudBuilder> rgbd_builder;
    std::optional<cvo::StereoCloudBuilder> stereo_builder;
    const auto cloudOf = [&](const cvo::CameraFrame& frame) {
      if (const auto* rgbd = std::get_if<cvo::RgbdFrame>(&frame)) {
        if (!rgbd_builder) rgbd_builder.emplace(settings.rgbdOptions());
        return rgbd_builder->build(*rgbd);
      }
      if (!stereo_builder) stereo_builder.emplace(settings.stereoOptions());
      return stereo_builder->build(std::get<cvo::StereoFrame>(frame));
    };
    cvo::Trajectory trajectory;
    cvo::StageTimer timer;
    Eigen::Matrix4d pose = Eigen::Matrix4d::Identity(), motion = Eigen::Matrix4d::Identity();
    Cloud::Ptr previous_cloud;
    cv::Mat previous_grey, previous_depth;
    const auto step = static_cast<std::size_t>(stride);
    for (std::size_t k = 0; k < input.stamps.size(); k += step) {
      // Decoding stays outside the timed part (the runner's `total` excludes it too).
      std::optional<cvo::CameraFrame> frame;
      cv::Mat image, raw_depth;
      if (is_pcl) {
        frame = input.frame(k);
      } else {
        tum_sequence->load(k, &image, &raw_depth);
      }
      const auto start = std::chrono::steady_clock::now();
      if (is_pcl) {
        Cloud::Ptr cloud = toPcl(cloudOf(*frame), voxel);
        if (previous_cloud) motion = pclMotion(method, previous_cloud, cloud, motion, resolution);
        previous_cloud = cloud;
      } else {
        cv::Mat grey;
        cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
        cv::Mat depth = cvo::depthToMetres(raw_depth, 5000.0, 0.1, 10.0);
        if (!previous_grey.empty()) {
          cv::Mat rt, guess;
          cv::eigen2cv(motion, guess);
          const bool ok = odometry->compute(grey, depth, cv::Mat(), previous_grey, previous_depth,
                                            cv::Mat(), rt, guess);
          if (ok) {
            cv::cv2eigen(rt, motion);
          } else {
            std::cerr << "frame " << k << ": " << method << " failed; keeping the guess\n";
          }
        }
        previous_grey = grey;
        previous_depth = depth;
      }
      const double ms =
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
              .count();
      if (k > 0) {  // the first frame only seeds the next
        pose = pose * motion;
        timer.add("frame", ms);
      }
      trajectory.append(input.stamps[k], Eigen::Isometry3d(pose));
    }
    timer.print(std::cout);
    cvo::writeTrajectory(cli.require("out"), trajectory, format);
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "cvo_peers: " << e.what() << "\n";
    return 2;
  }
}
