// A backend that forwards every call to another and tallies the calls and the wall time they
// took, by kind: how a registration's time splits between the backend (on a GPU: launches,
// kernels and the wait for each result) and the registration's own steps between calls
// (cvo_benchmark --time-calls). Wrapping hides a FailoverBackend from the registration, so a GPU
// failure is not replayed on the CPU: a benchmark's concern, not the odometry's.
#pragma once

#include <array>
#include <memory>
#include <string>

#include "cvo_odometry/core/registration_backend.hpp"

namespace cvo {

class TimedBackend : public RegistrationBackend {
 public:
  enum Call { kSetProblem, kUseSubsets, kMoments, kOneOffMoments, kTaylor, kCurvature, kCallKinds };
  struct Tally {
    long calls = 0;
    double ms = 0.0;
  };

  explicit TimedBackend(std::unique_ptr<RegistrationBackend> inner);

  std::string name() const override { return inner_->name(); }
  void setProblem(const LabeledCloud& target, const LabeledCloud& source,
                  const CvoParams& params) override;
  void useSubsets(const CloudSubsets& subsets) override;
  kernels::MomentSums moments(const Eigen::Isometry3d& T, double ell) override;
  kernels::MomentSums oneOffMoments(const Eigen::Isometry3d& T, double ell) override;
  kernels::TaylorSums taylor(const Eigen::Isometry3d& T, const Vector6d& xi, double ell) override;
  kernels::CurvatureSums curvature(const Eigen::Isometry3d& T, double ell) override;
  void setThreadLimit(int threads) override { inner_->setThreadLimit(threads); }
  std::optional<DeviceWork> deviceWork() const override { return inner_->deviceWork(); }

  const Tally& tally(Call call) const { return tallies_[call]; }
  static const char* callName(Call call);
  // Every call's time together.
  double totalMs() const;
  void reset() { tallies_ = {}; }

 private:
  template <class F>
  auto timed(Call call, F&& f);

  std::unique_ptr<RegistrationBackend> inner_;
  std::array<Tally, kCallKinds> tallies_{};
};

}  // namespace cvo
