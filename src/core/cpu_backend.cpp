#include "cvo_odometry/core/cpu_backend.hpp"

#include <algorithm>
#include <cmath>

#ifdef _OPENMP
#include <omp.h>
#endif

namespace cvo {

namespace {

// Block size of the deterministic reduction.
constexpr std::size_t kBlockSize = 128;
// Extra scaled distance kept in the candidate lists: the source may move skin * ell before the
// lists must be rebuilt.
constexpr double kSkin = 0.5;

}  // namespace

void CpuBackend::setProblem(const LabeledCloud& target, const LabeledCloud& source,
                            const CvoParams& params) {
  target_ = &target;
  source_ = &source;
  constants_ = makeKernelConstants(params, source.semanticClasses());
  cutoff2_ = retainedScaledDistance2(params);
  candidates_valid_ = false;
  rebuilds_ = 0;
  blocks_.assign((source.size() + kBlockSize - 1) / kBlockSize, Block());
}

int CpuBackend::threadCount() const {
#ifdef _OPENMP
  return num_threads_ > 0 ? num_threads_ : omp_get_max_threads();
#else
  return 1;
#endif
}

std::size_t CpuBackend::candidatePairs() const {
  std::size_t n = 0;
  for (const auto& b : blocks_)
    n += b.target.size();
  return n;
}

void CpuBackend::ensureCandidates(const Eigen::Isometry3d& T, double ell) {
  if (candidates_valid_ && ell == built_ell_) {
    const Eigen::Isometry3d relative = T * built_pose_.inverse();
    const double moved =
        lie::rotationAngle(relative.linear()) * built_radius_ + relative.translation().norm();
    if (moved < kSkin * ell) return;
  }
  buildCandidates(T, ell);
}

void CpuBackend::buildCandidates(const Eigen::Isometry3d& T, double ell) {
  ++rebuilds_;
  const double reach = std::sqrt(cutoff2_) + kSkin;  // scaled joint distance kept
  const float radius = static_cast<float>(reach * ell);
  if (grid_.cellSize() != radius || !candidates_valid_ || ell != built_ell_) {
    grid_.build(target_->positionData().data(), target_->size(), radius);
  }
  float pose[12];
  toRowMajor3x4(T, pose);
  const double max_weight_log =
      std::log(static_cast<double>(constants_.sigma2)) +
      (constants_.use_color ? std::log(constants_.color_sigma2) : 0.0) +
      (constants_.semantic_classes ? std::log(constants_.semantic_sigma2) : 0.0);
  const double inv_ell2 = 1.0 / (ell * ell);
  const double reach2 = reach * reach;
  const float* tgt = target_->positionData().data();
  const float* src = source_->positionData().data();
  const bool color = constants_.use_color;
  const bool semantic = constants_.semantic_classes > 0;
  const long block_count = static_cast<long>(blocks_.size());
  double radius_max = 0.0;
#pragma omp parallel for schedule(dynamic, 1) num_threads(threadCount()) reduction(max : radius_max)
  for (long b = 0; b < block_count; ++b) {
    Block& block = blocks_[b];
    block.offsets.assign(1, 0);
    block.target.clear();
    block.appearance.clear();
    const std::size_t begin = static_cast<std::size_t>(b) * kBlockSize;
    const std::size_t end = std::min(begin + kBlockSize, source_->size());
    for (std::size_t j = begin; j < end; ++j) {
      float z[3];
      kernels::transformPoint(pose, src + 3 * j, z);
      radius_max = std::max(
          radius_max, std::sqrt(double(z[0]) * z[0] + double(z[1]) * z[1] + double(z[2]) * z[2]));
      grid_.forEachWithin(z, radius, [&](std::uint32_t i) {
        const float appearance = kernels::appearanceWeight(
            constants_, color ? target_->color(i) : nullptr, color ? source_->color(j) : nullptr,
            semantic ? target_->semantics(i) : nullptr, semantic ? source_->semantics(j) : nullptr);
        if (!(appearance > 0.0f)) return;
        // Scaled joint distance^2: geometric part plus the appearance part recovered from the
        // weight.
        const double geometric = kernels::squaredDistance(tgt + 3 * i, z, 3) * inv_ell2;
        const double joint = geometric - 2.0 * (std::log(double(appearance)) - max_weight_log);
        if (joint < reach2) {
          block.target.push_back(i);
          block.appearance.push_back(appearance);
        }
      });
      block.offsets.push_back(static_cast<std::uint32_t>(block.target.size()));
    }
  }
  candidates_valid_ = true;
  built_ell_ = ell;
  built_pose_ = T;
  built_radius_ = radius_max;
}

kernels::MomentSums CpuBackend::moments(const Eigen::Isometry3d& T, double ell) {
  ensureCandidates(T, ell);
  float pose[12];
  toRowMajor3x4(T, pose);
  const float inv_two_ell2 = static_cast<float>(0.5 / (ell * ell));
  const float* tgt = target_->positionData().data();
  const float* src = source_->positionData().data();
  const long block_count = static_cast<long>(blocks_.size());
  std::vector<kernels::MomentSums> partial(blocks_.size());
#pragma omp parallel for schedule(dynamic, 1) num_threads(threadCount())
  for (long b = 0; b < block_count; ++b) {
    const Block& block = blocks_[b];
    kernels::MomentSums& m = partial[b];
    kernels::clear(m);
    const std::size_t begin = static_cast<std::size_t>(b) * kBlockSize;
    const std::size_t points = block.offsets.size() - 1;
    for (std::size_t k = 0; k < points; ++k) {
      float z[3];
      kernels::transformPoint(pose, src + 3 * (begin + k), z);
      kernels::PointSums sums;
      kernels::clear(sums);
      unsigned long long pairs = 0;
      for (std::uint32_t c = block.offsets[k]; c < block.offsets[k + 1]; ++c) {
        const float* x = tgt + 3 * block.target[c];
        const float a = kernels::pairWeight(block.appearance[c], kernels::squaredDistance(x, z, 3),
                                            inv_two_ell2);
        if (!kernels::isRetained(a, constants_.sp_thres)) continue;
        kernels::accumulatePair(sums, a, x);
        ++pairs;
      }
      if (pairs > 0) kernels::accumulatePoint(m, sums, z, pairs);
    }
  }
  kernels::MomentSums total;
  kernels::clear(total);
  for (const auto& m : partial)
    kernels::add(total, m);
  return total;
}

kernels::TaylorSums CpuBackend::taylor(const Eigen::Isometry3d& T, const Vector6d& xi, double ell) {
  ensureCandidates(T, ell);
  float pose[12];
  toRowMajor3x4(T, pose);
  const float inv_two_ell2 = static_cast<float>(0.5 / (ell * ell));
  const double inv_ell2 = 1.0 / (ell * ell);
  const float* tgt = target_->positionData().data();
  const float* src = source_->positionData().data();
  const long block_count = static_cast<long>(blocks_.size());
  std::vector<kernels::TaylorSums> partial(blocks_.size());
#pragma omp parallel for schedule(dynamic, 1) num_threads(threadCount())
  for (long b = 0; b < block_count; ++b) {
    const Block& block = blocks_[b];
    kernels::TaylorSums s{0.0, 0.0, 0.0, 0.0};
    const std::size_t begin = static_cast<std::size_t>(b) * kBlockSize;
    const std::size_t points = block.offsets.size() - 1;
    for (std::size_t k = 0; k < points; ++k) {
      float z[3];
      kernels::transformPoint(pose, src + 3 * (begin + k), z);
      kernels::TaylorFrame frame;
      kernels::makeTaylorFrame(z, xi.data(), frame);
      for (std::uint32_t c = block.offsets[k]; c < block.offsets[k + 1]; ++c) {
        const float* x = tgt + 3 * block.target[c];
        const float a = kernels::pairWeight(block.appearance[c], kernels::squaredDistance(x, z, 3),
                                            inv_two_ell2);
        if (!kernels::isRetained(a, constants_.sp_thres)) continue;
        kernels::accumulateTaylorPair(s, frame, x, z, a, inv_ell2);
      }
    }
    partial[b] = s;
  }
  kernels::TaylorSums total{0.0, 0.0, 0.0, 0.0};
  for (const auto& s : partial) {
    total.b += s.b;
    total.c += s.c;
    total.d += s.d;
    total.e += s.e;
  }
  return total;
}

}  // namespace cvo
