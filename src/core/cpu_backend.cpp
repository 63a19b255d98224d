#include "cvo_odometry/core/cpu_backend.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace cvo {

namespace {

// Block size of the deterministic reduction.
constexpr std::size_t kBlockSize = 128;
// Extra scaled distance kept in freshly built candidate lists: the source may move margin * ell
// before the lists must be rebuilt. A registration from a feature prior moves 0.3-0.5 ell in
// its first steps: at 0.35 most frames rebuilt every list once or twice, at 1.0 the lists are
// longer but mostly built once (one thread, TUM fr1_xyz: registration median 15.8-16.3 ->
// 13.7-14.7 ms, p95 31-33 -> 27-28; KITTI 06 8.2-8.4 -> 6.9-7.9 ms).
constexpr double kSkin = 1.0;
// Below this margin a lengthscale decrease rebuilds from the grid instead of refiltering.
constexpr double kMinMargin = 0.2;

// Sums over the `count` candidates of one source point z. `appearance` null: every pair's
// appearance factor is `constant` (geometry only). Plain float reductions so that the compiler
// vectorises the loop; compiled for AVX-512, AVX2 and baseline x86-64, picked at load time.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define CVO_CPU_DISPATCH __attribute__((target_clones("avx512f", "avx2", "default")))
#else
#define CVO_CPU_DISPATCH
#endif
CVO_CPU_DISPATCH kernels::PointSums sumCandidates(const float* xs, const float* ys, const float* zs,
                                                  const float* appearance, float constant,
                                                  int count, const float* z, float inv_two_ell2,
                                                  float sp_thres) {
  const float zx = z[0], zy = z[1], zz = z[2];
  float weight = 0.0f, ox = 0.0f, oy = 0.0f, oz = 0.0f, pairs = 0.0f;
  if (appearance == nullptr) {
#pragma omp simd reduction(+ : weight, ox, oy, oz, pairs)
    for (int c = 0; c < count; ++c) {
      const float dx = xs[c] - zx, dy = ys[c] - zy, dz = zs[c] - zz;
      const float a = kernels::retainedPairWeight(constant, dx, dy, dz, inv_two_ell2, sp_thres);
      weight += a;
      ox += a * dx;
      oy += a * dy;
      oz += a * dz;
      pairs += a > 0.0f ? 1.0f : 0.0f;
    }
  } else {
#pragma omp simd reduction(+ : weight, ox, oy, oz, pairs)
    for (int c = 0; c < count; ++c) {
      const float dx = xs[c] - zx, dy = ys[c] - zy, dz = zs[c] - zz;
      const float a =
          kernels::retainedPairWeight(appearance[c], dx, dy, dz, inv_two_ell2, sp_thres);
      weight += a;
      ox += a * dx;
      oy += a * dy;
      oz += a * dz;
      pairs += a > 0.0f ? 1.0f : 0.0f;
    }
  }
  return kernels::PointSums{weight, {ox, oy, oz}, static_cast<unsigned int>(pairs)};
}

// The curvature sums of one source point over its candidates (as sumCandidates).
CVO_CPU_DISPATCH kernels::PointCurvature curvatureOfCandidates(
    const float* xs, const float* ys, const float* zs, const float* appearance, float constant,
    int count, const float* z, float inv_two_ell2, float sp_thres, float inv_shell_width) {
  const float zx = z[0], zy = z[1], zz = z[2];
  const float shell_top = sp_thres + 1.0f / inv_shell_width;
  float w = 0.0f, ox = 0.0f, oy = 0.0f, oz = 0.0f;
  float sxx = 0.0f, sxy = 0.0f, sxz = 0.0f, syy = 0.0f, syz = 0.0f, szz = 0.0f;
  float bxx = 0.0f, bxy = 0.0f, bxz = 0.0f, byy = 0.0f, byz = 0.0f, bzz = 0.0f, pairs = 0.0f;
#pragma omp simd reduction(+ : w, ox, oy, oz, sxx, sxy, sxz, syy, syz, szz, bxx, bxy, bxz, byy, \
                               byz, bzz, pairs)
  for (int c = 0; c < count; ++c) {
    const float dx = xs[c] - zx, dy = ys[c] - zy, dz = zs[c] - zz;
    const float a = kernels::retainedPairWeight(appearance ? appearance[c] : constant, dx, dy, dz,
                                                inv_two_ell2, sp_thres);
    const float shell = kernels::shellWeight(a, shell_top, inv_shell_width);
    w += a;
    pairs += a > 0.0f ? 1.0f : 0.0f;
    ox += a * dx;
    oy += a * dy;
    oz += a * dz;
    sxx += a * dx * dx;
    sxy += a * dx * dy;
    sxz += a * dx * dz;
    syy += a * dy * dy;
    syz += a * dy * dz;
    szz += a * dz * dz;
    bxx += shell * dx * dx;
    bxy += shell * dx * dy;
    bxz += shell * dx * dz;
    byy += shell * dy * dy;
    byz += shell * dy * dz;
    bzz += shell * dz * dz;
  }
  return kernels::PointCurvature{w,
                                 {ox, oy, oz},
                                 {sxx, sxy, sxz, syy, syz, szz},
                                 {bxx, bxy, bxz, byy, byz, bzz},
                                 static_cast<unsigned int>(pairs)};
}

}  // namespace

void CpuBackend::Block::reserve(std::size_t n, bool with_appearance) {
  // Each array on its own: one left short by a failed allocation must not pass for grown.
  const auto grow = [n](std::vector<float>& v) {
    if (v.size() < n) v.resize(std::max(n, 2 * v.size()));
  };
  for (auto* v : {&x, &y, &z})
    grow(*v);
  if (with_appearance) {
    grow(appearance);
    grow(appearance_d2);
  }
}

void CpuBackend::Block::move(std::size_t from, std::size_t to, bool with_appearance) {
  x[to] = x[from];
  y[to] = y[from];
  z[to] = z[from];
  if (with_appearance) {
    appearance[to] = appearance[from];
    appearance_d2[to] = appearance_d2[from];
  }
}

CpuBackend::CpuBackend(int num_threads) : pool_(resolvedThreadCount(num_threads)) {}

void CpuBackend::setProblem(const LabeledCloud& target, const LabeledCloud& source,
                            const CvoParams& params) {
  whole_target_ = &target;
  whole_source_ = &source;
  constants_ = makeKernelConstants(params, source.semanticClasses());
  constant_appearance_ = !constants_.use_color && constants_.semantic_classes == 0;
  cutoff2_ = retainedScaledDistance2(params);
  ell_min_ = params.ell_min;
  usePoints(target, source);
}

void CpuBackend::useSubsets(const CloudSubsets& subsets) {
  if (!whole_target_) throw std::logic_error("useSubsets before setProblem");
  const LabeledCloud* target = whole_target_;
  const LabeledCloud* source = whole_source_;
  if (!subsets.wholeTarget()) {
    subsets.targetInto(*whole_target_, target_subset_);
    target = &target_subset_;
  }
  if (!subsets.wholeSource(whole_source_->size())) {
    subsets.sourceInto(*whole_source_, source_subset_);
    source = &source_subset_;
  }
  usePoints(*target, *source);
}

void CpuBackend::usePoints(const LabeledCloud& target, const LabeledCloud& source) {
  target_ = &target;
  source_ = &source;
  direct_ell_ = -1.0;
  grid_radius_ = -1.0f;
  // Blocks keep their storage across problems, those beyond a smaller problem's count too: the
  // registration's levels, its self products and each frame alternate problem sizes, and a
  // block made anew grew its lists from nothing again (reallocations and page faults).
  block_count_ = (source.size() + kBlockSize - 1) / kBlockSize;
  if (blocks_.size() < block_count_) blocks_.resize(block_count_);
  for (std::size_t b = 0; b < block_count_; ++b)
    blocks_[b].listed = false;
}

double CpuBackend::movedSinceListed(const Block& block, const Eigen::Isometry3d& T) {
  // A point c + d (|d| <= spread) of the block moves by |M c - c| + |(R - I) d| under the
  // motion M since the listing, and |(R - I) d| <= angle(R) |d|.
  const Eigen::Isometry3d motion = T * block.pose.inverse();
  return (motion * block.centre - block.centre).norm() +
         lie::rotationAngle(motion.linear()) * block.spread;
}

bool CpuBackend::blockHolds(const Block& block, const Eigen::Isometry3d& T, double ell) {
  return block.listed && ell == block.ell && movedSinceListed(block, T) < block.margin * ell;
}

bool CpuBackend::candidatesHold(const Eigen::Isometry3d& T, double ell) const {
  return std::all_of(blocks_.begin(), blocks_.begin() + static_cast<std::ptrdiff_t>(block_count_),
                     [&](const Block& block) { return blockHolds(block, T, ell); });
}

void CpuBackend::ensureCandidates(const Eigen::Isometry3d& T, double ell) {
  // Each block decides for itself: points near the motion's axis keep their lists longest.
  using Update = ListUpdate;
  std::vector<Update>& updates = block_updates_;
  std::vector<double>& margins = block_margins_;
  updates.assign(block_count_, Update::kBuild);
  margins.assign(block_count_, kSkin);
  bool any_build = false, any_change = false;
  for (std::size_t b = 0; b < block_count_; ++b) {
    const Block& block = blocks_[b];
    if (blockHolds(block, T, ell)) {
      updates[b] = Update::kKeep;
      continue;
    }
    any_change = true;
    if (block.listed && ell < block.ell) {
      const double margin = block.margin - movedSinceListed(block, T) / block.ell;
      if (margin >= kMinMargin) {
        updates[b] = Update::kRefilter;
        margins[b] = margin;
        continue;
      }
    }
    any_build = true;
  }
  if (!any_change) return;
  const double reach = std::sqrt(cutoff2_) + kSkin;  // scaled joint distance a build keeps
  const float radius = static_cast<float>(reach * ell);
  if (any_build) ensureGrid(radius);
  float pose[12];
  toRowMajor3x4(T, pose);
  pool_.run(block_count_, [&](std::size_t b) {
    if (updates[b] == Update::kKeep) return;
    Block& block = blocks_[b];
    block.listed = false;  // until the list is whole again (an allocation may throw)
    if (updates[b] == Update::kRefilter) {
      refilterBlock(b, pose, ell, margins[b]);
    } else {
      buildBlock(b, pose, ell, radius, reach);
    }
    block.listed = true;
    block.pose = T;
    block.ell = ell;
    block.margin = margins[b];
  });
}

void CpuBackend::Block::setExtent(const float* transformed, std::size_t points) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (std::size_t k = 0; k < points; ++k)
    sum += Eigen::Vector3d(transformed[3 * k], transformed[3 * k + 1], transformed[3 * k + 2]);
  centre = points ? Eigen::Vector3d(sum / static_cast<double>(points)) : sum;
  spread = 0.0;
  for (std::size_t k = 0; k < points; ++k) {
    const Eigen::Vector3d z(transformed[3 * k], transformed[3 * k + 1], transformed[3 * k + 2]);
    spread = std::max(spread, (z - centre).norm());
  }
}

void CpuBackend::buildBlock(std::size_t b, const float* pose, double ell, float radius,
                            double reach) {
  const float inv_ell2 = static_cast<float>(1.0 / (ell * ell));
  const float reach2 = static_cast<float>(reach * reach);
  const float radius2 = radius * radius;
  const float* tgt = target_->positionData().data();
  const float* src = source_->positionData().data();
  const float *xs = grid_->sortedX(), *ys = grid_->sortedY(), *zs = grid_->sortedZ();
  Block& block = blocks_[b];
  block.offsets.assign(1, 0);
  block.clear();
  const std::size_t begin = b * kBlockSize;
  const std::size_t end = std::min(begin + kBlockSize, source_->size());
  float transformed[3 * kBlockSize];
  for (std::size_t j = begin; j < end; ++j) {
    float* z = transformed + 3 * (j - begin);
    kernels::transformPoint(pose, src + 3 * j, z);
    if (constant_appearance_) {
      // Geometry only: the radius test is the joint-distance test.
      // Every slot of the range written, the next one's start moved on only past a kept point:
      // no branch to mispredict (about a third of a range is kept).
      grid_->forEachRange(z, radius, [&](std::uint32_t first, std::uint32_t last) {
        block.reserve(block.count + (last - first), false);
        float *bx = block.x.data(), *by = block.y.data(), *bz = block.z.data();
        std::size_t kept = block.count;
        for (std::uint32_t k = first; k < last; ++k) {
          const float dx = xs[k] - z[0], dy = ys[k] - z[1], dz = zs[k] - z[2];
          bx[kept] = xs[k];
          by[kept] = ys[k];
          bz[kept] = zs[k];
          kept += dx * dx + dy * dy + dz * dz <= radius2 ? 1 : 0;
        }
        block.count = kept;
      });
    } else {
      grid_->forEachWithin(z, radius, [&](std::uint32_t i, float distance2) {
        const float appearance_d2 = appearanceDistance2(i, j);
        if (distance2 * inv_ell2 + appearance_d2 >= reach2) return;
        const float* x = tgt + 3 * i;
        block.push(x[0], x[1], x[2], kernels::appearanceWeight(constants_, appearance_d2),
                   appearance_d2);
      });
    }
    block.offsets.push_back(static_cast<std::uint32_t>(block.size()));
  }
  block.setExtent(transformed, end - begin);
}

void CpuBackend::refilterBlock(std::size_t b, const float* pose, double ell, double margin) {
  const double reach = std::sqrt(cutoff2_) + margin;
  const float inv_ell2 = static_cast<float>(1.0 / (ell * ell));
  const float reach2 = static_cast<float>(reach * reach);
  const float* src = source_->positionData().data();
  Block& block = blocks_[b];
  const std::size_t begin = b * kBlockSize;
  const std::size_t points = block.offsets.size() - 1;
  float transformed[3 * kBlockSize];
  std::uint32_t kept = 0, first = 0;
  for (std::size_t k = 0; k < points; ++k) {
    float* z = transformed + 3 * k;
    kernels::transformPoint(pose, src + 3 * (begin + k), z);
    const std::uint32_t last = block.offsets[k + 1];
    for (std::uint32_t c = first; c < last; ++c) {
      const float x[3] = {block.x[c], block.y[c], block.z[c]};
      const float d2 = kernels::squaredDistance(x, z, 3) * inv_ell2;
      if (d2 + (constant_appearance_ ? 0.0f : block.appearance_d2[c]) >= reach2) continue;
      block.move(c, kept++, !constant_appearance_);
    }
    first = last;
    block.offsets[k + 1] = kept;
  }
  block.count = kept;
  block.setExtent(transformed, points);
}

template <class Sums, class Fill>
Sums CpuBackend::sumBlocks(Fill&& fill) const {
  std::vector<Sums> partial(block_count_);
  pool_.run(block_count_, [&](std::size_t b) {
    kernels::clear(partial[b]);
    fill(b, partial[b]);
  });
  Sums total;
  kernels::clear(total);
  for (const auto& m : partial)
    kernels::add(total, m);
  return total;
}

kernels::PointSums CpuBackend::listSums(const Block& block, std::size_t k, const float* z,
                                        float inv_two_ell2) const {
  const std::uint32_t first = block.offsets[k];
  return sumCandidates(block.x.data() + first, block.y.data() + first, block.z.data() + first,
                       constant_appearance_ ? nullptr : block.appearance.data() + first,
                       constants_.max_weight, static_cast<int>(block.offsets[k + 1] - first), z,
                       inv_two_ell2, constants_.sp_thres);
}

float CpuBackend::appearanceDistance2(std::uint32_t i, std::size_t j) const {
  const bool color = constants_.use_color, semantic = constants_.semantic_classes > 0;
  return kernels::appearanceDistance2(
      constants_, color ? target_->color(i) : nullptr, color ? source_->color(j) : nullptr,
      semantic ? target_->semantics(i) : nullptr, semantic ? source_->semantics(j) : nullptr);
}

void CpuBackend::ensureGrid(float radius) {
  if (radius == grid_radius_) return;
  grid_ = &grids_.grid(target_->positionData().data(), target_->size(), radius);
  grid_radius_ = radius;
}

kernels::MomentSums CpuBackend::moments(const Eigen::Isometry3d& T, double ell) {
  if (constant_appearance_ && ell > ell_min_ && ell != direct_ell_ && !candidatesHold(T, ell)) {
    // Geometry only, a coarse level's first evaluation (often its only one): reading the grid
    // costs less than building lists that may not be used again. At ell_min, where the
    // registration iterates to convergence, the lists pay off at once.
    direct_ell_ = ell;
    return gridMoments(T, ell);
  }
  ensureCandidates(T, ell);
  float pose[12];
  toRowMajor3x4(T, pose);
  const float inv_two_ell2 = static_cast<float>(0.5 / (ell * ell));
  const float* src = source_->positionData().data();
  return sumBlocks<kernels::MomentSums>([&](std::size_t b, kernels::MomentSums& m) {
    const Block& block = blocks_[b];
    const std::size_t begin = b * kBlockSize;
    for (std::size_t k = 0; k + 1 < block.offsets.size(); ++k) {
      float z[3];
      kernels::transformPoint(pose, src + 3 * (begin + k), z);
      const kernels::PointSums sums = listSums(block, k, z, inv_two_ell2);
      if (sums.pairs > 0) kernels::accumulatePoint(m, sums, z);
    }
  });
}

template <class PointSumsAt>
kernels::MomentSums CpuBackend::sumFromGrid(const Eigen::Isometry3d& T, double ell,
                                            PointSumsAt&& point_sums) {
  // Only pairs within the cut-off can be retained: the grid at that radius, no skin.
  const float radius = static_cast<float>(std::sqrt(cutoff2_) * ell);
  ensureGrid(radius);
  float pose[12];
  toRowMajor3x4(T, pose);
  const float inv_two_ell2 = static_cast<float>(0.5 / (ell * ell));
  const float* src = source_->positionData().data();
  return sumBlocks<kernels::MomentSums>([&](std::size_t b, kernels::MomentSums& m) {
    const Block& block = blocks_[b];
    // A block whose list still holds sums it: the same pairs, fewer visited.
    const bool listed = blockHolds(block, T, ell);
    const std::size_t begin = b * kBlockSize;
    const std::size_t end = std::min(begin + kBlockSize, source_->size());
    for (std::size_t j = begin; j < end; ++j) {
      float z[3];
      kernels::transformPoint(pose, src + 3 * j, z);
      const kernels::PointSums sums = listed ? listSums(block, j - begin, z, inv_two_ell2)
                                             : point_sums(j, z, radius, inv_two_ell2);
      if (sums.pairs > 0) kernels::accumulatePoint(m, sums, z);
    }
  });
}

kernels::MomentSums CpuBackend::gridMoments(const Eigen::Isometry3d& T, double ell) {
  return sumFromGrid(T, ell, [&](std::size_t, const float* z, float radius, float inv_two_ell2) {
    // The grid is (re)built by sumFromGrid: its arrays are read here, after that.
    const float *xs = grid_->sortedX(), *ys = grid_->sortedY(), *zs = grid_->sortedZ();
    // A point's ranges copied into one run: one vectorised loop a point, not one a range
    // (pairs beyond the cut-off in the ranges weigh 0 in the loop).
    thread_local std::vector<float> run_x, run_y, run_z;
    run_x.clear();
    run_y.clear();
    run_z.clear();
    grid_->forEachRange(z, radius, [&](std::uint32_t first, std::uint32_t last) {
      run_x.insert(run_x.end(), xs + first, xs + last);
      run_y.insert(run_y.end(), ys + first, ys + last);
      run_z.insert(run_z.end(), zs + first, zs + last);
    });
    return sumCandidates(run_x.data(), run_y.data(), run_z.data(), nullptr, constants_.max_weight,
                         static_cast<int>(run_x.size()), z, inv_two_ell2, constants_.sp_thres);
  });
}

kernels::MomentSums CpuBackend::oneOffMoments(const Eigen::Isometry3d& T, double ell) {
  if (constant_appearance_) return gridMoments(T, ell);
  const float* tgt = target_->positionData().data();
  return sumFromGrid(T, ell, [&](std::size_t j, const float* z, float radius, float inv_two_ell2) {
    kernels::PointSums sums;
    kernels::clear(sums);
    grid_->forEachWithin(z, radius, [&](std::uint32_t i, float) {
      const float* x = tgt + 3 * i;
      const float appearance = kernels::appearanceWeight(constants_, appearanceDistance2(i, j));
      const float a = kernels::retainedPairWeight(appearance, x[0] - z[0], x[1] - z[1], x[2] - z[2],
                                                  inv_two_ell2, constants_.sp_thres);
      kernels::accumulatePair(sums, a, x[0] - z[0], x[1] - z[1], x[2] - z[2]);
    });
    return sums;
  });
}

kernels::CurvatureSums CpuBackend::curvature(const Eigen::Isometry3d& T, double ell) {
  ensureCandidates(T, ell);
  float pose[12];
  toRowMajor3x4(T, pose);
  const float inv_two_ell2 = static_cast<float>(0.5 / (ell * ell));
  const double inv_ell2 = 1.0 / (ell * ell);
  const float inv_shell_width = kernels::inverseShellWidth(constants_.sp_thres);
  const float* src = source_->positionData().data();
  return sumBlocks<kernels::CurvatureSums>([&](std::size_t b, kernels::CurvatureSums& c) {
    const Block& block = blocks_[b];
    const std::size_t begin = b * kBlockSize;
    for (std::size_t k = 0; k + 1 < block.offsets.size(); ++k) {
      float z[3];
      kernels::transformPoint(pose, src + 3 * (begin + k), z);
      if ((begin + k) % kernels::kCurvatureStride != 0) {
        const kernels::PointSums sums = listSums(block, k, z, inv_two_ell2);
        if (sums.pairs > 0) kernels::accumulatePoint(c.moments, sums, z);
        continue;
      }
      const std::uint32_t first = block.offsets[k];
      const kernels::PointCurvature sums = curvatureOfCandidates(
          block.x.data() + first, block.y.data() + first, block.z.data() + first,
          constant_appearance_ ? nullptr : block.appearance.data() + first, constants_.max_weight,
          static_cast<int>(block.offsets[k + 1] - first), z, inv_two_ell2, constants_.sp_thres,
          inv_shell_width);
      kernels::accumulatePointCurvature(c, sums, z, inv_ell2, kernels::kCurvatureStride);
    }
  });
}

kernels::TaylorSums CpuBackend::taylor(const Eigen::Isometry3d& T, const Vector6d& xi, double ell) {
  ensureCandidates(T, ell);
  float pose[12];
  toRowMajor3x4(T, pose);
  const float inv_two_ell2 = static_cast<float>(0.5 / (ell * ell));
  const double inv_ell2 = 1.0 / (ell * ell);
  const float* src = source_->positionData().data();
  return sumBlocks<kernels::TaylorSums>([&](std::size_t b, kernels::TaylorSums& s) {
    const Block& block = blocks_[b];
    const std::size_t begin = b * kBlockSize;
    for (std::size_t k = 0; k + 1 < block.offsets.size(); ++k) {
      float z[3];
      kernels::transformPoint(pose, src + 3 * (begin + k), z);
      kernels::TaylorFrame frame;
      kernels::makeTaylorFrame(z, xi.data(), frame);
      for (std::uint32_t c = block.offsets[k]; c < block.offsets[k + 1]; ++c) {
        const float x[3] = {block.x[c], block.y[c], block.z[c]};
        const float appearance = constant_appearance_ ? constants_.max_weight : block.appearance[c];
        const float a = kernels::retainedPairWeight(appearance, x[0] - z[0], x[1] - z[1],
                                                    x[2] - z[2], inv_two_ell2, constants_.sp_thres);
        if (a > 0.0f) kernels::accumulateTaylorPair(s, frame, x, z, a, inv_ell2);
      }
    }
  });
}

}  // namespace cvo
