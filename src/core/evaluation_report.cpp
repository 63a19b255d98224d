#include "cvo_odometry/core/evaluation_report.hpp"

#include <iomanip>
#include <ostream>
#include <stdexcept>

namespace cvo {

EvaluationReport evaluateTrajectory(const Trajectory& ground_truth, const Trajectory& estimate,
                                    const EvaluationOptions& options) {
  EvaluationReport report;
  report.estimated_poses = estimate.size();
  const AssociatedPoses poses =
      associate(ground_truth, estimate, options.max_gap, options.association);
  report.associated_poses = poses.size();
  if (poses.size() < 2) {
    throw std::runtime_error("only " + std::to_string(poses.size()) + " of " +
                             std::to_string(estimate.size()) +
                             " estimated poses have ground truth within " +
                             std::to_string(options.max_gap) + " s: check the timestamps");
  }
  report.ate = computeAte(poses);
  report.rpe_frame = computeRpeFrameToFrame(poses);
  report.rpe_delta = computeRpeFixedDelta(poses, options.rpe_delta_s);
  report.drift = computeKittiDrift(poses, options.drift_lengths_m);
  return report;
}

void printEvaluationReport(std::ostream& out, const EvaluationReport& r,
                           const EvaluationOptions& options) {
  out << std::fixed;
  out << "poses: " << r.associated_poses << " of " << r.estimated_poses
      << " associated with ground truth\n";
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
}

}  // namespace cvo
