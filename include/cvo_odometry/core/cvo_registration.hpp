// CVO registration of a source cloud to a target cloud: finds T (target <- source) maximising
// F(T) = sum_ij a(x_i, T z_j), with the step method and lengthscale schedule of CvoParams.
#pragma once

#include <memory>
#include <string>

#include <Eigen/Geometry>

#include "cvo_odometry/core/cvo_params.hpp"
#include "cvo_odometry/core/labeled_cloud.hpp"
#include "cvo_odometry/core/registration_backend.hpp"
#include "cvo_odometry/core/registration_report.hpp"

namespace cvo {

struct RegistrationResult {
  Eigen::Isometry3d transform = Eigen::Isometry3d::Identity();  // target <- source
  RegistrationReport report;
};

class CvoRegistration {
 public:
  // Throws std::invalid_argument if `params` make no sense. Without a backend, one is chosen
  // from params.backend (see makeBackend).
  explicit CvoRegistration(const CvoParams& params,
                           std::unique_ptr<RegistrationBackend> backend = nullptr);
  ~CvoRegistration();

  // Throws std::invalid_argument for empty clouds, non-finite points or features the enabled
  // kernels need but the clouds lack. A registration that finds no pairs within the kernels'
  // reach returns converged = false with the guess and says so in the message. The annealing
  // starts at `initial_lengthscale` when > 0, else at ell_first_frame or ell_init.
  RegistrationResult align(const LabeledCloud& target, const LabeledCloud& source,
                           const Eigen::Isometry3d& initial_guess, bool first_frame = false,
                           double initial_lengthscale = 0.0);

  // F(T) at lengthscale `ell` (sparse sum over retained pairs).
  double innerProduct(const LabeledCloud& target, const LabeledCloud& source,
                      const Eigen::Isometry3d& T, double ell);
  // The paper's alignment indicator F / sqrt(|X||Z|).
  double indicator(const LabeledCloud& target, const LabeledCloud& source,
                   const Eigen::Isometry3d& T, double ell);
  // F(X, X) at `ell`: the squared norm of a cloud's function, estimated as the registration
  // sums: over an even sample of its points (1000, or the max_source_points budget if smaller)
  // against all of them, scaled.
  double selfProduct(const LabeledCloud& cloud, double ell);
  // Cosine of the angle between the two functions: F_XZ / sqrt(F_XX F_ZZ), in [0, 1], every sum
  // over every point.
  double cosine(const LabeledCloud& target, const LabeledCloud& source, const Eigen::Isometry3d& T,
                double ell);

  const CvoParams& params() const { return params_; }
  void setParams(const CvoParams& params);
  RegistrationBackend& backend() { return *backend_; }
  // Why `backend: auto` settled on the CPU (no device, a build without CUDA), else empty.
  const std::string& backendNote() const { return backend_note_; }

 private:
  void checkInputs(const LabeledCloud& target, const LabeledCloud& source) const;
  void runProcrustes(const Eigen::Isometry3d& guess, double ell, Eigen::Isometry3d& T,
                     RegistrationReport& report);
  void runReference(const Eigen::Isometry3d& guess, double ell, bool first_frame,
                    Eigen::Isometry3d& T, RegistrationReport& report);

  // How many of the source's points the finest level sums over (max_source_points, procrustes).
  std::size_t sourceBudget(const LabeledCloud& source) const;
  // Sets the backend's problem for lengthscale `ell`: at ell_min the target's points and the
  // source's budget (max_source_points); above it, when subsampling is on, every k-th point of
  // each, k ~ ell / ell_min (the source: no more than its budget), so that pairs per
  // iteration stay near the finest level's. Returns the source's points over those used: the
  // factor that scales the sums to the whole source.
  double useCloudsForLengthscale(double ell);
  double useFinestClouds();

  CvoParams params_;
  std::unique_ptr<RegistrationBackend> backend_;
  std::string backend_note_;
  const LabeledCloud* target_ = nullptr;
  const LabeledCloud* source_ = nullptr;
  // The subsets of align()'s clouds the backend uses now.
  CloudSubsets subsets_;
  // F at the guess from a procrustes run that never left its first lengthscale, else -1.
  double first_weight_at_final_ = -1.0;
};

}  // namespace cvo
