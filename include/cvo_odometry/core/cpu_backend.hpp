// CPU backend: candidate-pair lists built from a voxel grid over the target in the joint
// (position, appearance) space, kept across iterations while the source moves less than a skin
// (a Verlet list), evaluated with the shared pair kernels. Sums are taken per fixed block of
// source points and added in block order, so results do not depend on the thread count.
#pragma once

#include <cstdint>
#include <vector>

#include "cvo_odometry/core/block_pool.hpp"
#include "cvo_odometry/core/grid_cache.hpp"
#include "cvo_odometry/core/registration_backend.hpp"
#include "cvo_odometry/core/voxel_grid.hpp"

namespace cvo {

class CpuBackend : public RegistrationBackend {
 public:
  // `num_threads` 0: all cores (OpenMP's default count).
  explicit CpuBackend(int num_threads = 0);

  std::string name() const override { return "cpu"; }
  void setProblem(const LabeledCloud& target, const LabeledCloud& source,
                  const CvoParams& params) override;
  // Copies the subsets into storage kept across calls (new clouds at every level of a
  // registration cost 1.0 ms at 15k points, `cvo_benchmark --time-calls`).
  void useSubsets(const CloudSubsets& subsets) override;
  kernels::MomentSums moments(const Eigen::Isometry3d& T, double ell) override;
  // From the candidate lists of the blocks they hold for, the rest straight from the grid; the
  // lists are left as they are.
  kernels::MomentSums oneOffMoments(const Eigen::Isometry3d& T, double ell) override;
  kernels::TaylorSums taylor(const Eigen::Isometry3d& T, const Vector6d& xi, double ell) override;
  kernels::CurvatureSums curvature(const Eigen::Isometry3d& T, double ell) override;
  void setThreadLimit(int threads) override { pool_.setActiveThreads(threads); }

 private:
  // Candidate pairs of one block of source points, CSR layout. With geometry only every pair's
  // appearance is the same constant: the appearance arrays stay empty.
  struct Block {
    std::vector<std::uint32_t> offsets;  // size = points in block + 1
    // The list is the first `count` entries; the arrays keep their largest size, so that a
    // rebuild writes each entry once instead of zero-filling it first.
    std::size_t count = 0;
    std::vector<float> x, y, z;        // the target point, copied: unit-stride loads vectorise
    std::vector<float> appearance;     // s^2 times the appearance factors of the pair
    std::vector<float> appearance_d2;  // scaled appearance distance (pose independent)
    // The list holds every pair within sqrt(cutoff) + margin (scaled) at `pose` and `ell`.
    bool listed = false;
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    double ell = 0.0;
    double margin = 0.0;
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();  // of the points transformed by `pose`
    double spread = 0.0;                               // their largest distance from centre

    // centre and spread of `points` transformed points (x, y, z interleaved).
    void setExtent(const float* transformed, std::size_t points);

    std::size_t size() const { return count; }
    void clear() { count = 0; }
    // Room for n entries (the appearance arrays too when `with_appearance`).
    void reserve(std::size_t n, bool with_appearance);
    void push(float px, float py, float pz, float weight, float distance2) {
      reserve(count + 1, true);
      x[count] = px;
      y[count] = py;
      z[count] = pz;
      appearance[count] = weight;
      appearance_d2[count] = distance2;
      ++count;
    }
    // Keeps candidate `from` at slot `to` (to <= from), with its appearance when `with_appearance`.
    void move(std::size_t from, std::size_t to, bool with_appearance);
  };

  // How far any point of the block can have moved between its listing pose and T.
  static double movedSinceListed(const Block& block, const Eigen::Isometry3d& T);
  // True when the block's list still holds every pair at (T, ell).
  static bool blockHolds(const Block& block, const Eigen::Isometry3d& T, double ell);
  // True when every block's list holds.
  bool candidatesHold(const Eigen::Isometry3d& T, double ell) const;
  // Brings each block's list to (T, ell): kept while it holds, refiltered after a lengthscale
  // decrease while the margin left allows, else built from the grid (a Verlet list per block).
  void ensureCandidates(const Eigen::Isometry3d& T, double ell);
  // Candidates of block b from the grid (cell `radius`), kept when the scaled joint distance
  // < reach = sqrt(cutoff) + skin. `pose`: row-major 3x4.
  void buildBlock(std::size_t b, const float* pose, double ell, float radius, double reach);
  // After a lengthscale decrease: the joint distance only grows as ell shrinks, so the new list
  // is a filter of the old one, with the old margin less what the block moved since.
  void refilterBlock(std::size_t b, const float* pose, double ell, double margin);
  // The target's grid with this cell size (kept while the problem and size stay; a keyframe's
  // across the frames registered to it, from grids_).
  void ensureGrid(float radius);
  // Moments at the cut-off radius: from a block's list where it holds, else straight from the
  // grid, point_sums(j, T z_j, radius, 1 / (2 ell^2)) giving each source point's sums.
  template <class PointSumsAt>
  kernels::MomentSums sumFromGrid(const Eigen::Isometry3d& T, double ell, PointSumsAt&& point_sums);
  // Geometry only: the moments read from the grid's sorted ranges by the vectorised loop.
  kernels::MomentSums gridMoments(const Eigen::Isometry3d& T, double ell);
  // Scaled appearance distance of target point i and source point j (colour, semantics).
  float appearanceDistance2(std::uint32_t i, std::size_t j) const;
  // Sums of every block of source points, fill(block, sums), added in block order.
  template <class Sums, class Fill>
  Sums sumBlocks(Fill&& fill) const;
  // The moment sums of point k of `block` (at z) over its candidate list.
  kernels::PointSums listSums(const Block& block, std::size_t k, const float* z,
                              float inv_two_ell2) const;
  mutable BlockPool pool_;  // the blocks' threads (sums run from const members too)
  // The clouds the sums run over: setProblem's, or the copies of their subsets.
  void usePoints(const LabeledCloud& target, const LabeledCloud& source);

  const LabeledCloud* whole_target_ = nullptr;
  const LabeledCloud* whole_source_ = nullptr;
  LabeledCloud target_subset_, source_subset_;
  const LabeledCloud* target_ = nullptr;
  const LabeledCloud* source_ = nullptr;
  kernels::KernelConstants constants_{};
  bool constant_appearance_ = true;  // geometry only: every pair's appearance is s^2
  double cutoff2_ = 0.0;             // retained iff scaled joint distance^2 below this
  GridCache grids_;                  // the target's grid, and the last other one (a keyframe's)
  const VoxelGrid* grid_ = nullptr;  // the target's, from grids_
  float grid_radius_ = -1.0f;  // the cell size grid_ was built with, -1: none for this problem
  double direct_ell_ = -1.0;   // lengthscale of the last evaluation read from the grid
  double ell_min_ = 0.0;
  std::vector<Block> blocks_;    // the first block_count_ are this problem's
  std::size_t block_count_ = 0;  // blocks of kBlockSize source points in this problem
  // ensureCandidates' per-block plan, kept to avoid an allocation a call.
  enum class ListUpdate : unsigned char { kKeep, kRefilter, kBuild };
  std::vector<ListUpdate> block_updates_;
  std::vector<double> block_margins_;
};

}  // namespace cvo
