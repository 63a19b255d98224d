// Labels of ignored classes decide which pixels no stage uses (issue 40): the excluded mask of
// each kind of segmentation image, and on a real TUM frame the cloud, FrameImages::excluded and
// the photometric image all leaving out the ignored pixels grown by ignore_border_px.
#include <gtest/gtest.h>

#include <cstdint>
#include <string>

#include <opencv2/imgproc.hpp>

#include "cvo_odometry/frontend/depth_cloud_builder.hpp"
#include "cvo_odometry/frontend/depth_conversion.hpp"
#include "cvo_odometry/frontend/empty_frame_error.hpp"
#include "cvo_odometry/frontend/semantic_image.hpp"
#include "cvo_odometry/frontend/tum_sequence.hpp"

namespace {

const std::string kTum = std::string(CVO_TEST_DATA_DIR) + "/tum_fr1_xyz";

// Proves: excludedMask is 255 exactly where probabilities() is false (an ignored class or an id
// out of range) for 8-bit ids, 16-bit ids and float probabilities (by the most likely class).
TEST(ExcludedLabels, MaskOfEachSegmentationKind) {
  const cv::Mat ids8 = (cv::Mat_<std::uint8_t>(2, 3) << 0, 1, 2, 3, 9, 1);
  const cv::Mat mask8 = cvo::SemanticImage(ids8, 4, {1}).excludedMask();
  ASSERT_EQ(mask8.type(), CV_8UC1);
  ASSERT_EQ(mask8.size(), ids8.size());
  const cv::Mat want8 = (cv::Mat_<std::uint8_t>(2, 3) << 0, 255, 0, 0, 255, 255);
  EXPECT_EQ(cv::countNonZero(mask8 != want8), 0) << mask8;

  const cv::Mat ids16 = (cv::Mat_<std::uint16_t>(1, 5) << 0, 300, 299, 1000, 7);
  const cvo::SemanticImage wide(ids16, 301, {299, 7});
  const cv::Mat mask16 = wide.excludedMask();
  ASSERT_EQ(mask16.type(), CV_8UC1);
  const cv::Mat want16 = (cv::Mat_<std::uint8_t>(1, 5) << 0, 0, 255, 255, 255);
  EXPECT_EQ(cv::countNonZero(mask16 != want16), 0) << mask16;

  cv::Mat probs(1, 3, CV_32FC3);
  probs.at<cv::Vec3f>(0, 0) = {0.2f, 0.7f, 0.1f};  // class 1: ignored
  probs.at<cv::Vec3f>(0, 1) = {0.5f, 0.4f, 0.1f};  // class 0
  probs.at<cv::Vec3f>(0, 2) = {0.1f, 0.3f, 0.6f};  // class 2
  const cvo::SemanticImage soft(probs, 3, {1});
  const cv::Mat mask32 = soft.excludedMask();
  const cv::Mat want32 = (cv::Mat_<std::uint8_t>(1, 3) << 255, 0, 0);
  EXPECT_EQ(cv::countNonZero(mask32 != want32), 0) << mask32;

  // The same verdict as probabilities(), pixel by pixel.
  float p[301];
  for (int u = 0; u < 5; ++u)
    EXPECT_EQ(mask16.at<std::uint8_t>(0, u) != 0, !wide.probabilities(u, 0, p)) << u;
  for (int u = 0; u < 3; ++u)
    EXPECT_EQ(mask32.at<std::uint8_t>(0, u) != 0, !soft.probabilities(u, 0, p)) << u;
  // Nothing ignored and every id in range: nothing excluded.
  EXPECT_EQ(cv::countNonZero(cvo::SemanticImage(ids8, 10).excludedMask()), 0);
}

struct TumFrame {
  cv::Mat image, depth;
  cvo::PinholeIntrinsics K;
};

TumFrame tumFrame(std::size_t k) {
  const cvo::TumSequence sequence(kTum);
  TumFrame frame;
  cv::Mat raw;
  sequence.load(k, &frame.image, &raw);
  frame.depth = cvo::depthToMetres(raw, 5000.0, 0.1, 10.0);
  frame.K = cvo::tumIntrinsics("fr1");
  frame.K.distortion.clear();  // a point projects back onto its pixel with K alone
  return frame;
}

cvo::CloudBuilderOptions labelledOptions(int border) {
  cvo::CloudBuilderOptions options;
  options.semantic_classes = 2;
  options.ignore_classes = {1};
  options.ignore_border_px = border;
  options.image_levels = 2;
  return options;
}

// Proves: with a label square of an ignored class on a real TUM frame, no cloud point projects
// inside the square grown by ignore_border_px (while points crowd right outside it and the
// unlabelled cloud has points inside), FrameImages::excluded is exactly that grown square, and
// the photometric image's usable() is false inside it and true outside.
TEST(ExcludedLabels, CloudImagesAndPhotometricImageLeaveTheGrownSquareOut) {
  const TumFrame frame = tumFrame(5);
  const cv::Rect square(220, 150, 120, 100);  // has depth on the fixture's desk
  cv::Mat labels(frame.image.size(), CV_8UC1, cv::Scalar(0));
  labels(square).setTo(1);
  for (const int border : {0, 8, 15}) {
    SCOPED_TRACE("ignore_border_px " + std::to_string(border));
    const cv::Rect grown(square.x - border, square.y - border, square.width + 2 * border,
                         square.height + 2 * border);
    cvo::DepthCloudBuilder builder(labelledOptions(border));
    cvo::FrameImages images;
    const cvo::LabeledCloud cloud =
        builder.build(frame.image, frame.depth, frame.K, labels, nullptr, &images);
    ASSERT_GT(cloud.size(), 1000u);

    // FrameImages::excluded: the grown square, nothing else.
    cv::Mat expected(frame.image.size(), CV_8UC1, cv::Scalar(0));
    expected(grown).setTo(255);
    ASSERT_EQ(images.excluded.type(), CV_8UC1);
    ASSERT_EQ(images.excluded.size(), frame.image.size());
    EXPECT_EQ(cv::countNonZero((images.excluded != 0) != (expected != 0)), 0);

    // No point inside the grown square; many within 25 px around it.
    int inside = 0, around = 0;
    const cv::Rect ring(grown.x - 25, grown.y - 25, grown.width + 50, grown.height + 50);
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      const Eigen::Vector3f p = cloud.position(i);
      const double u = frame.K.fx * p.x() / p.z() + frame.K.cx;
      const double v = frame.K.fy * p.y() / p.z() + frame.K.cy;
      const cv::Point pixel(cvRound(u), cvRound(v));
      ASSERT_LT(std::abs(u - pixel.x), 1e-2) << "a point off its pixel";
      inside += grown.contains(pixel);
      around += ring.contains(pixel) && !grown.contains(pixel);
      ASSERT_EQ(cloud.semantics(i)[1], 0.0f) << "a point of the ignored class";
    }
    EXPECT_EQ(inside, 0);
    EXPECT_GT(around, 50) << "the cloud reaches the square's border";

    // The photometric stage's image: unusable exactly inside the grown square.
    const cvo::IntensityImage* image = cloud.image();
    ASSERT_NE(image, nullptr);
    ASSERT_TRUE(image->hasExcludedPixels());
    int wrong = 0;
    for (int v = 1; v < image->height() - 1; ++v) {
      for (int u = 1; u < image->width() - 1; ++u)
        wrong += image->usable(u, v) == grown.contains(cv::Point(u, v));
    }
    EXPECT_EQ(wrong, 0) << "pixels whose usable() disagrees with the grown square";
  }

  // Without labels the same frame has points inside the square: the test above can fail.
  cvo::CloudBuilderOptions plain;
  cvo::DepthCloudBuilder unlabelled(plain);
  cvo::FrameImages images;
  const cvo::LabeledCloud all =
      unlabelled.build(frame.image, frame.depth, frame.K, cv::Mat(), nullptr, &images);
  EXPECT_TRUE(images.excluded.empty());
  ASSERT_NE(all.image(), nullptr);
  EXPECT_FALSE(all.image()->hasExcludedPixels());
  int inside = 0;
  for (std::size_t i = 0; i < all.size(); ++i) {
    const Eigen::Vector3f p = all.position(i);
    inside += square.contains(cv::Point(cvRound(frame.K.fx * p.x() / p.z() + frame.K.cx),
                                        cvRound(frame.K.fy * p.y() / p.z() + frame.K.cy)));
  }
  EXPECT_GT(inside, 100);
}

// Proves: when every pixel with depth is of an ignored class the frame is an EmptyFrameError
// whose message names ignore_classes; labels that leave a strip that has depth still build.
TEST(ExcludedLabels, EveryPixelExcludedIsAnEmptyFrameNamingIgnoreClasses) {
  const TumFrame frame = tumFrame(0);
  cvo::DepthCloudBuilder builder(labelledOptions(8));
  const cv::Mat all_ignored(frame.image.size(), CV_8UC1, cv::Scalar(1));
  try {
    builder.build(frame.image, frame.depth, frame.K, all_ignored, nullptr);
    FAIL() << "no EmptyFrameError";
  } catch (const cvo::EmptyFrameError& e) {
    EXPECT_NE(std::string(e.what()).find("ignore_classes"), std::string::npos) << e.what();
  }
  // The border grows the labels over the rest: a strip narrower than the border is gone too.
  cv::Mat nearly(frame.image.size(), CV_8UC1, cv::Scalar(1));
  nearly.rowRange(200, 206).setTo(0);
  EXPECT_THROW(builder.build(frame.image, frame.depth, frame.K, nearly, nullptr),
               cvo::EmptyFrameError);
  cv::Mat wider(frame.image.size(), CV_8UC1, cv::Scalar(1));
  wider.rowRange(200, 260).setTo(0);
  EXPECT_GT(builder.build(frame.image, frame.depth, frame.K, wider, nullptr).size(), 100u);
}

}  // namespace
