#include "cvo_odometry/core/registration_backend.hpp"

#include <cmath>

namespace cvo {

double retainedScaledDistance2(const CvoParams& params) {
  return 2.0 * std::log(params.maxKernelWeight() / params.retainThreshold());
}

kernels::KernelConstants makeKernelConstants(const CvoParams& params, int semantic_classes) {
  kernels::KernelConstants k{};
  k.max_weight = static_cast<float>(params.maxKernelWeight());
  k.sp_thres = static_cast<float>(params.retainThreshold());
  k.use_color = params.use_color ? 1 : 0;
  k.color_inv_ell2 = static_cast<float>(1.0 / (params.color_ell * params.color_ell));
  k.semantic_classes = params.use_semantics ? semantic_classes : 0;
  k.semantic_cross_weight = static_cast<float>(params.semantic_cross_weight);
  return k;
}

void toRowMajor3x4(const Eigen::Isometry3d& T, float* out) {
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 4; ++c)
      out[4 * r + c] = static_cast<float>(T.matrix()(r, c));
  }
}

void CloudSubsets::targetInto(const LabeledCloud& target, LabeledCloud& out) const {
  target.stridedInto(target_stride, out);
}

void CloudSubsets::sourceInto(const LabeledCloud& source, LabeledCloud& out) const {
  if (source_count == 0) {
    source.stridedInto(source_stride, out);
  } else {
    source.thinnedInto(source_count, out);
  }
}

}  // namespace cvo
