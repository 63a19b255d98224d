// cvo_evaluate: ATE, RPE and KITTI drift of an estimated trajectory against ground truth.
#include <iostream>
#include <vector>

#include "cvo_odometry/core/evaluation_report.hpp"
#include "cvo_odometry/core/trajectory_io.hpp"
#include "cvo_odometry/tools/command_line.hpp"
#include "cvo_odometry/tools/evaluation_options.hpp"

namespace {

const char* kUsage =
    "usage: cvo_evaluate --gt FILE --est FILE [options]\n"
    "  --gt-format tum|kitti     default: detected from the file\n"
    "  --est-format tum|kitti    default: detected from the file\n"
    "  --gt-times FILE           KITTI stamps (times.txt) for the ground truth\n"
    "  --est-times FILE          KITTI stamps for the estimate\n"
    "  --all-trusted             count silent failures as if every pose were trusted (a method\n"
    "                            without a failure flag publishes every pose as right)\n";

cvo::Trajectory load(const cvo::CommandLine& cli, const std::string& which) {
  const std::string path = cli.require(which);
  const auto format = cli.has(which + "-format")
                          ? cvo::parseTrajectoryFormat(cli.get(which + "-format"))
                          : cvo::detectTrajectoryFormat(path);
  return cvo::readTrajectory(path, format, cli.get(which + "-times"));
}

}  // namespace

int main(int argc, char** argv) {
  try {
    auto names = cvo::evaluationOptionNames();
    names.insert(names.end(), {"gt", "est", "gt-format", "est-format", "gt-times", "est-times"});
    const cvo::CommandLine cli(argc, argv, {names.begin(), names.end()}, {"help", "all-trusted"});
    if (cli.has("help")) {
      std::cout << kUsage << cvo::kEvaluationOptionsUsage;
      return 0;
    }
    const cvo::EvaluationOptions options = cvo::evaluationOptionsFrom(cli);
    const cvo::Trajectory gt = load(cli, "gt");
    const cvo::Trajectory est = load(cli, "est");
    std::vector<double> every_stamp;
    for (const cvo::StampedPose& pose : est.poses())
      every_stamp.push_back(pose.stamp);
    const auto report =
        cvo::evaluateTrajectory(gt, est, options, cli.has("all-trusted") ? &every_stamp : nullptr);
    cvo::printEvaluationReport(std::cout, report, options);
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "cvo_evaluate: " << e.what() << "\n" << kUsage << cvo::kEvaluationOptionsUsage;
    return 2;
  }
}
