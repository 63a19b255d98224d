#include <gtest/gtest.h>

#include <sstream>

#include "cvo_odometry/core/format_error.hpp"
#include "cvo_odometry/core/params_io.hpp"

namespace {

std::string configPath(const std::string& name) {
  return std::string(CVO_TEST_DATA_DIR) + "/../../config/" + name;
}

std::string parseError(const std::string& text) {
  std::istringstream in(text);
  try {
    cvo::parseCvoParams(in, "p.yaml");
  } catch (const cvo::FormatError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(ParamsIo, PresetsLoadWithThePapersValues) {
  // The core reads only its own keys of a full preset (the front end's are skipped).
  const cvo::CvoParams tum =
      cvo::loadCvoParams(configPath("tum_rgbd.yaml"), {}, cvo::UnknownKeys::kIgnore);
  EXPECT_DOUBLE_EQ(tum.ell_init, 0.15);
  EXPECT_NEAR(tum.retainThreshold(), 0.003, 1e-12);  // the paper's sp_thres, geometry only
  EXPECT_DOUBLE_EQ(tum.color_sigma, 0.6);
  EXPECT_EQ(tum.step_method, cvo::StepMethod::kProcrustes);
  const cvo::CvoParams kitti =
      cvo::loadCvoParams(configPath("kitti_stereo.yaml"), {}, cvo::UnknownKeys::kIgnore);
  EXPECT_DOUBLE_EQ(kitti.ell_first_frame, 0.95);
  EXPECT_DOUBLE_EQ(kitti.sp_ratio, 0.7);
  EXPECT_NEAR(kitti.retainThreshold(), 0.007, 1e-12);  // the paper's sp_thres at its kernels
  EXPECT_EQ(kitti.indicator_window, 30);
  EXPECT_EQ(kitti.max_iterations, 10000);
}

TEST(ParamsIo, WrittenParametersReadBackTheSame) {
  cvo::CvoParams p;
  p.ell_min = 0.03;
  p.use_color = false;
  p.step_method = cvo::StepMethod::kReference;
  p.indicator_window = 7;
  std::stringstream text;
  cvo::writeCvoParams(text, p);
  const cvo::CvoParams back = cvo::parseCvoParams(text, "written");
  EXPECT_DOUBLE_EQ(back.ell_min, 0.03);
  EXPECT_FALSE(back.use_color);
  EXPECT_EQ(back.step_method, cvo::StepMethod::kReference);
  EXPECT_EQ(back.indicator_window, 7);
}

TEST(ParamsIo, BadFilesNameTheLineAndTheProblem) {
  EXPECT_EQ(parseError("ell_init: 0.2\nell_max: 3\n"), "p.yaml:2: unknown parameter 'ell_max'");
  EXPECT_EQ(parseError("sigma: big\n"), "p.yaml:1: sigma expects a number, got 'big'");
  EXPECT_EQ(parseError("use_color: maybe\n"),
            "p.yaml:1: use_color expects true or false, got 'maybe'");
  EXPECT_EQ(parseError("max_iterations: 1.5\n"),
            "p.yaml:1: max_iterations expects an integer, got '1.5'");
  EXPECT_EQ(parseError("sigma 0.1\n"), "p.yaml:1: expected 'key: value'");
  EXPECT_EQ(parseError("sigma: 0.1\nsigma: 0.2\n"), "p.yaml:2: 'sigma' given twice");
  EXPECT_NE(parseError("ell_min: 0.5\n").find("p.yaml: invalid CVO parameters: ell_min"),
            std::string::npos);
  EXPECT_EQ(parseError("step_method: newton\n"),
            "p.yaml:1: unknown step_method 'newton' (reference or procrustes)");
  EXPECT_THROW(cvo::loadCvoParams("/nonexistent.yaml"), std::runtime_error);
}
