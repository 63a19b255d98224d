#include "cvo_odometry/core/timed_backend.hpp"

#include <chrono>

namespace cvo {

TimedBackend::TimedBackend(std::unique_ptr<RegistrationBackend> inner) : inner_(std::move(inner)) {}

template <class F>
auto TimedBackend::timed(Call call, F&& f) {
  const auto start = std::chrono::steady_clock::now();
  auto result = f();
  Tally& tally = tallies_[call];
  ++tally.calls;
  tally.ms +=
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return result;
}

void TimedBackend::setProblem(const LabeledCloud& target, const LabeledCloud& source,
                              const CvoParams& params) {
  timed(kSetProblem, [&] {
    inner_->setProblem(target, source, params);
    return 0;
  });
}

void TimedBackend::useSubsets(const CloudSubsets& subsets) {
  timed(kUseSubsets, [&] {
    inner_->useSubsets(subsets);
    return 0;
  });
}

kernels::MomentSums TimedBackend::moments(const Eigen::Isometry3d& T, double ell) {
  return timed(kMoments, [&] { return inner_->moments(T, ell); });
}

kernels::MomentSums TimedBackend::oneOffMoments(const Eigen::Isometry3d& T, double ell) {
  return timed(kOneOffMoments, [&] { return inner_->oneOffMoments(T, ell); });
}

kernels::TaylorSums TimedBackend::taylor(const Eigen::Isometry3d& T, const Vector6d& xi,
                                         double ell) {
  return timed(kTaylor, [&] { return inner_->taylor(T, xi, ell); });
}

kernels::CurvatureSums TimedBackend::curvature(const Eigen::Isometry3d& T, double ell) {
  return timed(kCurvature, [&] { return inner_->curvature(T, ell); });
}

const char* TimedBackend::callName(Call call) {
  switch (call) {
    case kSetProblem:
      return "setProblem";
    case kUseSubsets:
      return "useSubsets";
    case kMoments:
      return "moments";
    case kOneOffMoments:
      return "oneOffMoments";
    case kTaylor:
      return "taylor";
    case kCurvature:
      return "curvature";
    default:
      return "?";
  }
}

double TimedBackend::totalMs() const {
  double ms = 0.0;
  for (const Tally& tally : tallies_)
    ms += tally.ms;
  return ms;
}

}  // namespace cvo
