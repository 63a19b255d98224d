// cvo_evaluate: ATE, RPE and KITTI drift of an estimated trajectory against ground truth.
#include <iostream>

#include "cvo_odometry/core/evaluation_report.hpp"
#include "cvo_odometry/core/trajectory_io.hpp"
#include "cvo_odometry/tools/command_line.hpp"

namespace {

const char* kUsage =
    "usage: cvo_evaluate --gt FILE --est FILE [options]\n"
    "  --gt-format tum|kitti     default: detected from the file\n"
    "  --est-format tum|kitti    default: detected from the file\n"
    "  --gt-times FILE           KITTI stamps (times.txt) for the ground truth\n"
    "  --est-times FILE          KITTI stamps for the estimate\n"
    "  --max-gap S               max time between an estimate and its ground truth (0.02)\n"
    "  --association interpolate|nearest   (interpolate)\n"
    "  --delta S                 fixed RPE interval in seconds (1.0)\n"
    "  --drift-lengths L1,L2,..  KITTI drift sub-sequence lengths in m (100,...,800)\n";

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
    const cvo::CommandLine cli(argc, argv,
                               {"gt", "est", "gt-format", "est-format", "gt-times", "est-times",
                                "max-gap", "association", "delta", "drift-lengths"},
                               {"help"});
    if (cli.has("help")) {
      std::cout << kUsage;
      return 0;
    }
    cvo::EvaluationOptions options;
    options.max_gap = cli.getDouble("max-gap", options.max_gap);
    const std::string association = cli.get("association", "interpolate");
    if (association == "nearest") {
      options.association = cvo::Association::kNearest;
    } else if (association != "interpolate") {
      throw std::invalid_argument("--association expects interpolate or nearest");
    }
    options.rpe_delta_s = cli.getDouble("delta", options.rpe_delta_s);
    options.drift_lengths_m = cli.getDoubleList("drift-lengths", options.drift_lengths_m);
    const cvo::Trajectory gt = load(cli, "gt");
    const cvo::Trajectory est = load(cli, "est");
    const auto report = cvo::evaluateTrajectory(gt, est, options);
    cvo::printEvaluationReport(std::cout, report, options);
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "cvo_evaluate: " << e.what() << "\n" << kUsage;
    return 2;
  }
}
