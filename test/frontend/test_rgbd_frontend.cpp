// The RGB-D front end on real TUM fr1_xyz frames: depth encodings, invalid depth, point
// selection and the errors bad input gets.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "cvo_odometry/frontend/color_features.hpp"
#include "cvo_odometry/frontend/depth_conversion.hpp"
#include "cvo_odometry/frontend/empty_frame_error.hpp"
#include "cvo_odometry/frontend/ray_table.hpp"
#include "cvo_odometry/frontend/rgbd_cloud_builder.hpp"
#include "cvo_odometry/frontend/tum_sequence.hpp"

namespace {

const std::string kTum = std::string(CVO_TEST_DATA_DIR) + "/tum_fr1_xyz";

struct TumFrame {
  cv::Mat image, depth;  // depth: TUM 16-bit PNG, 5000 per metre
};

TumFrame loadFrame(std::size_t index) {
  const cvo::TumSequence sequence(kTum);
  TumFrame f;
  sequence.load(index, &f.image, &f.depth);
  return f;
}

cvo::RgbdFrontendOptions options(cvo::SelectorKind kind, double units_per_metre) {
  cvo::RgbdFrontendOptions o;
  o.depth_units_per_metre = units_per_metre;
  o.cloud.selector.kind = kind;
  return o;
}

// Pixel of a cloud point (pinhole, no distortion).
cv::Point2d project(const Eigen::Vector3f& p, const cvo::PinholeIntrinsics& K) {
  return {K.fx * p.x() / p.z() + K.cx, K.fy * p.y() / p.z() + K.cy};
}

cvo::PinholeIntrinsics pinholeFr1() {
  cvo::PinholeIntrinsics K = cvo::tumIntrinsics("fr1");
  K.distortion.clear();
  return K;
}

TEST(TumSequence, ReadsTheFixtureWithDepthStampsBeforeRgb) {
  const cvo::TumSequence sequence(kTum);
  ASSERT_EQ(sequence.frames().size(), 37u);
  for (const auto& f : sequence.frames()) {
    EXPECT_GT(f.rgb_stamp - f.depth_stamp, 0.010);
    EXPECT_LT(f.rgb_stamp - f.depth_stamp, 0.021);
  }
  cv::Mat image, depth;
  sequence.load(0, &image, &depth);
  EXPECT_EQ(image.type(), CV_8UC3);
  EXPECT_EQ(depth.type(), CV_16UC1);
}

TEST(RgbdFrontend, FastSelectionLandsInTheConfiguredRangeWithValidDepth) {
  const TumFrame f = loadFrame(10);
  cvo::RgbdCloudBuilder builder(options(cvo::SelectorKind::kFast, 5000.0));
  cvo::FrontendStats stats;
  const cvo::LabeledCloud cloud =
      builder.build({f.image, f.depth, pinholeFr1(), cv::Mat()}, &stats);
  EXPECT_GE(cloud.size(), 3000u);
  EXPECT_LE(cloud.size(), 15000u);
  EXPECT_EQ(cloud.size(), stats.selection.selected);
  EXPECT_GT(stats.selection.fast_threshold, 0);
  EXPECT_GT(stats.valid_depth_pixels, 200000u);  // most of a 640x480 Kinect frame
  EXPECT_GT(stats.time_ms, 0.0);
  EXPECT_EQ(cloud.firstNonFinite(), -1);
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    ASSERT_GE(cloud.position(i).z(), 0.1f);
    ASSERT_LE(cloud.position(i).z(), 10.0f);
    for (int c = 0; c < 3; ++c) {  // B, G, R in [0, 1]
      ASSERT_GE(cloud.color(i)[c], 0.0f);
      ASSERT_LE(cloud.color(i)[c], 1.0f);
    }
  }
  // The fr1_xyz desk scene is 0.5-3 m away.
  double mean_z = 0;
  for (std::size_t i = 0; i < cloud.size(); ++i)
    mean_z += cloud.position(i).z();
  mean_z /= cloud.size();
  EXPECT_GT(mean_z, 0.6);
  EXPECT_LT(mean_z, 2.5);
}

TEST(RgbdFrontend, FastThresholdAdaptsToTheRange) {
  const TumFrame f = loadFrame(10);
  for (auto [lo, hi] : {std::pair{1000, 2000}, std::pair{8000, 12000}}) {
    cvo::RgbdFrontendOptions o = options(cvo::SelectorKind::kFast, 5000.0);
    o.cloud.selector.min_points = lo;
    o.cloud.selector.max_points = hi;
    cvo::RgbdCloudBuilder builder(o);
    cvo::FrontendStats stats;
    const auto cloud = builder.build({f.image, f.depth, pinholeFr1(), cv::Mat()}, &stats);
    EXPECT_GE(cloud.size(), static_cast<std::size_t>(lo)) << lo << ".." << hi;
    EXPECT_LE(cloud.size(), static_cast<std::size_t>(hi)) << lo << ".." << hi;
  }
}

TEST(RgbdFrontend, DepthEncodingsGiveTheSameCloud) {
  const TumFrame f = loadFrame(5);
  const cvo::PinholeIntrinsics K = pinholeFr1();
  // TUM PNG (5000/m), ROS 16UC1 millimetres and 32FC1 metres of the same depth.
  cv::Mat metres, millimetres;
  f.depth.convertTo(metres, CV_32F, 1.0 / 5000.0);
  f.depth.convertTo(millimetres, CV_16U, 1000.0 / 5000.0);
  cvo::RgbdCloudBuilder tum(options(cvo::SelectorKind::kGrid, 5000.0));
  cvo::RgbdCloudBuilder ros_mm(options(cvo::SelectorKind::kGrid, 1000.0));
  cvo::RgbdCloudBuilder ros_float(options(cvo::SelectorKind::kGrid, 1000.0));
  const auto a = tum.build({f.image, f.depth, K, cv::Mat()});
  const auto b = ros_mm.build({f.image, millimetres, K, cv::Mat()});
  const auto c = ros_float.build({f.image, metres, K, cv::Mat()});
  ASSERT_EQ(a.size(), c.size());
  ASSERT_NEAR(static_cast<double>(a.size()), static_cast<double>(b.size()), 0.001 * a.size());
  for (std::size_t i = 0; i < a.size(); ++i)
    ASSERT_LT((a.position(i) - c.position(i)).norm(), 1e-5f);
  for (std::size_t i = 0; i < std::min(a.size(), b.size()); i += 97)
    EXPECT_LT((a.position(i) - b.position(i)).norm(), 0.002f);  // millimetre rounding
}

TEST(RgbdFrontend, InvalidDepthIsSkipped) {
  const TumFrame f = loadFrame(5);
  const cvo::PinholeIntrinsics K = pinholeFr1();
  cv::Mat depth;
  f.depth.convertTo(depth, CV_32F, 1.0 / 5000.0);
  // Four bands of bad depth: zero, NaN, inf and beyond max_depth.
  const float bad[] = {0.0f, std::numeric_limits<float>::quiet_NaN(),
                       std::numeric_limits<float>::infinity(), 25.0f};
  for (int band = 0; band < 4; ++band)
    depth.colRange(band * 80, band * 80 + 80).setTo(bad[band]);
  cvo::RgbdCloudBuilder builder(options(cvo::SelectorKind::kGrid, 1000.0));
  cvo::FrontendStats stats;
  const auto cloud = builder.build({f.image, depth, K, cv::Mat()}, &stats);
  ASSERT_GT(cloud.size(), 1000u);
  for (std::size_t i = 0; i < cloud.size(); ++i)
    ASSERT_GE(project(cloud.position(i), K).x, 319.5) << "point from a band of invalid depth";
  EXPECT_EQ(cloud.firstNonFinite(), -1);
}

// Depth beyond max_depth stays out of the cloud but in the depth image the feature tracker gets.
TEST(RgbdFrontend, BeyondMaxDepthOnlyTheTrackerSees) {
  const TumFrame f = loadFrame(5);
  cvo::RgbdFrontendOptions o = options(cvo::SelectorKind::kGrid, 5000.0);
  o.cloud.max_depth = 1.0;  // fr1_xyz's desk: 0.65-1.8 m
  cvo::RgbdCloudBuilder builder(o);
  cvo::FrameImages images;
  const auto cloud = builder.build({f.image, f.depth, pinholeFr1(), cv::Mat()}, nullptr, &images);
  ASSERT_GT(cloud.size(), 100u);
  for (std::size_t i = 0; i < cloud.size(); ++i)
    ASSERT_LE(cloud.position(i).z(), 1.0f);
  const int beyond = cv::countNonZero(images.depth > 1.0);
  EXPECT_GT(beyond, 50000);
  cv::Mat metres;
  f.depth.convertTo(metres, CV_32F, 1.0 / 5000.0);
  EXPECT_EQ(beyond, cv::countNonZero(metres > 1.0));
  o.cloud.max_depth = 0.3;  // nearer than the desk
  cvo::RgbdCloudBuilder empty(o);
  try {
    empty.build({f.image, f.depth, pinholeFr1(), cv::Mat()}, nullptr);
    ADD_FAILURE() << "no depth in range must throw";
  } catch (const cvo::EmptyFrameError& e) {
    EXPECT_NE(std::string(e.what()).find("no pixel has depth in [0.1"), std::string::npos)
        << e.what();
  }
}

// An empty frame names what emptied it: the crop when the depth is only in the cropped rows.
TEST(RgbdFrontend, AnEmptyFrameNamesTheCropOrTheRange) {
  const TumFrame f = loadFrame(5);
  const auto message = [&](int crop_top_rows, double max_depth) {
    cvo::RgbdFrontendOptions o = options(cvo::SelectorKind::kGrid, 5000.0);
    o.cloud.crop_top_rows = crop_top_rows;
    o.cloud.max_depth = max_depth;
    cvo::RgbdCloudBuilder builder(o);
    cv::Mat depth = f.depth.clone();
    depth.rowRange(100, depth.rows).setTo(0);  // depth in the top 100 rows only
    try {
      builder.build({f.image, depth, pinholeFr1(), cv::Mat()}, nullptr);
    } catch (const cvo::EmptyFrameError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(message(100, 10.0), "no pixel below the top 100 rows (crop_top_rows) has valid depth");
  EXPECT_EQ(message(480, 10.0), "crop_top_rows (480) leaves none of the image's 480 rows");
  EXPECT_EQ(
      message(50, 0.3).rfind("no pixel below the top 50 rows (crop_top_rows) has depth in [0.1", 0),
      0u);
  EXPECT_EQ(message(0, 10.0), "no error");
}

// The range is the closed interval of the given doubles, also for the floats next to its ends
// (0.7 and 2.3 round below and above themselves as floats; 0.1 above).
TEST(RgbdFrontend, DepthRangeKeepsExactlyTheFloatsWithinIt) {
  const float inf = std::numeric_limits<float>::infinity();
  for (const auto& [min_depth, max_depth] :
       std::vector<std::pair<double, double>>{{0.7, 2.3}, {0.1, 0.3}, {0.0, 4.0}}) {
    std::vector<float> values;
    for (const double end : {min_depth, max_depth}) {
      const float f = static_cast<float>(end);
      for (const float v : {std::nextafter(f, -inf), f, std::nextafter(f, inf)})
        values.push_back(v);
    }
    values.insert(values.end(), {0.0f, -1.0f, inf, std::numeric_limits<float>::quiet_NaN()});
    const cv::Mat depth(1, static_cast<int>(values.size()), CV_32FC1, values.data());
    const cv::Mat metres = cvo::depthToMetres(depth, 1.0, min_depth, max_depth);
    for (std::size_t k = 0; k < values.size(); ++k) {
      const double d = values[k];
      const bool kept = std::isfinite(d) && d > 0.0 && d >= min_depth && d <= max_depth;
      const float out = metres.at<float>(0, static_cast<int>(k));
      if (kept) {
        EXPECT_EQ(out, values[k]) << values[k] << " in [" << min_depth << ", " << max_depth << "]";
      } else {
        EXPECT_TRUE(std::isnan(out))
            << values[k] << " in [" << min_depth << ", " << max_depth << "] kept";
      }
    }
  }
}

TEST(RgbdFrontend, DistortionModelMovesRaysOffCentre) {
  const std::vector<cv::Point> pixels{{318, 255}, {20, 20}};
  const auto distorted = cvo::normalisedRays(pixels, cvo::tumIntrinsics("fr1"));
  const auto pinhole = cvo::normalisedRays(pixels, pinholeFr1());
  EXPECT_NEAR(distorted[0].x, pinhole[0].x, 1e-3);  // near the centre: the same ray
  EXPECT_GT(std::abs(distorted[1].x - pinhole[1].x), 0.01);
}

TEST(RgbdFrontend, RayTableGivesEachPixelsOwnUndistortedRay) {
  const cvo::PinholeIntrinsics fr1 = cvo::tumIntrinsics("fr1");
  const std::vector<cv::Point> pixels{{0, 0}, {639, 479}, {318, 255}, {20, 451}, {600, 3}};
  cvo::RayTable table;
  const auto looked_up = table.rays(pixels, fr1);
  ASSERT_EQ(looked_up.size(), pixels.size());
  for (std::size_t k = 0; k < pixels.size(); ++k) {
    const auto alone = cvo::normalisedRays(std::vector<cv::Point>{pixels[k]}, fr1);
    EXPECT_EQ(looked_up[k], alone[0]) << "pixel " << pixels[k];  // bit for bit
  }
  // Other intrinsics: a new table, not the old one's rays.
  cvo::PinholeIntrinsics other = fr1;
  other.distortion[0] = -0.1;
  const auto changed = table.rays(pixels, other);
  const auto direct = cvo::normalisedRays(pixels, other);
  for (std::size_t k = 0; k < pixels.size(); ++k)
    EXPECT_EQ(changed[k], direct[k]) << "pixel " << pixels[k];
  EXPECT_GT(std::abs(changed[0].x - looked_up[0].x), 1e-3);
  // No distortion: computed directly.
  EXPECT_EQ(table.rays(pixels, pinholeFr1()), cvo::normalisedRays(pixels, pinholeFr1()));
  // Back to fr1: pixels asked before and new ones, each its own ray.
  const std::vector<cv::Point> mixed{{639, 479}, {1, 2}, {0, 0}, {320, 240}, {1, 2}};
  const auto again = table.rays(mixed, fr1);
  for (std::size_t k = 0; k < mixed.size(); ++k)
    EXPECT_EQ(again[k], cvo::normalisedRays(std::vector<cv::Point>{mixed[k]}, fr1)[0])
        << "pixel " << mixed[k];
}

void expectError(const std::function<void()>& call, const std::string& words) {
  try {
    call();
    FAIL() << "no error; expected one mentioning '" << words << "'";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
  }
}

TEST(RgbdFrontend, BadInputGetsAClearError) {
  const TumFrame f = loadFrame(0);
  const cvo::PinholeIntrinsics K = pinholeFr1();
  cvo::RgbdCloudBuilder builder(options(cvo::SelectorKind::kFast, 5000.0));
  expectError([&] { builder.build({cv::Mat(), f.depth, K, cv::Mat()}); }, "colour image is empty");
  expectError([&] { builder.build({f.image, cv::Mat(), K, cv::Mat()}); }, "depth image is empty");
  cv::Mat half;
  cv::resize(f.depth, half, cv::Size(320, 240), 0, 0, cv::INTER_NEAREST);
  expectError(
      [&] {
        builder.build({f.image, half, K, cv::Mat()});
      },
      "640x480 but depth is 320x240");
  cv::Mat bytes;
  f.depth.convertTo(bytes, CV_8U);
  expectError(
      [&] {
        builder.build({f.image, bytes, K, cv::Mat()});
      },
      "unsupported depth image type");
  expectError(
      [&] {
        builder.build({f.image, cv::Mat::zeros(480, 640, CV_16UC1), K, cv::Mat()});
      },
      "no pixel has valid depth");
  cvo::PinholeIntrinsics nan_focal = K;
  nan_focal.fx = std::numeric_limits<double>::quiet_NaN();
  expectError([&] { builder.build({f.image, f.depth, nan_focal, cv::Mat()}); }, "focal");
  // Found by fuzz_frontend: OpenCV asserts on coefficient counts no model has.
  cvo::PinholeIntrinsics seven = cvo::tumIntrinsics("fr1");
  seven.distortion.resize(7, 0.01);
  expectError(
      [&] {
        builder.build({f.image, f.depth, seven, cv::Mat()});
      },
      "7 distortion coefficients");
  cvo::PinholeIntrinsics nan_distortion = cvo::tumIntrinsics("fr1");
  nan_distortion.distortion[0] = std::numeric_limits<double>::quiet_NaN();
  expectError(
      [&] {
        builder.build({f.image, f.depth, nan_distortion, cv::Mat()});
      },
      "distortion coefficient is not finite");
  cvo::PinholeIntrinsics other_size = K;
  other_size.width = 1280;
  expectError(
      [&] {
        builder.build({f.image, f.depth, other_size, cv::Mat()});
      },
      "camera info is for 1280x480");
  cvo::RgbdFrontendOptions inverted = options(cvo::SelectorKind::kFast, 5000.0);
  inverted.cloud.min_depth = 5.0;
  inverted.cloud.max_depth = 1.0;
  expectError([&] { cvo::RgbdCloudBuilder{inverted}; }, "depth range");
}

}  // namespace

TEST(RgbdFrontend, ColourFeaturesAreColourAndCentralDifferences) {
  // The five values at a pixel against OpenCV's own arithmetic: channels / 255 and central
  // differences of the grey image with the border replicated, borders included, for colour and
  // grey images alike.
  const TumFrame f = loadFrame(3);
  cv::Mat grey_image;
  cv::cvtColor(f.image, grey_image, cv::COLOR_BGR2GRAY);
  for (const cv::Mat& image : {f.image, grey_image}) {
    const cv::Mat grey = cvo::toGrey(image);
    cv::Mat grey_float, gx, gy;
    grey.convertTo(grey_float, CV_32F);
    const cv::Mat central = (cv::Mat_<float>(1, 3) << -0.5f, 0.0f, 0.5f);
    cv::filter2D(grey_float, gx, CV_32F, central, cv::Point(-1, -1), 0.0, cv::BORDER_REPLICATE);
    cv::filter2D(grey_float, gy, CV_32F, central.t(), cv::Point(-1, -1), 0.0, cv::BORDER_REPLICATE);
    for (const cv::Point p : {cv::Point(0, 0), cv::Point(639, 479), cv::Point(0, 200),
                              cv::Point(320, 0), cv::Point(123, 456), cv::Point(517, 31)}) {
      float one[5];
      cvo::colorFeaturesAt(image, grey, p.x, p.y, one);
      for (int k = 0; k < 3; ++k) {
        const int channel = image.channels() == 3 ? k : 0;
        EXPECT_EQ(one[k], image.ptr<std::uint8_t>(p.y)[image.channels() * p.x + channel] / 255.0f)
            << p << " channel " << k;
      }
      EXPECT_EQ(one[3], gx.at<float>(p) / 500.0f + 0.5f) << p;
      EXPECT_EQ(one[4], gy.at<float>(p) / 500.0f + 0.5f) << p;
    }
  }
}
