// Trajectory error metrics: ATE (after Horn/Umeyama alignment), RPE as the TUM RGB-D benchmark
// defines it, and the KITTI odometry drift metric.
#pragma once

#include <cstddef>
#include <vector>

#include <Eigen/Geometry>

#include "cvo_odometry/core/settings_table.hpp"
#include "cvo_odometry/core/trajectory.hpp"

namespace cvo {

enum class Association {
  kInterpolate,  // ground truth interpolated at each estimate's stamp (for dense ground truth);
                 // where its samples are too far apart, the nearest one within max_gap
  kNearest       // the ground-truth sample nearest in time
};
const std::vector<EnumName<Association>>& enumNames(Association);

// Estimated poses matched with ground truth at the estimate's stamps.
struct AssociatedPoses {
  std::vector<double> stamps;
  std::vector<Eigen::Isometry3d, Eigen::aligned_allocator<Eigen::Isometry3d>> ground_truth;
  std::vector<Eigen::Isometry3d, Eigen::aligned_allocator<Eigen::Isometry3d>> estimate;
  std::size_t size() const { return stamps.size(); }
  // Interpolation asked for, the nearest sample taken: the samples were too far apart.
  std::size_t nearest_fallbacks = 0;
};

// Estimates with no ground truth within `max_gap` seconds are left out.
AssociatedPoses associate(const Trajectory& ground_truth, const Trajectory& estimate,
                          double max_gap, Association mode);

struct AteResult {
  std::size_t count = 0;
  double rmse = 0.0, mean = 0.0, median = 0.0, max = 0.0;       // metres
  Eigen::Isometry3d alignment = Eigen::Isometry3d::Identity();  // applied to the estimate
};

// Absolute trajectory error after the rigid (Horn/Umeyama, no scale) alignment of the estimate.
AteResult computeAte(const AssociatedPoses& poses);

struct RpeResult {
  std::size_t count = 0;
  double translation_rmse = 0.0;        // metres per pair
  double rotation_rmse_deg = 0.0;       // degrees per pair
  double translation_rate_rmse = 0.0;   // each pair's error over its interval: m/s
  double rotation_rate_rmse_deg = 0.0;  // deg/s
};

// E = (Q_i^-1 Q_j)^-1 (P_i^-1 P_j) over consecutive pairs (j = i + 1).
RpeResult computeRpeFrameToFrame(const AssociatedPoses& poses);
// Pairs (i, j) with stamp_j nearest stamp_i + delta_s, within a tolerance of half the median frame
// interval (at least 1 ms); none where the trajectory is shorter than delta_s.
RpeResult computeRpeFixedDelta(const AssociatedPoses& poses, double delta_s);

struct DriftResult {
  std::size_t count = 0;             // sub-sequences evaluated
  double translation_percent = 0.0;  // mean |t_err| / length * 100
  double rotation_deg_per_m = 0.0;   // mean angle_err / length
};

// KITTI devkit metric: sub-sequences starting every `step` frames, of path lengths `lengths_m`
// (KITTI: 100, 200, ..., 800 m) measured along the ground truth.
DriftResult computeKittiDrift(const AssociatedPoses& poses, const std::vector<double>& lengths_m,
                              int step = 10);
std::vector<double> kittiDriftLengths();

// Frames the odometry called trusted whose motion from the previous trusted frame is wrong:
// translation error above both `fraction` of the ground-truth step and `min_error_m`, or
// rotation error above `max_rotation_deg`. A "silent failure": a wrong pose reported as right.
// A restart between two trusted frames (`restart_stamps`: tracking started anew there, which
// the indicator says) ends a stretch: the pair across it is not judged.
struct SilentFailures {
  std::size_t judged = 0;  // trusted frames with ground truth at them and the previous one
  std::size_t failures = 0;
  // RMS error of the judged pairs' motion (none across a restart, where the pose holds while
  // the camera moved on): what a user of the trusted poses sees frame to frame.
  double translation_rmse = 0.0;
  double rotation_rmse_deg = 0.0;
};
SilentFailures countSilentFailures(const AssociatedPoses& poses,
                                   const std::vector<double>& trusted_stamps, double fraction = 0.5,
                                   double min_error_m = 0.02, double max_rotation_deg = 1.0,
                                   const std::vector<double>& restart_stamps = {});

}  // namespace cvo
