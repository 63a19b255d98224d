// cvo_run_sequence: frame-to-frame CVO odometry over a recorded TUM RGB-D folder, with the
// trajectory written out and, given ground truth, evaluated.
#include <unistd.h>

#include <chrono>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "cvo_odometry/core/evaluation_report.hpp"
#include "cvo_odometry/core/frame_to_frame_odometry.hpp"
#include "cvo_odometry/core/params_io.hpp"
#include "cvo_odometry/core/trajectory_io.hpp"
#include "cvo_odometry/frontend/rgbd_cloud_builder.hpp"
#include "cvo_odometry/frontend/tum_sequence.hpp"
#include "cvo_odometry/tools/command_line.hpp"
#include "cvo_odometry/tools/stage_timer.hpp"
#include "cvo_odometry/tools/tool_options.hpp"

namespace {

const char* kUsage =
    "usage: cvo_run_sequence --tum DIR [options]\n"
    "  --preset FILE           CVO parameters (config/tum_rgbd.yaml)\n"
    "  --set k=v[,k=v...]      override parameters of the preset\n"
    "  --camera NAME           fr1 | fr2 | fr3 | fx,fy,cx,cy[,k1,k2,p1,p2,k3] (fr1)\n"
    "  --depth-scale N         depth PNG units per metre (5000)\n"
    "  --selector fast|grid    point selection (fast)\n"
    "  --min-points N --max-points N   selected point range (3000, 15000)\n"
    "  --backend auto|cpu|cuda\n"
    "  --first N --last N      frame range (0 .. all)\n"
    "  --stamp depth|rgb       which image time stamps the pose (depth)\n"
    "  --out FILE --format tum|kitti   trajectory output (TUM format)\n"
    "  --gt FILE               ground truth to evaluate against\n"
    "  --quiet                 no per-frame lines\n";

// A progress bar on the terminal (stderr).
void progress(std::size_t done, std::size_t total, double fps) {
  const int width = 30;
  const int filled = static_cast<int>(width * done / std::max<std::size_t>(total, 1));
  std::cerr << "\r[" << std::string(filled, '#') << std::string(width - filled, ' ') << "] " << done
            << "/" << total << "  " << std::fixed << std::setprecision(1) << fps << " frames/s"
            << std::flush;
  if (done == total) std::cerr << "\n";
}

}  // namespace

int main(int argc, char** argv) {
  try {
    const cvo::CommandLine cli(
        argc, argv,
        {"tum", "preset", "set", "camera", "depth-scale", "selector", "min-points", "max-points",
         "backend", "first", "last", "stamp", "out", "format", "gt"},
        {"help", "quiet"});
    if (cli.has("help")) {
      std::cout << kUsage;
      return 0;
    }
    const cvo::CvoParams params = cvo::cvoParamsFrom(cli);

    const cvo::TumSequence sequence(cli.require("tum"));
    const cvo::PinholeIntrinsics intrinsics = cvo::tumIntrinsics(cli.get("camera", "fr1"));
    cvo::RgbdCloudBuilder builder(cvo::rgbdFrontendOptionsFrom(cli));
    cvo::FrameToFrameOdometry odometry(params);
    const bool stamp_depth = cli.get("stamp", "depth") == "depth";

    const std::size_t total = sequence.frames().size();
    const std::size_t first = static_cast<std::size_t>(cli.getInt("first", 0));
    const std::size_t last = std::min(
        total - 1, static_cast<std::size_t>(cli.getInt("last", static_cast<int>(total) - 1)));
    if (first > last) throw std::invalid_argument("--first is after --last");
    const bool tty = isatty(STDERR_FILENO) && !cli.has("quiet");
    std::cerr << "cvo_run_sequence: " << (last - first + 1) << " frames, backend "
              << odometry.registration().backend().name() << ", step "
              << cvo::toString(params.step_method) << ", colour "
              << (params.use_color ? "on" : "off") << "\n";

    cvo::Trajectory trajectory;
    cvo::StageTimer timer;
    const auto start = std::chrono::steady_clock::now();
    for (std::size_t k = first; k <= last; ++k) {
      cv::Mat image, depth;
      sequence.load(k, &image, &depth);
      cvo::FrontendStats stats;
      cvo::LabeledCloud cloud = builder.build({image, depth, intrinsics, cv::Mat()}, &stats);
      timer.add("frontend", stats.time_ms);
      const auto& f = sequence.frames()[k];
      const double stamp = stamp_depth ? f.depth_stamp : f.rgb_stamp;
      const cvo::OdometryUpdate update = odometry.process(stamp, std::move(cloud));
      trajectory.append(stamp, update.pose);
      if (!update.first_frame) {
        timer.add("registration", update.report.time_ms);
        timer.add("total", update.report.time_ms + stats.time_ms);
      }
      const std::size_t done = k - first + 1;
      const double elapsed =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      if (tty) {
        progress(done, last - first + 1, done / elapsed);
      } else if (!cli.has("quiet")) {
        std::cerr << "frame " << k << ": " << stats.selection.selected << " points (FAST "
                  << stats.selection.fast_threshold << ")";
        if (!update.first_frame) {
          std::cerr << ", " << update.report.iterations << " iterations, " << std::setprecision(2)
                    << std::fixed << update.report.time_ms << " ms, "
                    << (update.report.converged ? "converged" : update.report.message);
        }
        std::cerr << "\n";
      }
    }
    timer.print(std::cout);
    if (cli.has("out")) {
      cvo::writeTrajectory(cli.get("out"), trajectory,
                           cvo::parseTrajectoryFormat(cli.get("format", "tum")));
      std::cout << "trajectory: " << cli.get("out") << "\n";
    }
    if (cli.has("gt")) {
      cvo::EvaluationOptions options;
      const auto report =
          cvo::evaluateTrajectory(cvo::readTumTrajectory(cli.get("gt")), trajectory, options);
      cvo::printEvaluationReport(std::cout, report, options);
    }
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "cvo_run_sequence: " << e.what() << "\n";
    return 2;
  }
}
