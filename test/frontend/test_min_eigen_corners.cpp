// MinEigenCorners against cv::goodFeaturesToTrack (what the feature tracker called before) on
// real frames, with a depth mask and a cropped top, and on degenerate images.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "cvo_odometry/frontend/depth_conversion.hpp"
#include "cvo_odometry/frontend/kitti_sequence.hpp"
#include "cvo_odometry/frontend/min_eigen_corners.hpp"
#include "cvo_odometry/frontend/tum_sequence.hpp"

namespace {

const std::string kData = CVO_TEST_DATA_DIR;
constexpr double kQuality = 0.01;

// OpenCV's corners as the tracker found them: rows from 2 above the crop (what the measure
// reads), the mask cutting the crop and the pixels without depth.
std::vector<cv::Point2f> openCvCorners(const cv::Mat& grey, const cv::Mat& depth, int crop,
                                       int max_corners, double min_distance) {
  const int first = std::clamp(crop - 2, 0, grey.rows);
  const cv::Range band(first, grey.rows);
  cv::Mat mask = (depth.rowRange(band) == depth.rowRange(band));
  mask.rowRange(0, std::clamp(crop - first, 0, mask.rows)).setTo(0);
  std::vector<cv::Point2f> corners;
  cv::goodFeaturesToTrack(grey.rowRange(band), corners, max_corners, kQuality, min_distance, mask,
                          3, false);
  for (cv::Point2f& corner : corners)
    corner.y += static_cast<float>(first);
  return corners;
}

void expectOpenCvsCorners(const cv::Mat& grey, const cv::Mat& depth, int crop) {
  cvo::MinEigenCorners finder;
  for (const double min_distance : {12.0, 7.0, 0.0}) {
    const std::vector<cv::Point2f> ours =
        finder.find(grey, depth, crop, 500, kQuality, min_distance);
    const std::vector<cv::Point2f> theirs = openCvCorners(grey, depth, crop, 500, min_distance);
    ASSERT_GT(theirs.size(), 250u) << "min_distance " << min_distance;
    // The same corners, strongest first: OpenCV sums the gradients in float, so corners of
    // nearly equal strength could change places (none do on these frames here): each found
    // within a few places of its rank in OpenCV's list.
    std::size_t near_rank = 0, found = 0;
    for (std::size_t k = 0; k < ours.size(); ++k) {
      const auto at = std::find(theirs.begin(), theirs.end(), ours[k]);
      found += at != theirs.end();
      const auto rank = static_cast<std::ptrdiff_t>(at - theirs.begin());
      near_rank += at != theirs.end() && std::abs(rank - static_cast<std::ptrdiff_t>(k)) <= 3;
      EXPECT_GE(ours[k].y, static_cast<float>(crop));
      EXPECT_TRUE(std::isfinite(depth.at<float>(cvRound(ours[k].y), cvRound(ours[k].x))));
    }
    EXPECT_NEAR(static_cast<double>(ours.size()), static_cast<double>(theirs.size()),
                0.01 * theirs.size());
    EXPECT_GE(found, ours.size() * 99 / 100) << "min_distance " << min_distance;
    EXPECT_GE(near_rank, ours.size() * 95 / 100) << "min_distance " << min_distance;
    for (std::size_t a = 0; a < ours.size() && min_distance > 0.0; ++a) {
      for (std::size_t b = a + 1; b < ours.size(); ++b)
        ASSERT_GE(cv::norm(ours[a] - ours[b]), min_distance);
    }
  }
}

}  // namespace

TEST(MinEigenCorners, FindsOpenCvsCornersOnATumFrame) {
  const cvo::TumSequence sequence(kData + "/tum_fr1_xyz");
  cv::Mat image, depth;
  sequence.load(5, &image, &depth);
  cv::Mat grey;
  cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  const cv::Mat metres = cvo::depthToMetres(depth, 5000.0, 0.1, 10.0);  // NaN where none
  expectOpenCvsCorners(grey, metres, 0);
  expectOpenCvsCorners(grey, metres, 1);
}

TEST(MinEigenCorners, FindsOpenCvsCornersBelowKittisCrop) {
  const cvo::KittiSequence sequence(kData + "/kitti_06_stereo");
  cv::Mat left, right;
  sequence.load(0, &left, &right, nullptr);
  if (left.channels() == 3) cv::cvtColor(left, left, cv::COLOR_BGR2GRAY);
  // Depth where the image is not dark (any mask will do; this one has holes everywhere).
  cv::Mat depth(left.size(), CV_32FC1, cv::Scalar(10.0f));
  depth.setTo(std::numeric_limits<float>::quiet_NaN(), left < 40);
  expectOpenCvsCorners(left, depth, 100);  // the KITTI preset's crop_top_rows
}

TEST(MinEigenCorners, DegenerateImagesGiveNoCornersAndNoFault) {
  cvo::MinEigenCorners finder;
  const auto count = [&](const cv::Mat& grey, const cv::Mat& depth, int first_row) {
    return finder.find(grey, depth, first_row, 100, kQuality, 5.0).size();
  };
  cv::Mat noise(40, 50, CV_8UC1);
  cv::randu(noise, 0, 256);
  const cv::Mat depth(noise.size(), CV_32FC1, cv::Scalar(1.0f));
  EXPECT_GT(count(noise, depth, 0), 10u);
  EXPECT_EQ(count(noise(cv::Rect(0, 0, 2, 2)), depth(cv::Rect(0, 0, 2, 2)), 0), 0u);
  EXPECT_LE(count(noise(cv::Rect(0, 0, 3, 3)), depth(cv::Rect(0, 0, 3, 3)), 0), 1u);  // the centre
  EXPECT_EQ(count(cv::Mat(40, 50, CV_8UC1, cv::Scalar(7)), depth, 0), 0u);            // flat
  const cv::Mat no_depth(noise.size(), CV_32FC1,
                         cv::Scalar(std::numeric_limits<float>::quiet_NaN()));
  EXPECT_EQ(count(noise, no_depth, 0), 0u);
  EXPECT_EQ(count(noise, depth, 39), 0u);  // no interior row left
  EXPECT_EQ(count(noise, depth, 1000), 0u);
  EXPECT_THROW(count(noise, depth(cv::Rect(0, 0, 10, 10)), 0), std::invalid_argument);
  // Farther apart than the image's diagonal: the strongest corner alone.
  EXPECT_EQ(finder.find(noise, depth, 0, 100, kQuality, 1e300).size(), 1u);
  // max_corners <= 0: every local maximum above the threshold.
  const std::size_t unlimited = finder.find(noise, depth, 0, 0, kQuality, 0.0).size();
  EXPECT_GT(unlimited, 100u);
  EXPECT_EQ(finder.find(noise, depth, 0, 100, kQuality, 0.0).size(), 100u);
  EXPECT_THROW(finder.find(noise, depth, 0, 100, 0.0, 5.0), std::invalid_argument);
  EXPECT_THROW(finder.find(noise, depth, 0, 100, kQuality, -1.0), std::invalid_argument);
  EXPECT_THROW(finder.find(noise, depth, 0, 100, kQuality, std::nan("")), std::invalid_argument);
  cv::Mat colour;
  cv::cvtColor(noise, colour, cv::COLOR_GRAY2BGR);
  EXPECT_THROW(count(colour, depth, 0), std::invalid_argument);
}
