// Front-end keys of the presets: both shipped presets load, CVO keys are skipped, bad values name
// the file and line.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <sstream>

#include "cvo_odometry/core/format_error.hpp"
#include "cvo_odometry/core/params_io.hpp"
#include "cvo_odometry/frontend/frontend_params.hpp"

namespace {

const std::string kConfig = std::string(CVO_SOURCE_DIR) + "/config";

TEST(FrontendParams, ShippedPresetsLoadInBothLayers) {
  cvo::CloudBuilderOptions tum, kitti;
  cvo::loadFrontendParams(kConfig + "/tum_rgbd.yaml", &tum);
  cvo::loadFrontendParams(kConfig + "/kitti_stereo.yaml", &kitti);
  EXPECT_EQ(tum.selector.kind, cvo::SelectorKind::kGrid);
  EXPECT_EQ(kitti.selector.kind, cvo::SelectorKind::kFast);
  EXPECT_EQ(kitti.crop_top_rows, 100);
  EXPECT_DOUBLE_EQ(kitti.max_depth, 55.0);
  const cvo::CvoParams params = cvo::loadCvoParams(kConfig + "/tum_rgbd.yaml");
  EXPECT_DOUBLE_EQ(params.color_ell, 0.3);
  std::istringstream typo("point_selectr: grid\n");
  EXPECT_THROW(cvo::parseCvoParams(typo, "typo.yaml"), cvo::FormatError) << "unknown key";
}

TEST(FrontendParams, ImageLevelsOnlyWhenThePhotometricStageUsesThem) {
  cvo::CloudBuilderOptions tum;
  cvo::loadFrontendParams(kConfig + "/tum_rgbd.yaml", &tum);
  cvo::CvoParams params = cvo::loadCvoParams(kConfig + "/tum_rgbd.yaml");
  ASSERT_TRUE(params.photometric_rotation);
  EXPECT_EQ(cvo::frontendOptionsFor(tum, params).image_levels, 2);
  params.photometric_rotation = false;
  const cvo::CloudBuilderOptions off = cvo::frontendOptionsFor(tum, params);
  EXPECT_EQ(off.image_levels, 0);
  EXPECT_EQ(off.selector.max_points, tum.selector.max_points) << "nothing else changes";
}

TEST(FrontendParams, BadValuesNameFileAndLine) {
  const std::string path = testing::TempDir() + "/bad_frontend.yaml";
  std::ofstream(path) << "ell_min: 0.05\nmin_points: many\n";
  cvo::CloudBuilderOptions options;
  try {
    cvo::loadFrontendParams(path, &options);
    FAIL() << "accepted a bad value";
  } catch (const cvo::FormatError& e) {
    EXPECT_NE(std::string(e.what()).find("bad_frontend.yaml:2: 'min_points' expects a number"),
              std::string::npos)
        << e.what();
  }
  std::ofstream(path) << "point_selector: sift\n";
  EXPECT_THROW(cvo::loadFrontendParams(path, &options), cvo::FormatError);
  // Found by fuzz_params: a value beyond int's range was converted (undefined behaviour).
  std::ofstream(path) << "min_points: 1e40\n";
  EXPECT_THROW(cvo::loadFrontendParams(path, &options), cvo::FormatError);
  std::ofstream(path) << "min_points: 5000\nmax_points: 100\n";
  EXPECT_THROW(cvo::loadFrontendParams(path, &options), std::exception);
  std::remove(path.c_str());
}

}  // namespace
