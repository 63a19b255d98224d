// The settings table below ROS: the shipped presets, one parser for every text form, range and
// cross-parameter checks that name the file and line, and a round trip of every row.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <set>
#include <sstream>

#include "cvo_odometry/core/format_error.hpp"
#include "cvo_odometry/frontend/builtin_presets.hpp"
#include "cvo_odometry/frontend/odometry_settings.hpp"

namespace {

const std::string kConfig = std::string(CVO_SOURCE_DIR) + "/config";

std::string loadError(const std::string& text) {
  const std::string path = testing::TempDir() + "/bad_settings.yaml";
  std::ofstream(path) << text;
  try {
    cvo::loadOdometrySettings(path);
  } catch (const std::exception& e) {
    std::remove(path.c_str());
    return e.what();
  }
  std::remove(path.c_str());
  return "";
}

TEST(OdometrySettings, ShippedPresetsLoadByNameAndByFile) {
  cvo::OdometrySettings by_name,
      by_file = cvo::loadOdometrySettings(kConfig + "/kitti_stereo.yaml");
  cvo::applyPreset("kitti_stereo", &by_name);
  EXPECT_EQ(cvo::describeSettings(by_name), cvo::describeSettings(by_file));
  EXPECT_EQ(by_name.cloud.selector.kind, cvo::SelectorKind::kFast);
  EXPECT_EQ(by_name.cloud.crop_top_rows, 100);
  EXPECT_DOUBLE_EQ(by_name.cloud.max_depth, 55.0);
  EXPECT_DOUBLE_EQ(by_name.cvo.ell_first_frame, 0.95);
  EXPECT_DOUBLE_EQ(by_name.cvo.sp_ratio, 0.7);
  EXPECT_EQ(by_name.cvo.max_iterations, 10000);
  // The defaults are the RGB-D camera's: the TUM preset changes nothing.
  cvo::OdometrySettings tum;
  cvo::applyPreset("tum_rgbd", &tum);
  EXPECT_EQ(cvo::describeSettings(tum), cvo::describeSettings(cvo::OdometrySettings()));
  EXPECT_EQ(tum.cloud.selector.kind, cvo::SelectorKind::kGrid);
  EXPECT_DOUBLE_EQ(tum.cvo.ell_min, 0.02);
  EXPECT_TRUE(tum.cvo.photometric_rotation);
  EXPECT_FALSE(tum.cvo.use_color);
  EXPECT_THROW(cvo::applyPreset("kitti_mono", &tum), std::runtime_error);
}

TEST(OdometrySettings, PresetsStateOnlyWhatTheyChange) {
  for (const auto& preset : cvo::builtInPresets()) {
    const std::string& name = preset.first;
    std::istringstream in(preset.second);
    cvo::parseKeyValueLines(in, name, [&](const std::string& key, const std::string& value) {
      cvo::OdometrySettings changed;
      cvo::setSetting(changed, key, value);
      EXPECT_NE(cvo::settingValue(changed, key), cvo::settingValue(cvo::OdometrySettings(), key))
          << name << ": " << key << " states the default";
    });
  }
}

TEST(OdometrySettings, EveryRowIsDocumentedAndReadsBackTheSame) {
  const auto rows = cvo::settingRows(cvo::OdometrySettings());
  std::set<std::string> names;
  for (const auto& row : rows) {
    EXPECT_TRUE(names.insert(row.name).second) << row.name << " is declared twice";
    EXPECT_FALSE(row.doc.empty()) << row.name;
    EXPECT_FALSE(row.group.empty()) << row.name;
  }
  cvo::OdometrySettings changed;
  cvo::applyPreset("kitti_stereo", &changed);
  changed.cloud.ignore_classes = {3, 7};
  std::istringstream text(cvo::describeSettings(changed));
  cvo::OdometrySettings back;
  cvo::readSettings(text, "described", &back);
  EXPECT_EQ(cvo::describeSettings(back), cvo::describeSettings(changed));
  EXPECT_EQ(back.cloud.ignore_classes, (std::vector<int>{3, 7}));
}

TEST(OdometrySettings, OneParserForEveryInteger) {
  cvo::OdometrySettings s;
  cvo::setSetting(s, "min_points", "3000.0");
  cvo::setSetting(s, "max_iterations", "3000.0");
  EXPECT_EQ(s.cloud.selector.min_points, 3000);
  EXPECT_EQ(s.cvo.max_iterations, 3000);
  EXPECT_THROW(cvo::setSetting(s, "min_points", "1.5"), std::invalid_argument);
  EXPECT_THROW(cvo::setSetting(s, "max_iterations", "1.5"), std::invalid_argument);
  EXPECT_THROW(cvo::setSetting(s, "ell_init", "5"), std::invalid_argument) << "out of range";
  cvo::setSetting(s, "ignore_classes", "[1, 2]");
  EXPECT_EQ(s.cloud.ignore_classes, (std::vector<int>{1, 2}));
}

TEST(OdometrySettings, ImageLevelsOnlyWhenThePhotometricStageUsesThem) {
  cvo::OdometrySettings s;
  ASSERT_TRUE(s.cvo.photometric_rotation);
  EXPECT_EQ(s.cloudOptions().image_levels, 2);
  s.cvo.photometric_rotation = false;
  EXPECT_EQ(s.cloudOptions().image_levels, 0);
  EXPECT_EQ(s.rgbdOptions().cloud.selector.max_points, s.cloud.selector.max_points);
}

TEST(OdometrySettings, BadValuesNameFileAndLine) {
  EXPECT_NE(loadError("ell_min: 0.05\nmin_points: many\n")
                .find("bad_settings.yaml:2: min_points expects an integer, got 'many'"),
            std::string::npos);
  EXPECT_NE(loadError("point_selector: sift\n")
                .find("unknown point_selector 'sift' (grid, fast or mixed)"),
            std::string::npos);
  EXPECT_NE(loadError("point_selectr: grid\n").find(":1: unknown parameter 'point_selectr'"),
            std::string::npos);
  // Found by fuzz_params: a value beyond int's range was converted (undefined behaviour).
  EXPECT_NE(loadError("min_points: 1e40\n").find("expects an integer"), std::string::npos);
  EXPECT_NE(loadError("min_points: 5000\nmax_points: 1000\n").find("point count range"),
            std::string::npos);
  EXPECT_NE(loadError("ell_min: 0.5\n").find("invalid CVO parameters: ell_min"), std::string::npos);
  EXPECT_NE(loadError("sigma: 0.1\nsigma: 0.2\n").find(":2: 'sigma' given twice"),
            std::string::npos);
}

}  // namespace
