#include "cvo_odometry/core/device_backend.hpp"

namespace cvo {

template <DeviceSystem System>
DeviceBackend<System>::DeviceBackend(int num_threads) : device_(num_threads) {}

template <DeviceSystem System>
std::string DeviceBackend<System>::name() const {
  return System == DeviceSystem::kCuda ? "cuda" : "device_cpu";
}

template <DeviceSystem System>
void DeviceBackend<System>::setProblem(const LabeledCloud& target, const LabeledCloud& source,
                                       const CvoParams& params) {
  const int classes = params.use_semantics ? source.semanticClasses() : 0;
  // By role, not by address: target and source may be the same cloud (a self product).
  for (const bool is_target : {true, false}) {
    const LabeledCloud& cloud = is_target ? target : source;
    device_.setCloud(is_target, cloud.positionData().data(),
                     params.use_color ? cloud.colorData().data() : nullptr,
                     classes ? cloud.semanticData().data() : nullptr,
                     static_cast<int>(cloud.size()), classes);
  }
  device_.setConstants(makeKernelConstants(params, classes), retainedScaledDistance2(params));
}

template <DeviceSystem System>
void DeviceBackend<System>::useSubsets(const CloudSubsets& subsets) {
  device_.useSubsets(subsets.target_stride, subsets.source_stride, subsets.source_count);
}

template <DeviceSystem System>
kernels::MomentSums DeviceBackend<System>::moments(const Eigen::Isometry3d& T, double ell) {
  float pose[12];
  toRowMajor3x4(T, pose);
  return device_.moments(pose, ell);
}

template <DeviceSystem System>
kernels::TaylorSums DeviceBackend<System>::taylor(const Eigen::Isometry3d& T, const Vector6d& xi,
                                                  double ell) {
  float pose[12];
  toRowMajor3x4(T, pose);
  return device_.taylor(pose, xi.data(), ell);
}

template <DeviceSystem System>
kernels::CurvatureSums DeviceBackend<System>::curvature(const Eigen::Isometry3d& T, double ell) {
  float pose[12];
  toRowMajor3x4(T, pose);
  return device_.curvature(pose, ell);
}

#ifdef CVO_HAVE_CUDA
template class DeviceBackend<DeviceSystem::kCuda>;
#endif
#ifdef CVO_HAVE_DEVICE_CPU
template class DeviceBackend<DeviceSystem::kOmp>;
#endif

}  // namespace cvo
