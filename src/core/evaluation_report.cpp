#include "cvo_odometry/core/evaluation_report.hpp"

#include <iomanip>
#include <ostream>
#include <sstream>
#include <stdexcept>

namespace cvo {

EvaluationReport evaluateTrajectory(const Trajectory& ground_truth, const Trajectory& estimate,
                                    const EvaluationOptions& options,
                                    const std::vector<double>* trusted_stamps,
                                    const std::vector<double>& restart_stamps) {
  EvaluationReport report;
  report.estimated_poses = estimate.size();
  const AssociatedPoses poses =
      associate(ground_truth, estimate, options.max_gap, options.association);
  report.associated_poses = poses.size();
  report.nearest_fallbacks = poses.nearest_fallbacks;
  if (poses.size() < 2) {
    std::ostringstream why;
    why << "only " << poses.size() << " of " << estimate.size()
        << " estimated poses have a ground-truth sample within " << options.max_gap
        << " s (--max-gap): check the timestamps";
    if (!estimate.empty() && !ground_truth.empty()) {
      why << " (estimate " << std::fixed << std::setprecision(3) << estimate[0].stamp << " .. "
          << estimate[estimate.size() - 1].stamp << " s, ground truth " << ground_truth[0].stamp
          << " .. " << ground_truth[ground_truth.size() - 1].stamp << " s)";
    }
    throw std::runtime_error(why.str());
  }
  report.ate = computeAte(poses);
  report.rpe_frame = computeRpeFrameToFrame(poses);
  report.rpe_delta = computeRpeFixedDelta(poses, options.rpe_delta_s);
  report.drift = computeKittiDrift(poses, options.drift_lengths_m);
  if (trusted_stamps) {
    report.judged_trust = true;
    report.silent = countSilentFailures(poses, *trusted_stamps, 0.5, 0.02, 1.0, restart_stamps);
  }
  return report;
}

void printEvaluationReport(std::ostream& out, const EvaluationReport& r,
                           const EvaluationOptions& options) {
  out << std::fixed;
  out << "poses: " << r.associated_poses << " of " << r.estimated_poses
      << " associated with ground truth";
  if (r.nearest_fallbacks > 0) {
    out << " (" << r.nearest_fallbacks << " to the nearest sample within " << std::setprecision(3)
        << options.max_gap << " s: the ground truth's samples are too far apart to interpolate)";
  }
  out << "\n";
  out << std::setprecision(6) << "ATE rmse: " << r.ate.rmse << " m (mean " << r.ate.mean
      << ", median " << r.ate.median << ", max " << r.ate.max << ")\n";
  out << "RPE frame-to-frame (" << r.rpe_frame.count << " pairs): " << r.rpe_frame.translation_rmse
      << " m, " << r.rpe_frame.rotation_rmse_deg << " deg; " << r.rpe_frame.translation_rate_rmse
      << " m/s, " << r.rpe_frame.rotation_rate_rmse_deg << " deg/s\n";
  out << std::setprecision(2) << "RPE delta " << options.rpe_delta_s << " s";
  if (r.rpe_delta.count == 0) {
    out << ": n/a (trajectory shorter than the delta)\n";
  } else {
    out << std::setprecision(6) << " (" << r.rpe_delta.count
        << " pairs): " << r.rpe_delta.translation_rmse << " m, " << r.rpe_delta.rotation_rmse_deg
        << " deg\n";
  }
  out << "drift (";
  for (std::size_t k = 0; k < options.drift_lengths_m.size(); ++k) {
    out << std::setprecision(0) << (k ? "," : "") << options.drift_lengths_m[k];
  }
  out << " m)";
  if (r.drift.count == 0) {
    out << ": n/a (path shorter than the shortest length)\n";
  } else {
    out << std::setprecision(4) << " (" << r.drift.count
        << " sub-sequences): " << r.drift.translation_percent << " %, "
        << r.drift.rotation_deg_per_m << " deg/m\n";
  }
  if (r.judged_trust) {
    out << "silent failures: " << r.silent.failures << " of " << r.silent.judged
        << " trusted frames (motion error > 50 % of the step and 2 cm, or > 1 deg)\n";
    out << std::setprecision(6) << "trusted frame-to-frame (" << r.silent.judged
        << " pairs, none across a restart): " << r.silent.translation_rmse << " m, "
        << r.silent.rotation_rmse_deg << " deg\n";
  }
}

}  // namespace cvo
