#include "cvo_odometry/core/cuda_backend.hpp"

namespace cvo {

CudaBackend::CudaBackend() = default;

void CudaBackend::setProblem(const LabeledCloud& target, const LabeledCloud& source,
                             const CvoParams& params) {
  const int classes = params.use_semantics ? source.semanticClasses() : 0;
  for (const LabeledCloud* cloud : {&target, &source}) {
    device_.setCloud(cloud == &target, cloud->positionData().data(),
                     params.use_color ? cloud->colorData().data() : nullptr,
                     classes ? cloud->semanticData().data() : nullptr,
                     static_cast<int>(cloud->size()), classes);
  }
  device_.setConstants(makeKernelConstants(params, classes), retainedScaledDistance2(params));
}

kernels::MomentSums CudaBackend::moments(const Eigen::Isometry3d& T, double ell) {
  float pose[12];
  toRowMajor3x4(T, pose);
  return device_.moments(pose, ell);
}

kernels::TaylorSums CudaBackend::taylor(const Eigen::Isometry3d& T, const Vector6d& xi,
                                        double ell) {
  float pose[12];
  toRowMajor3x4(T, pose);
  return device_.taylor(pose, xi.data(), ell);
}

kernels::CurvatureSums CudaBackend::curvature(const Eigen::Isometry3d& T, double ell) {
  float pose[12];
  toRowMajor3x4(T, pose);
  return device_.curvature(pose, ell);
}

}  // namespace cvo
