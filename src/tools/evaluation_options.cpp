#include "cvo_odometry/tools/evaluation_options.hpp"

namespace cvo {

const char* const kEvaluationOptionsUsage =
    "  --max-gap S             largest time (s) between a pose and its ground truth (0.02)\n"
    "  --association interpolate|nearest   interpolate (default; the nearest sample where the\n"
    "                          ground truth's samples are too far apart) or the nearest sample\n"
    "  --delta S               RPE interval (1 s)\n"
    "  --drift-lengths L,...   drift sub-sequence lengths in m (KITTI: 100,...,800)\n";

std::vector<std::string> evaluationOptionNames() {
  return {"max-gap", "association", "delta", "drift-lengths"};
}

EvaluationOptions evaluationOptionsFrom(const CommandLine& cli) {
  EvaluationOptions options;
  options.max_gap = cli.getDouble("max-gap", options.max_gap);
  if (cli.has("association")) {
    options.association = parseEnum<Association>("--association", cli.get("association"));
  }
  options.rpe_delta_s = cli.getDouble("delta", options.rpe_delta_s);
  options.drift_lengths_m = cli.getDoubleList("drift-lengths", options.drift_lengths_m);
  return options;
}

}  // namespace cvo
