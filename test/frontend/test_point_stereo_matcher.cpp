// The point stereo matcher (stereo_depth quarter, half, sparse) on the bundled KITTI pair and
// sequence: its disparities at corners against a third party's and dense SGBM's, its refusals,
// and the stereo front end's depth and clouds in each point mode.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <opencv2/features2d.hpp>
#include <opencv2/imgcodecs.hpp>

#include "cvo_odometry/frontend/block_costs.hpp"
#include "cvo_odometry/frontend/builtin_presets.hpp"
#include "cvo_odometry/frontend/point_stereo_matcher.hpp"
#include "cvo_odometry/frontend/stereo_cloud_builder.hpp"
#include "kitti_frames.hpp"

namespace {

const std::string kData = CVO_TEST_DATA_DIR;
const std::string kPair = kData + "/kitti_stereo_pair";
const std::string kKitti = kData + "/kitti_06_stereo";

cv::Mat readGrey(const std::string& path) {
  cv::Mat image = cv::imread(path, cv::IMREAD_GRAYSCALE);
  if (image.empty()) throw std::runtime_error("missing " + path);
  return image;
}

// FAST corners of the part of the left image that has stereo overlap and a third-party value.
std::vector<cv::Point> corners(const cv::Mat& left) {
  std::vector<cv::KeyPoint> keypoints;
  cv::FAST(left, keypoints, 20, true);
  std::vector<cv::Point> pixels;
  for (const auto& k : keypoints) {
    const cv::Point p(cvRound(k.pt.x), cvRound(k.pt.y));
    if (p.y >= 100 && p.x >= 128) pixels.push_back(p);
  }
  return pixels;
}

double median(std::vector<float> values) {
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
  return values[values.size() / 2];
}

// Both vectorised block costs (psadbw where there is SSE2, OpenCV's 16 lanes elsewhere) against
// the pixel-by-pixel sums, on the KITTI pair's rows (padded by 48 bytes, more than the costs
// read beyond a window row): windows of the matcher and its refinement (7 x 7, 15 x 5, up to
// 15 x 21) and wider than one 16-byte piece, at shifts from 0 up to past a 16-lane boundary.
TEST(BlockCosts, EqualThePixelByPixelSums) {
  cv::Mat left, right;
  cv::copyMakeBorder(readGrey(kPair + "/left.png"), left, 0, 0, 48, 48, cv::BORDER_REFLECT_101);
  cv::copyMakeBorder(readGrey(kPair + "/right.png"), right, 0, 0, 48, 48, cv::BORDER_REFLECT_101);
  struct Window {
    int h, rows;
  };
  int compared = 0;
  for (const Window window : {Window{0, 1}, Window{1, 3}, Window{2, 5}, Window{3, 7}, Window{3, 4},
                              Window{7, 5}, Window{7, 21}, Window{9, 3}, Window{15, 2}}) {
    for (int y = 150; y + window.rows < left.rows; y += 37) {
      for (int x = 80; x + 80 < left.cols; x += 53) {
        const std::uint8_t* a[32];
        const std::uint8_t* b[32];
        for (int r = 0; r < window.rows; ++r) {
          a[r] = left.ptr<std::uint8_t>(y + r) + x;
          b[r] = right.ptr<std::uint8_t>(y + r) + x - 40;
        }
        for (const auto& [from, to] : {std::pair{0, 1}, std::pair{0, 18}, std::pair{5, 38}}) {
          std::vector<std::uint16_t> fast(static_cast<std::size_t>(to - from)), lanes = fast,
                                                                                plain = fast;
          cvo::blockCosts(a, b, window.h, window.rows, from, to, fast.data());
          cvo::blockCostsInLanes(a, b, window.h, window.rows, from, to, lanes.data());
          cvo::blockCostsOneByOne(a, b, window.h, window.rows, from, to, plain.data());
          ASSERT_EQ(fast, plain) << "window " << 2 * window.h + 1 << " x " << window.rows
                                 << " at (" << x << ", " << y << "), shifts " << from << ".." << to;
          ASSERT_EQ(lanes, plain) << "16 lanes, window " << 2 * window.h + 1 << " x "
                                  << window.rows << " at (" << x << ", " << y << ")";
          ++compared;
        }
      }
    }
  }
  EXPECT_GT(compared, 500);
}

class PointMatcherLevels : public ::testing::TestWithParam<int> {};

// KITTI's stereo benchmark rule (3 px or 5 %) against the third party's disparity, and close to
// our dense SGBM's at the same corners: the point modes give the depth the dense mode gives.
TEST_P(PointMatcherLevels, CornersAgreeWithThirdPartyAndDenseDisparity) {
  const cv::Mat left = readGrey(kPair + "/left.png"), right = readGrey(kPair + "/right.png");
  const cv::Mat theirs = cv::imread(kPair + "/disparity.png", cv::IMREAD_UNCHANGED);
  ASSERT_EQ(theirs.type(), CV_8UC1);
  const cv::Mat dense = cvo::StereoMatcher{cvo::StereoMatcherOptions()}.disparity(left, right);
  cvo::PointMatcherOptions options;
  options.coarse_level = GetParam();
  cvo::PointStereoMatcher matcher(options);
  matcher.prepare(left, right);
  const auto pixels = corners(left);
  ASSERT_GT(pixels.size(), 1000u);
  const std::vector<float> disparities = matcher.match(pixels);
  ASSERT_EQ(disparities.size(), pixels.size());

  std::size_t matched = 0, compared = 0, agreeing = 0;
  std::vector<float> third_party_errors, dense_differences;
  for (std::size_t i = 0; i < pixels.size(); ++i) {
    const float d = disparities[i];
    if (!std::isfinite(d)) continue;
    ++matched;
    EXPECT_GE(d, options.min_disparity - 1.0f);
    EXPECT_LT(d, options.min_disparity + options.num_disparities + 1.0f);
    const float t = theirs.at<std::uint8_t>(pixels[i]);
    if (t > 0) {
      ++compared;
      const float error = std::abs(d - t);
      third_party_errors.push_back(error);
      if (error <= 3.0f || error <= 0.05f * t) ++agreeing;
    }
    const float s = dense.at<float>(pixels[i]);
    if (std::isfinite(s)) dense_differences.push_back(std::abs(d - s));
  }
  ASSERT_GT(compared, 500u);
  ASSERT_GT(dense_differences.size(), 500u);
  const double fraction = static_cast<double>(agreeing) / compared;
  std::cout << "coarse level " << GetParam() << ": " << matched << " of " << pixels.size()
            << " corners matched; vs third party: median |error| " << median(third_party_errors)
            << " px, " << 100.0 * fraction << " % within 3 px or 5 %; vs dense SGBM: median "
            << median(dense_differences) << " px\n";
  EXPECT_GT(matched, pixels.size() / 2) << "most corners must get a disparity";
  EXPECT_LT(median(third_party_errors), 1.0);
  EXPECT_GT(fraction, 0.90);
  EXPECT_LT(median(dense_differences), 0.5);
}

INSTANTIATE_TEST_SUITE_P(Sparse, PointMatcherLevels, ::testing::Values(0));
INSTANTIATE_TEST_SUITE_P(Half, PointMatcherLevels, ::testing::Values(1));
INSTANTIATE_TEST_SUITE_P(Quarter, PointMatcherLevels, ::testing::Values(2));

TEST(PointStereoMatcher, RefusesWhatItCannotMatch) {
  const cv::Mat left = readGrey(kPair + "/left.png"), right = readGrey(kPair + "/right.png");
  cvo::PointMatcherOptions options;
  cvo::PointStereoMatcher matcher(options);
  EXPECT_THROW(matcher.match(cv::Point(600, 200)), std::logic_error);  // before prepare()
  EXPECT_THROW(matcher.prepare(cv::Mat(), right), std::invalid_argument);
  EXPECT_THROW(matcher.prepare(left, right(cv::Rect(0, 0, 600, 300))), std::invalid_argument);
  EXPECT_THROW(matcher.prepare(left, right, left.rows), std::invalid_argument);
  matcher.prepare(left, right, 100);
  EXPECT_THROW(matcher.match(cv::Point(-1, 200)), std::invalid_argument);
  EXPECT_THROW(matcher.match(cv::Point(600, left.rows)), std::invalid_argument);
  // Above the prepared rows, or where the whole range leaves the right image: no disparity.
  EXPECT_TRUE(std::isnan(matcher.match(cv::Point(600, 20))));
  EXPECT_TRUE(std::isnan(matcher.match(cv::Point(2, 200))));

  cvo::PointMatcherOptions even_block;
  even_block.block_size = 4;
  EXPECT_THROW(even_block.validate(), std::invalid_argument);
  cvo::StereoMatcherOptions unknown_depth;
  unknown_depth.depth = "everywhere";
  EXPECT_THROW(unknown_depth.validate(), std::invalid_argument);
}

cvo::OdometrySettings kittiSettings(const std::string& depth) {
  cvo::OdometrySettings settings;
  cvo::applyPreset("kitti_stereo", &settings);
  settings.stereo.depth = depth;
  return settings;
}

class PointDepthModes : public ::testing::TestWithParam<std::string> {};

// In a point mode the depth image holds only the matched pixels, and the clouds built from it
// still register two KITTI frames to their ground-truth motion.
TEST_P(PointDepthModes, DepthAtThePointsAndCloudsRegisterToGroundTruth) {
  const cvo::KittiSequence sequence(kKitti);
  const auto settings = kittiSettings(GetParam());
  cvo::StereoCloudBuilder builder(settings.stereoOptions());
  const cv::Mat depth = builder.depth(cvo_test::kittiFrame(sequence, 0));
  ASSERT_EQ(depth.type(), CV_32FC1);
  const double with_depth = cv::countNonZero(depth == depth);  // NaN != NaN
  const double share = with_depth / depth.total();
  std::cout << GetParam() << ": " << 100.0 * share << " % of the pixels with depth\n";
  EXPECT_GT(with_depth, 2000.0);
  EXPECT_LT(share, 0.3) << "a point mode matches the pixels it uses, not the image";

  const auto error = cvo_test::firstStepError(kKitti, builder, settings.cvo);
  ASSERT_TRUE(error.converged) << error.message;
  EXPECT_LT(error.translation_m, 0.05);
  EXPECT_LT(error.rotation_deg, 0.2);
}

INSTANTIATE_TEST_SUITE_P(Modes, PointDepthModes, ::testing::Values("quarter", "half", "sparse"));

}  // namespace
