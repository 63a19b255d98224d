// The full evaluation of an estimate against ground truth, and its text form (cvo_evaluate and the
// sequence runner print the same report).
#pragma once

#include <iosfwd>
#include <vector>

#include "cvo_odometry/core/trajectory_evaluation.hpp"

namespace cvo {

struct EvaluationOptions {
  double max_gap = 0.02;  // seconds between an estimate and its ground truth
  Association association = Association::kInterpolate;
  double rpe_delta_s = 1.0;
  std::vector<double> drift_lengths_m = kittiDriftLengths();
};

struct EvaluationReport {
  std::size_t estimated_poses = 0;
  std::size_t associated_poses = 0;
  std::size_t nearest_fallbacks = 0;  // see AssociatedPoses
  AteResult ate;
  RpeResult rpe_frame;
  RpeResult rpe_delta;
  DriftResult drift;
  bool judged_trust = false;  // trusted stamps were given
  SilentFailures silent;
};

// `trusted_stamps`, when given, are the frames the odometry called trusted: the report then
// counts its silent failures; `restart_stamps` the frames where tracking restarted
// (countSilentFailures).
EvaluationReport evaluateTrajectory(const Trajectory& ground_truth, const Trajectory& estimate,
                                    const EvaluationOptions& options,
                                    const std::vector<double>* trusted_stamps = nullptr,
                                    const std::vector<double>& restart_stamps = {});
void printEvaluationReport(std::ostream& out, const EvaluationReport& report,
                           const EvaluationOptions& options);

}  // namespace cvo
