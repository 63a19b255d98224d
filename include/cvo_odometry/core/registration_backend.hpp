// Where the double sums of CVO are computed. The registration algorithm (steps, schedule,
// convergence) is shared; a backend only evaluates sums over retained pairs, the same sums on
// every backend (up to floating-point rounding).
#pragma once

#include <cstddef>
#include <memory>
#include <string>

#include <Eigen/Geometry>

#include <optional>

#include "cvo_odometry/core/cvo_params.hpp"
#include "cvo_odometry/core/device_pair_sums.hpp"
#include "cvo_odometry/core/labeled_cloud.hpp"
#include "cvo_odometry/core/lie_group.hpp"
#include "cvo_odometry/core/pair_kernels.hpp"

namespace cvo {

// Which points of setProblem's clouds the following calls sum over (a registration's coarse
// levels and its source budget): the target's every target_stride-th point, from the first; the
// source's every source_stride-th point, or, where source_count is not 0, source_count points
// spread evenly over the whole source (LabeledCloud::thinnedInto's points). The default: every
// point of both.
struct CloudSubsets {
  std::size_t target_stride = 1;
  std::size_t source_stride = 1;
  std::size_t source_count = 0;

  bool operator==(const CloudSubsets& o) const {
    return target_stride == o.target_stride && source_stride == o.source_stride &&
           source_count == o.source_count;
  }
  bool operator!=(const CloudSubsets& o) const { return !(*this == o); }
  // The subsets as copies (a backend that does not index the whole clouds).
  void targetInto(const LabeledCloud& target, LabeledCloud& out) const;
  void sourceInto(const LabeledCloud& source, LabeledCloud& out) const;
  bool wholeTarget() const { return target_stride <= 1; }
  bool wholeSource(std::size_t source_size) const {
    return source_count == 0 ? source_stride <= 1 : source_count >= source_size;
  }
};

class RegistrationBackend {
 public:
  virtual ~RegistrationBackend() = default;
  virtual std::string name() const = 0;

  // The clouds and kernel settings for the following calls, every point of both used. The
  // clouds must stay alive and unchanged until the next setProblem: a device backend copies
  // them to the device here, and only here.
  virtual void setProblem(const LabeledCloud& target, const LabeledCloud& source,
                          const CvoParams& params) = 0;
  // From the next call on, only `subsets` of the clouds of the last setProblem.
  virtual void useSubsets(const CloudSubsets& subsets) = 0;
  // Sums over the retained pairs (x_i, T z_j) at lengthscale `ell`.
  virtual kernels::MomentSums moments(const Eigen::Isometry3d& T, double ell) = 0;
  // The same sums at a pose that the following calls will not come back near (an indicator at
  // the initial guess, a self product): a backend need not build what it would reuse.
  virtual kernels::MomentSums oneOffMoments(const Eigen::Isometry3d& T, double ell) {
    return moments(T, ell);
  }
  // Taylor coefficients of F(exp(t xi) T) in t, over the pairs retained at T.
  virtual kernels::TaylorSums taylor(const Eigen::Isometry3d& T, const Vector6d& xi,
                                     double ell) = 0;
  // Gradient and Hessian of sum (a - sp_thres)_+ at exp(xi) T, xi = 0, over the pairs retained
  // at T (the Newton step at the finest lengthscale).
  virtual kernels::CurvatureSums curvature(const Eigen::Isometry3d& T, double ell) = 0;
  // From the next call on, use at most `threads` CPU threads (>= 1; ThreadGovernor). Backends
  // without CPU threads of their own ignore it; results do not depend on it.
  virtual void setThreadLimit(int /*threads*/) {}
  // The device code's work so far (cuda, device_cpu); none for the CPU backend.
  virtual std::optional<DeviceWork> deviceWork() const { return std::nullopt; }
};

// Squared cut-off of the scaled joint distance D^2 = |x - z|^2 / ell^2 + sum_V |u - v|^2 / ell_V^2:
// a pair can be retained only if D^2 < this (its kernel product is then above sp_thres).
double retainedScaledDistance2(const CvoParams& params);
kernels::KernelConstants makeKernelConstants(const CvoParams& params, int semantic_classes);
// Row-major 3x4 float copy of T for the kernels.
void toRowMajor3x4(const Eigen::Isometry3d& T, float* out);

}  // namespace cvo
