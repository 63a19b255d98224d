#include "cvo_odometry/core/disparity_offset_estimator.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>

#include "cvo_odometry/core/lie_group.hpp"

namespace cvo {

namespace {

using Matrix7d = Eigen::Matrix<double, 7, 7>;
using Vector7d = Eigen::Matrix<double, 7, 1>;
using Vector6d = Eigen::Matrix<double, 6, 1>;

constexpr int kConvexIterations = 5;
constexpr int kIterations = 15;
constexpr double kMinDepth = 0.1;  // m: a point this near (or behind) the camera says nothing

// One track's whitened residuals, both frames' (left image position, disparity), at its point
// (first frame's camera), motion T and offset; with Jacobians in the camera parameters
// [rotation, translation (left perturbation of T), offset] and in the point.
struct TrackLinearisation {
  Vector6d residual;
  Eigen::Matrix<double, 6, 7> camera;
  Eigen::Matrix<double, 6, 3> point;
};

// Whitened (u, v, disparity) prediction error of `seen` / `disparity` for a point p, and its
// derivative in p.
void observe(const Eigen::Vector3d& p, const Eigen::Vector2d& seen, double disparity, double offset,
             double pixel, double disp, double focal_baseline, Eigen::Ref<Eigen::Vector3d> residual,
             Eigen::Ref<Eigen::Matrix3d> d_point) {
  const double iz = 1.0 / p.z();
  residual << pixel * (seen.x() - p.x() * iz), pixel * (seen.y() - p.y() * iz),
      disp * (disparity + offset - focal_baseline * iz);
  d_point << -pixel * iz, 0.0, pixel * p.x() * iz * iz,  //
      0.0, -pixel * iz, pixel * p.y() * iz * iz,         //
      0.0, 0.0, disp * focal_baseline * iz * iz;
}

bool linearise(const StereoTrack& track, const Eigen::Vector3d& p, const Eigen::Isometry3d& T,
               double offset, double focal_baseline, double pixel, double disp,
               TrackLinearisation* out) {
  const Eigen::Vector3d q = T * p;
  if (p.z() < kMinDepth || q.z() < kMinDepth) return false;
  Eigen::Matrix3d d_first, d_second;
  observe(p, track.before, track.disparity_before, offset, pixel, disp, focal_baseline,
          out->residual.head<3>(), d_first);
  observe(q, track.after, track.disparity_after, offset, pixel, disp, focal_baseline,
          out->residual.tail<3>(), d_second);
  out->point.topRows<3>() = d_first;
  out->point.bottomRows<3>() = d_second * T.linear();
  out->camera.setZero();
  out->camera.block<3, 3>(3, 0) = -d_second * lie::hat(q);
  out->camera.block<3, 3>(3, 3) = d_second;
  out->camera(2, 6) = disp;  // a measured disparity plus the offset is the model's
  out->camera(5, 6) = disp;
  return true;
}

// Huber's weight first (convex: any start converges), then Cauchy's, which lets go of gross
// errors (a corner on an occluding edge takes the background's disparity, a car moves)
// instead of letting each pull in proportion to its size.
double robustWeight(double norm, double threshold, bool redescending) {
  if (redescending) return 1.0 / (1.0 + (norm / threshold) * (norm / threshold));
  return norm <= threshold ? 1.0 : threshold / norm;
}

}  // namespace

DisparityOffsetEstimator::DisparityOffsetEstimator(const DisparityOffsetOptions& options)
    : options_(options) {
  if (options.min_tracks < 7 || options.min_pairs < 2 || !(options.max_standard_error > 0.0) ||
      !(options.max_pair_offset > 0.0) || !(options.pixel_sigma > 0.0) ||
      !(options.disparity_sigma > 0.0) || !(options.huber_threshold > 0.0)) {
    throw std::invalid_argument("disparity offset estimator: options out of range");
  }
}

std::optional<DisparityOffsetEstimator::PairSolution> DisparityOffsetEstimator::solvePair(
    const StereoTracks& tracks, const Eigen::Isometry3d& second_from_first, double focal_px,
    double focal_baseline, double current_offset) const {
  if (static_cast<int>(tracks.size()) < options_.min_tracks || !(focal_px > 0.0) ||
      !(focal_baseline > 0.0) || !std::isfinite(focal_px) || !std::isfinite(focal_baseline) ||
      !std::isfinite(current_offset) || !second_from_first.matrix().allFinite()) {
    return std::nullopt;
  }
  // Two-view bundle adjustment: every track's point (first frame's camera) is free, observed
  // with noise in both frames, so neither frame's disparity is taken as exact (which biases the
  // offset as the motion grows). Points are eliminated per track (3x3), leaving a 7x7 system in
  // the motion and the offset.
  const double pixel = focal_px / options_.pixel_sigma;
  const double disp = 1.0 / options_.disparity_sigma;
  Eigen::Isometry3d T = second_from_first;
  double offset = current_offset;
  std::vector<Eigen::Vector3d, Eigen::aligned_allocator<Eigen::Vector3d>> points;
  // A track with a non-finite number says nothing; it must not poison the pair.
  std::vector<char> finite(tracks.size(), 0);
  for (std::size_t i = 0; i < tracks.size(); ++i) {
    const StereoTrack& t = tracks[i];
    finite[i] = t.before.allFinite() && t.after.allFinite() && std::isfinite(t.disparity_before) &&
                std::isfinite(t.disparity_after);
  }
  std::vector<char> usable(tracks.size(), 0);
  points.reserve(tracks.size());
  for (const StereoTrack& track : tracks) {
    const double disparity = track.disparity_before + offset;
    const double z = disparity > 0.0 ? focal_baseline / disparity : 0.0;
    points.emplace_back(track.before.x() * z, track.before.y() * z, z);
  }
  Matrix7d H;
  TrackLinearisation lin;
  // Per track, what the point's own step needs once the camera step is known.
  std::vector<Eigen::Matrix3d, Eigen::aligned_allocator<Eigen::Matrix3d>> point_inverse(
      tracks.size());
  std::vector<Eigen::Matrix<double, 3, 7>, Eigen::aligned_allocator<Eigen::Matrix<double, 3, 7>>>
      point_camera(tracks.size());
  std::vector<Eigen::Vector3d, Eigen::aligned_allocator<Eigen::Vector3d>> point_gradient(
      tracks.size());
  for (int iteration = 0; iteration < kIterations; ++iteration) {
    H.setZero();
    Vector7d b = Vector7d::Zero();
    int used = 0;
    for (std::size_t i = 0; i < tracks.size(); ++i) {
      usable[i] = finite[i] &&
                  linearise(tracks[i], points[i], T, offset, focal_baseline, pixel, disp, &lin);
      if (!usable[i]) continue;
      const double w = robustWeight(lin.residual.norm(), options_.huber_threshold,
                                    iteration >= kConvexIterations);
      const Eigen::Matrix3d V = w * lin.point.transpose() * lin.point;
      const Eigen::Matrix<double, 7, 3> W = w * lin.camera.transpose() * lin.point;
      const Eigen::Vector3d gp = w * lin.point.transpose() * lin.residual;
      const Eigen::LDLT<Eigen::Matrix3d> point_system(V);
      if (point_system.info() != Eigen::Success || !point_system.isPositive()) {
        usable[i] = 0;
        continue;
      }
      const Eigen::Matrix3d V_inverse = point_system.solve(Eigen::Matrix3d::Identity());
      H.noalias() += w * lin.camera.transpose() * lin.camera - W * V_inverse * W.transpose();
      b.noalias() += w * lin.camera.transpose() * lin.residual - W * (V_inverse * gp);
      point_inverse[i] = V_inverse;
      point_camera[i] = W.transpose();
      point_gradient[i] = gp;
      ++used;
    }
    if (used < options_.min_tracks) return std::nullopt;
    const Eigen::LDLT<Matrix7d> ldlt(H);
    if (ldlt.info() != Eigen::Success || !ldlt.isPositive()) return std::nullopt;
    const Vector7d step = -ldlt.solve(b);
    if (!step.allFinite()) return std::nullopt;
    for (std::size_t i = 0; i < tracks.size(); ++i) {
      if (usable[i]) points[i] -= point_inverse[i] * (point_gradient[i] + point_camera[i] * step);
    }
    T = lie::expSE3(step.head<6>()) * T;
    offset += step(6);
    if (std::abs(offset - current_offset) > options_.max_pair_offset) return std::nullopt;
    // Steps far below what one pair can tell (its offset is known to ~0.2 px).
    if (iteration >= kConvexIterations && step.head<3>().norm() < 1e-7 &&
        step.segment<3>(3).norm() < 1e-5 && std::abs(step(6)) < 1e-4) {
      break;
    }
  }
  // The offset's information with the motion marginalised out (Schur complement).
  const Eigen::Matrix<double, 6, 6> Hmm = H.topLeftCorner<6, 6>();
  const Eigen::Matrix<double, 6, 1> Hmo = H.topRightCorner<6, 1>();
  const Eigen::LDLT<Eigen::Matrix<double, 6, 6>> motion(Hmm);
  if (motion.info() != Eigen::Success || !motion.isPositive()) return std::nullopt;
  const double information = H(6, 6) - Hmo.dot(motion.solve(Hmo));
  if (!(information > 0.0) || !std::isfinite(offset)) return std::nullopt;
  PairSolution solution;
  solution.offset = offset;
  solution.information = information;
  solution.second_from_first = T;
  return solution;
}

bool DisparityOffsetEstimator::addPair(const StereoTracks& tracks,
                                       const Eigen::Isometry3d& second_from_first, double focal_px,
                                       double focal_baseline, double current_offset) {
  const std::optional<PairSolution> pair =
      solvePair(tracks, second_from_first, focal_px, focal_baseline, current_offset);
  if (!pair || !std::isfinite(pair->offset) || !std::isfinite(pair->information)) return false;
  const double w = pair->information;
  sum_weight_ += w;
  sum_weight_squared_ += w * w;
  sum_weighted_offset_ += w * pair->offset;
  sum_weighted_square_ += w * pair->offset * pair->offset;
  ++pairs_;
  return true;
}

std::optional<DisparityOffsetEstimate> DisparityOffsetEstimator::estimate() const {
  if (pairs_ == 0) return std::nullopt;
  DisparityOffsetEstimate result;
  result.pairs = pairs_;
  result.offset = sum_weighted_offset_ / sum_weight_;
  // The pairs' weighted spread about the mean, over Kish's effective number of pairs: one pair
  // of much information counts as one, however many weak ones surround it.
  const double spread =
      std::max(0.0, sum_weighted_square_ / sum_weight_ - result.offset * result.offset);
  const double effective_pairs = sum_weight_ * sum_weight_ / sum_weight_squared_;
  result.standard_error = effective_pairs > 1.0 ? std::sqrt(spread / (effective_pairs - 1.0))
                                                : std::numeric_limits<double>::infinity();
  result.trusted =
      pairs_ >= options_.min_pairs && result.standard_error <= options_.max_standard_error;
  return result;
}

void DisparityOffsetEstimator::reset() {
  sum_weight_ = sum_weight_squared_ = sum_weighted_offset_ = sum_weighted_square_ = 0.0;
  pairs_ = 0;
}

}  // namespace cvo
