#include "cvo_odometry/core/trajectory_evaluation.hpp"

#include <optional>
#include <set>

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

#include "cvo_odometry/core/lie_group.hpp"
#include "cvo_odometry/core/robust_scale.hpp"

namespace cvo {

namespace {

constexpr double kRadToDeg = 180.0 / M_PI;

double rms(const std::vector<double>& v) {
  if (v.empty()) return 0.0;
  double sum = 0.0;
  for (double x : v)
    sum += x * x;
  return std::sqrt(sum / static_cast<double>(v.size()));
}

// TUM benchmark relative error of the pair (i, j).
Eigen::Isometry3d relativeError(const AssociatedPoses& p, std::size_t i, std::size_t j) {
  const Eigen::Isometry3d gt_rel = p.ground_truth[i].inverse() * p.ground_truth[j];
  const Eigen::Isometry3d est_rel = p.estimate[i].inverse() * p.estimate[j];
  return gt_rel.inverse() * est_rel;
}

RpeResult rpeOverPairs(const AssociatedPoses& p,
                       const std::vector<std::pair<std::size_t, std::size_t>>& pairs) {
  std::vector<double> t, r, t_rate, r_rate;
  for (const auto& [i, j] : pairs) {
    const Eigen::Isometry3d e = relativeError(p, i, j);
    const double dt = p.stamps[j] - p.stamps[i];
    t.push_back(e.translation().norm());
    r.push_back(lie::rotationAngle(e.linear()) * kRadToDeg);
    t_rate.push_back(t.back() / dt);
    r_rate.push_back(r.back() / dt);
  }
  RpeResult result;
  result.count = pairs.size();
  result.translation_rmse = rms(t);
  result.rotation_rmse_deg = rms(r);
  result.translation_rate_rmse = rms(t_rate);
  result.rotation_rate_rmse_deg = rms(r_rate);
  return result;
}

}  // namespace

const std::vector<EnumName<Association>>& enumNames(Association) {
  static const std::vector<EnumName<Association>> names{{Association::kInterpolate, "interpolate"},
                                                        {Association::kNearest, "nearest"}};
  return names;
}

AssociatedPoses associate(const Trajectory& ground_truth, const Trajectory& estimate,
                          double max_gap, Association mode) {
  AssociatedPoses out;
  for (const auto& sample : estimate.poses()) {
    Eigen::Isometry3d gt;
    const bool interpolated =
        mode == Association::kInterpolate && ground_truth.interpolate(sample.stamp, max_gap, &gt);
    if (!interpolated) {
      const long k = ground_truth.nearest(sample.stamp, max_gap);
      if (k < 0) continue;
      gt = ground_truth[static_cast<std::size_t>(k)].pose;
      if (mode == Association::kInterpolate) ++out.nearest_fallbacks;
    }
    out.stamps.push_back(sample.stamp);
    out.ground_truth.push_back(gt);
    out.estimate.push_back(sample.pose);
  }
  return out;
}

AteResult computeAte(const AssociatedPoses& poses) {
  AteResult result;
  const auto n = static_cast<Eigen::Index>(poses.size());
  result.count = poses.size();
  if (n == 0) return result;
  Eigen::Matrix3Xd est(3, n), gt(3, n);
  for (Eigen::Index k = 0; k < n; ++k) {
    est.col(k) = poses.estimate[k].translation();
    gt.col(k) = poses.ground_truth[k].translation();
  }
  if (n >= 3) result.alignment.matrix() = Eigen::umeyama(est, gt, false);
  std::vector<double> errors(n);
  for (Eigen::Index k = 0; k < n; ++k)
    errors[k] = (result.alignment * est.col(k) - gt.col(k)).norm();
  result.rmse = rms(errors);
  double sum = 0.0;
  for (double e : errors)
    sum += e;
  result.mean = sum / static_cast<double>(n);
  result.max = *std::max_element(errors.begin(), errors.end());
  result.median = medianInPlace(errors);
  return result;
}

RpeResult computeRpeFrameToFrame(const AssociatedPoses& poses) {
  std::vector<std::pair<std::size_t, std::size_t>> pairs;
  for (std::size_t i = 0; i + 1 < poses.size(); ++i)
    pairs.emplace_back(i, i + 1);
  return rpeOverPairs(poses, pairs);
}

RpeResult computeRpeFixedDelta(const AssociatedPoses& poses, double delta_s) {
  std::vector<std::pair<std::size_t, std::size_t>> pairs;
  const std::size_t n = poses.size();
  if (n < 2) return rpeOverPairs(poses, pairs);
  std::vector<double> intervals;
  for (std::size_t i = 0; i + 1 < n; ++i)
    intervals.push_back(poses.stamps[i + 1] - poses.stamps[i]);
  const double tolerance = std::max(0.5 * medianInPlace(intervals), 1e-3);
  for (std::size_t i = 0; i < n; ++i) {
    const double wanted = poses.stamps[i] + delta_s;
    auto it = std::lower_bound(poses.stamps.begin() + i, poses.stamps.end(), wanted);
    std::size_t best = n;
    double best_gap = tolerance;
    for (auto c : {it - 1, it}) {
      if (c <= poses.stamps.begin() + i || c >= poses.stamps.end()) continue;
      const double gap = std::abs(*c - wanted);
      if (gap <= best_gap) {
        best_gap = gap;
        best = static_cast<std::size_t>(c - poses.stamps.begin());
      }
    }
    if (best < n) pairs.emplace_back(i, best);
  }
  return rpeOverPairs(poses, pairs);
}

std::vector<double> kittiDriftLengths() {
  return {100, 200, 300, 400, 500, 600, 700, 800};
}

DriftResult computeKittiDrift(const AssociatedPoses& poses, const std::vector<double>& lengths_m,
                              int step) {
  DriftResult result;
  const std::size_t n = poses.size();
  std::vector<double> dist(n, 0.0);
  for (std::size_t i = 1; i < n; ++i) {
    dist[i] =
        dist[i - 1] +
        (poses.ground_truth[i].translation() - poses.ground_truth[i - 1].translation()).norm();
  }
  double t_sum = 0.0, r_sum = 0.0;
  for (std::size_t first = 0; first < n; first += static_cast<std::size_t>(std::max(step, 1))) {
    for (double length : lengths_m) {
      // First frame whose path distance from `first` exceeds `length` (as the devkit does).
      auto it = std::upper_bound(dist.begin() + first, dist.end(), dist[first] + length);
      if (it == dist.end()) continue;
      const auto last = static_cast<std::size_t>(it - dist.begin());
      const Eigen::Isometry3d e = relativeError(poses, first, last);
      t_sum += e.translation().norm() / length;
      r_sum += lie::rotationAngle(e.linear()) / length;
      ++result.count;
    }
  }
  if (result.count > 0) {
    result.translation_percent = 100.0 * t_sum / static_cast<double>(result.count);
    result.rotation_deg_per_m = kRadToDeg * r_sum / static_cast<double>(result.count);
  }
  return result;
}

SilentFailures countSilentFailures(const AssociatedPoses& poses,
                                   const std::vector<double>& trusted_stamps, double fraction,
                                   double min_error_m, double max_rotation_deg,
                                   const std::vector<double>& restart_stamps) {
  SilentFailures result;
  const std::set<double> trusted(trusted_stamps.begin(), trusted_stamps.end());
  const std::set<double> restarts(restart_stamps.begin(), restart_stamps.end());
  // Each trusted frame against the trusted one before it: an untrusted pose between them is a
  // guess that no trusted pose is measured from.
  std::optional<std::size_t> last;
  for (std::size_t k = 0; k < poses.size(); ++k) {
    if (!trusted.count(poses.stamps[k])) continue;
    const std::optional<std::size_t> before = last;
    last = k;
    if (!before) continue;
    const std::size_t j = *before;
    const auto restart = restarts.upper_bound(poses.stamps[j]);
    if (restart != restarts.end() && *restart <= poses.stamps[k]) continue;
    const Eigen::Isometry3d truth = poses.ground_truth[j].inverse() * poses.ground_truth[k];
    const Eigen::Isometry3d step = poses.estimate[j].inverse() * poses.estimate[k];
    const Eigen::Isometry3d error = truth.inverse() * step;
    const double t = error.translation().norm();
    const double r = Eigen::AngleAxisd(error.rotation()).angle() * 180.0 / M_PI;
    ++result.judged;
    result.translation_rmse += t * t;
    result.rotation_rmse_deg += r * r;
    if ((t > fraction * truth.translation().norm() && t > min_error_m) || r > max_rotation_deg) {
      ++result.failures;
    }
  }
  if (result.judged > 0) {
    result.translation_rmse = std::sqrt(result.translation_rmse / result.judged);
    result.rotation_rmse_deg = std::sqrt(result.rotation_rmse_deg / result.judged);
  }
  return result;
}

}  // namespace cvo
