// CPU and CUDA backends give the same registrations. Compiled whenever CUDA is; skipped with a
// message where no device is present (CI has none: GPU runs are done by hand, see README).
#include <gtest/gtest.h>

#include "cvo_odometry/core/backend_factory.hpp"
#include "cvo_odometry/core/cloud_io.hpp"
#include "cvo_odometry/core/cpu_backend.hpp"
#include "cvo_odometry/core/cuda_backend.hpp"
#include "cvo_odometry/core/cvo_registration.hpp"
#include "synthetic_scene.hpp"

namespace {

void expectParity(const cvo::LabeledCloud& target, const cvo::LabeledCloud& source,
                  cvo::CvoParams params, bool first_frame, const std::string& what) {
  cvo::CvoRegistration cpu(params, std::make_unique<cvo::CpuBackend>());
  cvo::CvoRegistration gpu(params, std::make_unique<cvo::CudaBackend>());
  const auto a = cpu.align(target, source, Eigen::Isometry3d::Identity(), first_frame);
  const auto b = gpu.align(target, source, Eigen::Isometry3d::Identity(), first_frame);
  const Eigen::Isometry3d diff = a.transform.inverse() * b.transform;
  EXPECT_LT(cvo::lie::rotationAngle(diff.linear()), 1e-4) << what;
  EXPECT_LT(diff.translation().norm(), 1e-4) << what;
  EXPECT_NEAR(b.report.indicator_after, a.report.indicator_after, 1e-5 * a.report.indicator_after)
      << what;
  // Float sums in another order may move the last step across eps_2 one iteration apart.
  EXPECT_LE(std::abs(a.report.iterations - b.report.iterations), 1) << what;
}

}  // namespace

class CudaParity : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string why_not;
    if (!cvo::cudaBackendAvailable(&why_not)) GTEST_SKIP() << "no CUDA device: " << why_not;
  }
};

TEST_F(CudaParity, SyntheticRoomGeometricAndColour) {
  for (bool color : {false, true}) {
    cvo::CvoParams params;
    params.use_color = color;
    params.ell_first_frame = 0.5;
    const auto target = cvo_test::roomScene(3000, 10, color);
    Eigen::Isometry3d truth = Eigen::Isometry3d::Identity();
    truth.linear() = Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    truth.translation() << 0.1, -0.05, 0.02;
    const auto source =
        cvo_test::roomScene(3000, 11, color).transformed(truth.inverse().cast<float>());
    expectParity(target, source, params, true, color ? "synthetic colour" : "synthetic geometric");
  }
}

TEST_F(CudaParity, RealTumFramesBothMethods) {
  const std::string data = std::string(CVO_TEST_DATA_DIR) + "/tum_clouds/";
  for (const char* size : {"3000", "15000"}) {
    const auto target = cvo::readCloud(data + "frame10_" + size + ".cloud");
    const auto source = cvo::readCloud(data + "frame11_" + size + ".cloud");
    for (bool color : {false, true}) {
      cvo::CvoParams params;
      params.use_color = color;
      expectParity(target, source, params, false,
                   std::string(size) + (color ? " colour" : " geometric"));
      if (std::string(size) == "3000") {
        params.step_method = cvo::StepMethod::kReference;
        expectParity(target, source, params, false,
                     std::string("reference ") + (color ? "colour" : "geometric"));
      }
    }
  }
}
