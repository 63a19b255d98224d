#include "cvo_odometry/core/photometric_rotation.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#include <vector>

#include "cvo_odometry/core/lie_group.hpp"
#include "cvo_odometry/core/robust_scale.hpp"
#include "cvo_odometry/core/track_reprojection.hpp"

namespace cvo {

namespace {

constexpr double kStepTolerance = 1e-4;
// Below this correlation of the current intensities with the reference's at the result the two
// images do not show the same scene (a covered lens, a black frame): the rotation is not taken.
constexpr double kMinCorrelation = 0.5;

// Points whose residuals share a cell of this size (px, in the current image) count as one
// cluster when the tracks join: neighbouring intensities share their depth's and the image's
// errors. The cells must hold the correlation (KITTI 06's design effect still grows from 6.0 at
// 16 px cells to 7.5 at 32) yet leave many clusters for the 6x6 M (~300 at 32 px on KITTI's
// cropped image, ~300 at 640x480).
constexpr double kClusterCellPx = 32.0;
// Fewer clusters than this cannot estimate the intensities' 6x6 covariance: no tracks joined.
constexpr std::size_t kMinClusters = 24;
// The tracks' scale never falls below this (px): exact tracks would otherwise weigh infinitely.
constexpr double kMinTrackScalePx = 0.05;

}  // namespace

PhotometricRotationResult refineRotationPhotometrically(
    const IntensityImage& reference, const IntensityImage& current, const LabeledCloud& cloud,
    const Eigen::Isometry3d& reference_from_current, const CvoParams& params, BlockPool* pool,
    const PhotometricTracks* tracks, const PixelRegion* reference_left_out) {
  const auto start = std::chrono::steady_clock::now();
  PhotometricRotationResult out;
  out.transform = reference_from_current;
  PhotometricReport& report = out.report;
  auto finish = [&](const std::string& skipped) {
    report.skipped = skipped;
    report.applied = skipped.empty();
    if (!report.applied) {
      out.transform = reference_from_current;
      report.tracks = 0;  // nothing of theirs is kept
    }
    report.time_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    return out;
  };
  if (reference.levelCount() != current.levelCount()) return finish("image levels differ");
  for (int l = 0; l < reference.levelCount(); ++l) {
    if (reference.blurSigma(l) != current.blurSigma(l)) return finish("image levels differ");
  }
  const std::size_t minimum = static_cast<std::size_t>(params.min_tracking_points);
  const std::size_t n = cloud.size();
  std::vector<Eigen::Vector3d> points(n);
  for (std::size_t j = 0; j < n; ++j)
    points[j] = cloud.position(j).cast<double>();

  Eigen::Isometry3d T = reference_from_current;
  constexpr std::size_t kPointsPerBlock = 512;
  // Per point (NaN residual: not observed), filled in parallel; the normal equations summed per
  // block of points, the blocks added in order: the same sums whatever the thread count.
  std::vector<double> own(n), point_residual(n, NAN);
  std::vector<Vector6d> point_jacobian(n);
  std::optional<TrackReprojection> track_terms;
  if (tracks && tracks->prior && params.photometric_tracks) {
    track_terms.emplace(*tracks->prior, tracks->prior_from_reference);
  }
  // With tracks: each point's cluster (a cell of its own image) and each cluster's gradient.
  std::vector<std::size_t> point_cluster(track_terms ? n : 0);
  std::vector<Vector6d> cluster_g;
  const auto cells_per_row = static_cast<std::size_t>(std::ceil(current.width() / kClusterCellPx));
  const auto cell_rows = static_cast<std::size_t>(std::ceil(current.height() / kClusterCellPx));
  if (track_terms) cluster_g.resize(cells_per_row * cell_rows);
  // Adds the tracks to the intensities' normal equations, each set at its own confidence. The
  // intensities' errors are correlated between neighbours, so they count with their
  // cluster-robust (sandwich) information: their step -H^-1 g has covariance H^-1 M H^-1, M the
  // sum over cells of each cell's gradient outer product, i.e. information H M^-1 H. Left as
  // they are (the intensities alone) when too few cells or tracks are seen.
  auto joinTracks = [&](const Eigen::Isometry3d& T, double huber, Matrix6d* H, Vector6d* g) {
    report.tracks = 0;
    std::fill(cluster_g.begin(), cluster_g.end(), Vector6d::Zero());
    for (std::size_t j = 0; j < n; ++j) {
      const double r = point_residual[j];
      if (std::isnan(r)) continue;
      const double w = huberWeight(std::abs(r), huber);
      cluster_g[point_cluster[j]] += w * r * point_jacobian[j];
    }
    std::size_t clusters = 0;
    Vector6d mean = Vector6d::Zero();
    for (const Vector6d& cell : cluster_g) {
      if (cell.isZero(0.0)) continue;
      mean += cell;
      ++clusters;
    }
    if (clusters < kMinClusters) return;
    // Centred: at the joint estimate the intensities' own gradient need not vanish, and its
    // mean must not count as their scatter.
    mean /= static_cast<double>(clusters);
    Matrix6d M = Matrix6d::Zero();
    for (const Vector6d& cell : cluster_g) {
      if (cell.isZero(0.0)) continue;
      M.noalias() += (cell - mean) * (cell - mean).transpose();
    }
    const Eigen::LDLT<Matrix6d> m_ldlt(M);
    const auto pivots = m_ldlt.vectorD();
    if (m_ldlt.info() != Eigen::Success || !(pivots.minCoeff() > 1e-12 * pivots.maxCoeff())) {
      return;
    }
    Matrix6d track_H = Matrix6d::Zero();
    Vector6d track_g = Vector6d::Zero();
    const std::size_t seen =
        track_terms->addNormalEquations(T, kMinTrackScalePx, &track_H, &track_g);
    if (seen == 0) return;
    const Matrix6d H_Minv = m_ldlt.solve(*H).transpose();  // H M^-1: H and M are symmetric
    const Matrix6d information = H_Minv * *H;
    *H = 0.5 * (information + information.transpose()) + track_H;
    *g = H_Minv * *g + track_g;
    report.tracks = seen;
  };
  std::vector<double> magnitudes;  // |residual| of the observed points, for the median
  magnitudes.reserve(n);
  std::vector<double> median_scratch;
  const std::size_t blocks = (n + kPointsPerBlock - 1) / kPointsPerBlock;
  // Each block's share of the normal equations, summed in block order.
  std::vector<Eigen::Matrix<double, 6, 6>> block_H(blocks);
  std::vector<Eigen::Matrix<double, 6, 1>> block_g(blocks);
  for (int level = 0; level < reference.levelCount(); ++level) {
    // Each point's intensity in its own image (where it was selected), at this blur. A blurred
    // level only steers the finer ones: every (2 sigma)-th point of the cloud's order serves it
    // (TUM fr1_xyz: the same rotation at strides 1, 3 and 5, the stage 5.0 -> 3.2 ms), and the
    // points it needs in view are fewer by as much. The last, unblurred level uses every point.
    const auto stride =
        static_cast<std::size_t>(std::max(1.0, std::floor(2.0 * reference.blurSigma(level))));
    const std::size_t needed = std::max<std::size_t>(minimum / stride, 6);
    forEachInBlocks(pool, n, kPointsPerBlock, [&](std::size_t j) {
      own[j] = NAN;
      if (j % stride != 0) return;
      if (!(points[j].z() > 0.0)) return;
      const Eigen::Vector2d p = current.camera().project(points[j]);
      if (!current.inside(p.x(), p.y()) || !current.usable(p.x(), p.y())) return;
      own[j] = current.intensity(level, p.x(), p.y());
      if (!point_cluster.empty()) {
        point_cluster[j] = static_cast<std::size_t>(p.y() / kClusterCellPx) * cells_per_row +
                           static_cast<std::size_t>(p.x() / kClusterCellPx);
      }
    });
    double median = 0.0;  // of the level's last iteration: the next one's is near it
    for (int it = 0; it < params.photometric_iterations; ++it) {
      forEachInBlocks(pool, n, kPointsPerBlock, [&](std::size_t j) {
        point_residual[j] = NAN;
        if (std::isnan(own[j])) return;
        const Eigen::Vector3d Y = T * points[j];
        if (!(Y.z() > 0.0)) return;
        const Eigen::Vector2d p = reference.camera().project(Y);
        // Where the reference saw a moving or ignored class the intensities belong to it.
        if (!reference.inside(p.x(), p.y()) || !reference.usable(p.x(), p.y()) ||
            (reference_left_out && reference_left_out->contains(p.x(), p.y()))) {
          return;
        }
        const IntensitySample s = reference.sample(level, p.x(), p.y());
        // d I / d Y, then the left perturbation Y + omega x Y + v.
        const Eigen::Vector3d dI = reference.camera().pinholeJacobian(Y).transpose() *
                                   Eigen::Vector2d(s.gradient_u, s.gradient_v);
        point_jacobian[j] << Y.cross(dI), dI;
        point_residual[j] = s.intensity - own[j];
      });
      magnitudes.clear();
      for (std::size_t j = 0; j < n; ++j) {
        if (!std::isnan(point_residual[j])) magnitudes.push_back(std::abs(point_residual[j]));
      }
      report.points = magnitudes.size();
      if (magnitudes.size() < needed) {
        return finish("only " + std::to_string(magnitudes.size()) + " of " +
                      std::to_string((n + stride - 1) / stride) +
                      " points inside the reference image at blur level " + std::to_string(level));
      }
      median = medianNear(magnitudes, median, median_scratch);
      const double scale = std::max(kMadToSigma * median, 1e-6);
      const double huber = kHuberScale * scale;
      forEachBlock(pool, blocks, [&](std::size_t b) {
        Eigen::Matrix<double, 6, 6> H = Eigen::Matrix<double, 6, 6>::Zero();
        Eigen::Matrix<double, 6, 1> g = Eigen::Matrix<double, 6, 1>::Zero();
        const std::size_t end = std::min(n, (b + 1) * kPointsPerBlock);
        for (std::size_t j = b * kPointsPerBlock; j < end; ++j) {
          const double r = point_residual[j];
          if (std::isnan(r)) continue;
          const double w = huberWeight(std::abs(r), huber);
          // Fixed-size outer product: unrolled, far cheaper than a triangular rank update.
          H.noalias() += (w * point_jacobian[j]) * point_jacobian[j].transpose();
          g += w * r * point_jacobian[j];
        }
        block_H[b] = H;
        block_g[b] = g;
      });
      Eigen::Matrix<double, 6, 6> H = Eigen::Matrix<double, 6, 6>::Zero();
      Eigen::Matrix<double, 6, 1> g = Eigen::Matrix<double, 6, 1>::Zero();
      for (std::size_t b = 0; b < blocks; ++b) {
        H += block_H[b];
        g += block_g[b];
      }
      if (track_terms) joinTracks(T, huber, &H, &g);
      const Eigen::LDLT<Eigen::Matrix<double, 6, 6>> ldlt(H);
      const Eigen::Matrix<double, 6, 1> xi = -ldlt.solve(g);
      ++report.iterations;
      if (ldlt.info() != Eigen::Success || !xi.allFinite()) return finish("degenerate solve");
      Eigen::Isometry3d step = Eigen::Isometry3d::Identity();
      step.linear() = lie::expSO3(xi.head<3>());
      step.translation() = xi.tail<3>();
      T = step * T;
      if (xi.norm() < kStepTolerance) break;
    }
  }
  // Correlation of own and reference intensities (reference = own + residual) at the last step.
  double mean_own = 0.0, mean_ref = 0.0;
  std::size_t observed = 0;
  for (std::size_t j = 0; j < n; ++j) {
    if (std::isnan(point_residual[j])) continue;
    mean_own += own[j];
    mean_ref += own[j] + point_residual[j];
    ++observed;
  }
  mean_own /= static_cast<double>(observed);
  mean_ref /= static_cast<double>(observed);
  double s_oo = 0.0, s_rr = 0.0, s_or = 0.0;
  for (std::size_t j = 0; j < n; ++j) {
    if (std::isnan(point_residual[j])) continue;
    const double o = own[j] - mean_own, r = own[j] + point_residual[j] - mean_ref;
    s_oo += o * o;
    s_rr += r * r;
    s_or += o * r;
  }
  report.correlation = s_oo > 0.0 && s_rr > 0.0 ? s_or / std::sqrt(s_oo * s_rr) : 0.0;
  if (!(report.correlation >= kMinCorrelation)) {
    return finish("images do not match (intensity correlation " +
                  std::to_string(report.correlation) + ")");
  }
  const Eigen::AngleAxisd change(T.linear() * reference_from_current.linear().transpose());
  report.correction_deg = std::abs(change.angle()) * 180.0 / M_PI;
  if (!(report.correction_deg <= params.photometric_max_correction)) {
    return finish("correction " + std::to_string(report.correction_deg) +
                  " deg > photometric_max_correction");
  }
  out.transform.linear() = lie::orthonormalized(T).linear();
  out.transform.translation() = params.photometric_translation
                                    ? Eigen::Vector3d(T.translation())
                                    : Eigen::Vector3d(reference_from_current.translation());
  return finish("");
}

}  // namespace cvo
