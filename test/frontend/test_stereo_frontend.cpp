// The stereo front end on real KITTI data: our SGBM disparity against a third party's on the
// same pair, the given-disparity path, cropping and range, the KITTI sequence reader, and one
// stereo registration against the official ground truth.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "cvo_odometry/core/params_io.hpp"
#include "cvo_odometry/frontend/builtin_presets.hpp"
#include "cvo_odometry/frontend/depth_conversion.hpp"
#include "cvo_odometry/frontend/kitti_sequence.hpp"
#include "cvo_odometry/frontend/stereo_cloud_builder.hpp"
#include "kitti_frames.hpp"

namespace {

// The stereo front end as the kitti_stereo preset sets it up.
cvo::OdometrySettings kittiSettings() {
  cvo::OdometrySettings settings;
  cvo::applyPreset("kitti_stereo", &settings);
  return settings;
}

const std::string kData = CVO_TEST_DATA_DIR;
const std::string kPair = kData + "/kitti_stereo_pair";
const std::string kKitti = kData + "/kitti_06_stereo";

using cvo_test::kPairBaseline;
using cvo_test::pairIntrinsics;

cv::Mat readGrey(const std::string& path) {
  cv::Mat image = cv::imread(path, cv::IMREAD_GRAYSCALE);
  if (image.empty()) throw std::runtime_error("missing " + path);
  return image;
}

// KITTI's stereo benchmark rule: a pixel agrees when its error is at most 3 px or 5 %.
TEST(StereoMatcher, AgreesWithThirdPartyDisparityOnTheKittiPair) {
  const cv::Mat left = readGrey(kPair + "/left.png"), right = readGrey(kPair + "/right.png");
  const cv::Mat theirs = cv::imread(kPair + "/disparity.png", cv::IMREAD_UNCHANGED);
  ASSERT_EQ(theirs.type(), CV_8UC1);
  const cvo::StereoMatcher matcher{cvo::StereoMatcherOptions()};
  const cv::Mat ours = matcher.disparity(left, right);
  ASSERT_EQ(ours.type(), CV_32FC1);
  std::size_t compared = 0, agreeing = 0, ours_valid = 0;
  std::vector<float> errors;
  for (int v = 100; v < ours.rows; ++v) {    // below the band without stereo overlap
    for (int u = 128; u < ours.cols; ++u) {  // left of num_disparities nothing can match
      const float d = ours.at<float>(v, u);
      if (!std::isfinite(d)) continue;
      ++ours_valid;
      const float t = theirs.at<std::uint8_t>(v, u);
      if (t <= 0) continue;
      ++compared;
      const float error = std::abs(d - t);
      errors.push_back(error);
      if (error <= 3.0f || error <= 0.05f * t) ++agreeing;
    }
  }
  const std::size_t area = static_cast<std::size_t>((ours.rows - 100) * (ours.cols - 128));
  EXPECT_GT(ours_valid, area / 2) << "SGBM left most pixels without a disparity";
  ASSERT_GT(compared, area / 2);
  std::nth_element(errors.begin(), errors.begin() + errors.size() / 2, errors.end());
  const double median = errors[errors.size() / 2];
  const double fraction = static_cast<double>(agreeing) / compared;
  std::cout << "disparity vs third party: " << compared << " pixels, median |error| " << median
            << " px, " << 100.0 * fraction << " % within 3 px or 5 %\n";
  EXPECT_LT(median, 1.0);
  EXPECT_GT(fraction, 0.90);
}

TEST(StereoFrontend, GivenDisparityGivesMetricDepthCroppedAndInRange) {
  const cv::Mat left = readGrey(kPair + "/left.png");
  const cv::Mat disparity = cv::imread(kPair + "/disparity.png", cv::IMREAD_UNCHANGED);
  cvo::StereoCloudBuilder builder(kittiSettings().stereoOptions());
  cvo::StereoFrame frame;
  frame.left = left;
  frame.disparity = disparity;
  frame.intrinsics = pairIntrinsics();
  frame.baseline = kPairBaseline;
  cvo::FrontendStats stats;
  const auto cloud = builder.build(frame, &stats);
  EXPECT_GE(cloud.size(), 3000u);
  EXPECT_LE(cloud.size(), 15000u);
  const auto K = pairIntrinsics();
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const auto p = cloud.position(i);
    ASSERT_GE(p.z(), 1.0f);
    ASSERT_LE(p.z(), 55.0f);
    ASSERT_GE(K.fy * p.y() / p.z() + K.cy, 99.5) << "a point from the cropped top rows";
    // z = f b / d exactly for the pixel the point came from.
    const int u = static_cast<int>(std::lround(K.fx * p.x() / p.z() + K.cx));
    const int v = static_cast<int>(std::lround(K.fy * p.y() / p.z() + K.cy));
    ASSERT_NEAR(p.z(), K.fx * kPairBaseline / disparity.at<std::uint8_t>(v, u), 1e-3 * p.z());
  }
}

// disparity_offset corrects a calibration: z = f b / (d + offset) where d is valid, and the
// pixels without a disparity (0) stay without depth.
TEST(StereoFrontend, DisparityOffsetShiftsEveryValidDisparity) {
  const cv::Mat disparity = cv::imread(kPair + "/disparity.png", cv::IMREAD_UNCHANGED);
  cvo::OdometrySettings settings = kittiSettings();
  const cv::Mat plain = cvo::StereoCloudBuilder(settings.stereoOptions()).depth([&] {
    cvo::StereoFrame frame;
    frame.left = readGrey(kPair + "/left.png");
    frame.disparity = disparity;
    frame.intrinsics = pairIntrinsics();
    frame.baseline = kPairBaseline;
    return frame;
  }());
  settings.disparity_offset = 0.25;
  cvo::StereoFrame frame;
  frame.left = readGrey(kPair + "/left.png");
  frame.disparity = disparity;
  frame.intrinsics = pairIntrinsics();
  frame.baseline = kPairBaseline;
  const cv::Mat shifted = cvo::StereoCloudBuilder(settings.stereoOptions()).depth(frame);
  const double fb = pairIntrinsics().fx * kPairBaseline;
  std::size_t checked = 0;
  for (int v = 0; v < disparity.rows; ++v) {
    for (int u = 0; u < disparity.cols; ++u) {
      const int d = disparity.at<std::uint8_t>(v, u);
      const float z = shifted.at<float>(v, u);
      if (d == 0) {
        ASSERT_FALSE(std::isfinite(z)) << "no disparity, no depth";
        continue;
      }
      if (!std::isfinite(plain.at<float>(v, u)) || !std::isfinite(z)) continue;  // out of range
      ASSERT_NEAR(z, fb / (d + 0.25), 1e-4 * z);
      ++checked;
    }
  }
  EXPECT_GT(checked, 100000u);
}

TEST(StereoFrontend, MatchedAndGivenDisparityGiveSimilarDepth) {
  cvo::StereoCloudBuilder builder(kittiSettings().stereoOptions());
  cvo::StereoFrame matched;
  matched.left = readGrey(kPair + "/left.png");
  matched.right = readGrey(kPair + "/right.png");
  matched.intrinsics = pairIntrinsics();
  matched.baseline = kPairBaseline;
  cvo::StereoFrame given = matched;
  given.right = cv::Mat();
  given.disparity = cv::imread(kPair + "/disparity.png", cv::IMREAD_UNCHANGED);
  const cv::Mat a = builder.depth(matched), b = builder.depth(given);
  std::vector<float> relative;
  for (int v = 100; v < a.rows; ++v)
    for (int u = 128; u < a.cols; ++u)
      if (std::isfinite(a.at<float>(v, u)) && std::isfinite(b.at<float>(v, u)))
        relative.push_back(std::abs(a.at<float>(v, u) - b.at<float>(v, u)) / b.at<float>(v, u));
  ASSERT_GT(relative.size(), 100000u);
  std::nth_element(relative.begin(), relative.begin() + relative.size() / 2, relative.end());
  EXPECT_LT(relative[relative.size() / 2], 0.05) << "median relative depth difference";
}

// Matching skips the rows above crop_top_rows (but for 16 rows of context): no depth there, and
// below it the depth of the whole pair's matching (SGBM's stripes differ, so not bit for bit).
TEST(StereoFrontend, MatchingSkipsTheCroppedRows) {
  cvo::OdometrySettings settings = kittiSettings();
  ASSERT_EQ(settings.cloud.crop_top_rows, 100);
  cvo::StereoFrame frame;
  frame.left = readGrey(kPair + "/left.png");
  frame.right = readGrey(kPair + "/right.png");
  frame.intrinsics = pairIntrinsics();
  frame.baseline = kPairBaseline;
  const cv::Mat cropped = cvo::StereoCloudBuilder(settings.stereoOptions()).depth(frame);
  settings.cloud.crop_top_rows = 0;
  const cv::Mat whole = cvo::StereoCloudBuilder(settings.stereoOptions()).depth(frame);
  for (int v = 0; v < 84; ++v)
    for (int u = 0; u < cropped.cols; ++u)
      ASSERT_FALSE(std::isfinite(cropped.at<float>(v, u))) << "row " << v << " was matched";
  std::size_t both = 0, only_whole = 0, same = 0;
  for (int v = 100; v < cropped.rows; ++v) {
    for (int u = 0; u < cropped.cols; ++u) {
      const float a = cropped.at<float>(v, u), b = whole.at<float>(v, u);
      if (std::isfinite(a) && std::isfinite(b)) {
        ++both;
        same += std::abs(a - b) <= 0.01f * b;
      } else if (std::isfinite(b)) {
        ++only_whole;
      }
    }
  }
  ASSERT_GT(both, 200000u);
  EXPECT_LT(only_whole, both / 50) << "the band loses depth the whole pair has";
  EXPECT_GT(same, both * 95 / 100) << "depth within 1 % of the whole pair's";
}

TEST(DisparityConversion, EncodingsAndInvalidValues) {
  cv::Mat fixed_point = (cv::Mat_<std::int16_t>(1, 4) << 160, -16, 0, 320);  // OpenCV 16S
  const cv::Mat z = cvo::disparityToMetres(fixed_point, 100.0, 1.0 / 16.0, 0.5, 60.0);
  EXPECT_FLOAT_EQ(z.at<float>(0, 0), 10.0f);
  EXPECT_TRUE(std::isnan(z.at<float>(0, 1)));
  EXPECT_TRUE(std::isnan(z.at<float>(0, 2)));
  EXPECT_FLOAT_EQ(z.at<float>(0, 3), 5.0f);
  cv::Mat kitti16 = (cv::Mat_<std::uint16_t>(1, 2) << 2560, 256);  // KITTI: value / 256
  const cv::Mat z16 = cvo::disparityToMetres(kitti16, 100.0, 1.0 / 256.0, 0.5, 60.0);
  EXPECT_FLOAT_EQ(z16.at<float>(0, 0), 10.0f);
  EXPECT_TRUE(std::isnan(z16.at<float>(0, 1))) << "100 m is beyond max_depth";
  EXPECT_THROW(cvo::disparityToMetres(cv::Mat::zeros(2, 2, CV_64F), 1.0, 1.0, 0.1, 10.0),
               std::invalid_argument);
  EXPECT_THROW(cvo::disparityToMetres(kitti16, 0.0, 1.0, 0.1, 10.0), std::invalid_argument);
}

TEST(StereoFrontend, BadInputGetsAClearError) {
  cvo::StereoCloudBuilder builder(kittiSettings().stereoOptions());
  cvo::StereoFrame frame;
  frame.left = readGrey(kPair + "/left.png");
  frame.intrinsics = pairIntrinsics();
  frame.baseline = kPairBaseline;
  auto message = [&](const cvo::StereoFrame& f) {
    try {
      builder.build(f);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message(frame).find("neither a right image nor a disparity"), std::string::npos);
  cvo::StereoFrame small = frame;
  cv::resize(frame.left, small.right, cv::Size(620, 188));
  EXPECT_NE(message(small).find("but right is 620x188"), std::string::npos) << message(small);
  cvo::StereoFrame no_baseline = frame;
  no_baseline.right = frame.left;
  no_baseline.baseline = 0.0;
  EXPECT_NE(message(no_baseline).find("baseline must be positive"), std::string::npos);
  cvo::StereoMatcherOptions odd;
  odd.num_disparities = 100;
  EXPECT_THROW(cvo::StereoMatcher{odd}, std::invalid_argument);
}

// OpenCV 4.6's SGBM matches columns max(min + num, 0) .. cols + min(min, 0) and needs that band
// wider than block_size / 2 (StereoMatcherOptions::minImageWidth): sgbm_3way asks for a negative
// buffer size when it is empty (fuzz regression sgbm_3way_narrower_than_disparity_range), and all
// modes read past the band when it is narrower than half a block. Just inside the rule every mode
// really matches (same answer twice); one column less is refused before OpenCV is called.
TEST(StereoMatcher, SizeRuleForEveryModeJustInsideAndOutside) {
  struct Case {
    int min_disparity, num_disparities, block_size, min_width;
  };
  const Case cases[] = {{0, 16, 5, 19},  {0, 16, 11, 22}, {0, 32, 1, 33},
                        {-8, 16, 3, 18}, {4, 16, 5, 23},  {0, 128, 5, 131}};
  for (const std::string mode : {"sgbm", "hh", "sgbm_3way"}) {
    for (const Case& c : cases) {
      cvo::StereoMatcherOptions options;
      options.mode = mode;
      options.min_disparity = c.min_disparity;
      options.num_disparities = c.num_disparities;
      options.block_size = c.block_size;
      const std::string what = mode + " min " + std::to_string(c.min_disparity) + " num " +
                               std::to_string(c.num_disparities) + " block " +
                               std::to_string(c.block_size);
      ASSERT_EQ(options.minImageWidth(), c.min_width) << what;
      const cvo::StereoMatcher matcher(options);
      for (const int rows : {1, 2, 9}) {
        cv::Mat left(rows, c.min_width, CV_8UC1), right(rows, c.min_width, CV_8UC1);
        cv::theRNG().state = 16;
        cv::randu(left, 0, 256);
        cv::randu(right, 0, 256);
        EXPECT_NO_THROW(options.checkImageSize(c.min_width, rows)) << what;
        const cv::Mat first = matcher.disparity(left, right);
        ASSERT_EQ(first.size(), left.size()) << what;
        ASSERT_EQ(first.type(), CV_32FC1) << what;
        const cv::Mat second = matcher.disparity(left, right);
        EXPECT_TRUE(
            std::equal(first.begin<float>(), first.end<float>(), second.begin<float>(),
                       [](float a, float b) { return a == b || (std::isnan(a) && std::isnan(b)); }))
            << what << " rows " << rows;
        const int narrow = c.min_width - 1;
        EXPECT_THROW(options.checkImageSize(narrow, rows), std::invalid_argument) << what;
        try {
          matcher.disparity(left.colRange(0, narrow), right.colRange(0, narrow));
          ADD_FAILURE() << what << ": a " << narrow << "-column pair was matched";
        } catch (const std::invalid_argument& e) {
          EXPECT_NE(std::string(e.what()).find("needs images at least " +
                                               std::to_string(c.min_width) + " pixels wide"),
                    std::string::npos)
              << e.what();
        }
      }
    }
  }
  cvo::StereoMatcherOptions options;
  EXPECT_THROW(options.checkImageSize(0, 10), std::invalid_argument);
  EXPECT_THROW(options.checkImageSize(200, 0), std::invalid_argument);
  options.uniqueness_ratio = 100;  // sgbm_3way would divide by 100 - uniqueness_ratio
  EXPECT_THROW(cvo::StereoMatcher{options}, std::invalid_argument);
}

// The fuzzer's finding through the whole front end: a 1x1 pair for a 16-disparity matcher.
TEST(StereoFrontend, PairNarrowerThanTheDisparityRangeIsRefused) {
  cvo::StereoFrontendOptions options;
  options.matcher.num_disparities = 16;
  cvo::StereoCloudBuilder builder(options);
  cvo::StereoFrame frame;
  frame.left = cv::Mat(1, 1, CV_8UC1, cv::Scalar(9));
  frame.right = frame.left.clone();
  frame.intrinsics = pairIntrinsics();
  frame.intrinsics.width = frame.intrinsics.height = 1;
  frame.intrinsics.cx = frame.intrinsics.cy = 0.5;
  frame.baseline = kPairBaseline;
  try {
    builder.build(frame);
    ADD_FAILURE() << "a 1x1 stereo pair was matched";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("stereo pair is 1x1"), std::string::npos) << e.what();
  }
}

TEST(KittiSequence, ReadsCalibrationTimesAndImages) {
  const cvo::KittiSequence sequence(kKitti);
  ASSERT_EQ(sequence.size(), 8u);
  EXPECT_NEAR(sequence.calibration().left.fx, 707.0912, 1e-6);
  EXPECT_NEAR(sequence.calibration().baseline, 0.5372, 1e-4);
  EXPECT_EQ(sequence.calibration().left.width, 1226);
  EXPECT_EQ(sequence.calibration().left.height, 370);
  EXPECT_NEAR(sequence.stamps()[1] - sequence.stamps()[0], 0.1, 0.01);
  cv::Mat left, right, segmentation;
  sequence.load(3, &left, &right, &segmentation);
  EXPECT_EQ(left.size(), right.size());
  EXPECT_TRUE(segmentation.empty());
  EXPECT_THROW(cvo::KittiSequence(kKitti, 1), std::invalid_argument);
  EXPECT_THROW(cvo::KittiSequence(kData + "/tum_fr1_xyz"), std::runtime_error);
}

// One real stereo registration (frame 0 -> 1, about 1 m forward) against the official poses.
TEST(StereoFrontend, StereoCloudsRegisterToGroundTruth) {
  cvo::StereoCloudBuilder builder(kittiSettings().stereoOptions());
  const auto error = cvo_test::firstStepError(kKitti, builder, kittiSettings().cvo);
  ASSERT_GT(error.step_m, 0.5);
  ASSERT_TRUE(error.converged) << error.message;
  EXPECT_LT(error.translation_m, 0.05);
  EXPECT_LT(error.rotation_deg, 0.2);
}

}  // namespace
