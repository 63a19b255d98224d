// Segmentation input: class-id images (8/16-bit), class-probability images, ignored classes,
// and labels carried into the cloud built from a real TUM frame.
#include <gtest/gtest.h>

#include "cvo_odometry/frontend/rgbd_cloud_builder.hpp"
#include "cvo_odometry/frontend/semantic_image.hpp"
#include "cvo_odometry/frontend/tum_sequence.hpp"

namespace {

TEST(SemanticImage, ClassIdsBecomeOneHotAndIgnoredClassesDrop) {
  cv::Mat ids8 = (cv::Mat_<std::uint8_t>(1, 4) << 0, 2, 3, 9);
  const cvo::SemanticImage image(ids8, 4, {3});
  float p[4];
  ASSERT_TRUE(image.probabilities(1, 0, p));
  EXPECT_EQ(std::vector<float>(p, p + 4), (std::vector<float>{0, 0, 1, 0}));
  EXPECT_FALSE(image.probabilities(2, 0, p)) << "class 3 is ignored";
  EXPECT_FALSE(image.probabilities(3, 0, p)) << "id 9 is out of range";

  cv::Mat ids16 = (cv::Mat_<std::uint16_t>(1, 2) << 300, 1);
  const cvo::SemanticImage wide(ids16, 301);
  std::vector<float> q(301);
  ASSERT_TRUE(wide.probabilities(0, 0, q.data()));
  EXPECT_EQ(q[300], 1.0f);
}

TEST(SemanticImage, ProbabilityChannelsPassThroughUnlessTheirBestClassIsIgnored) {
  cv::Mat probs(1, 2, CV_32FC3);
  probs.at<cv::Vec3f>(0, 0) = {0.2f, 0.7f, 0.1f};
  probs.at<cv::Vec3f>(0, 1) = {0.1f, 0.1f, 0.8f};
  const cvo::SemanticImage image(probs, 3, {2});
  float p[3];
  ASSERT_TRUE(image.probabilities(0, 0, p));
  EXPECT_FLOAT_EQ(p[1], 0.7f);
  EXPECT_FALSE(image.probabilities(1, 0, p));
  EXPECT_THROW(cvo::SemanticImage(probs, 5), std::invalid_argument) << "3 channels for 5 classes";
  EXPECT_THROW(cvo::SemanticImage(cv::Mat::zeros(2, 2, CV_64F), 2), std::invalid_argument);
}

// Synthetic labels on a real frame: left half "sky" (ignored), right half class 2.
TEST(RgbdFrontend, SegmentationLabelsTheCloudAndDropsIgnoredPixels) {
  const cvo::TumSequence sequence(std::string(CVO_TEST_DATA_DIR) + "/tum_fr1_xyz");
  cvo::RgbdFrame frame;
  sequence.load(3, &frame.image, &frame.depth);
  frame.intrinsics = cvo::tumIntrinsics("fr1");
  frame.intrinsics.distortion.clear();
  frame.semantics = cv::Mat(480, 640, CV_8UC1, cv::Scalar(2));
  frame.semantics.colRange(0, 320).setTo(0);
  cvo::RgbdFrontendOptions options;
  options.depth_units_per_metre = 5000.0;
  options.cloud.semantic_classes = 3;
  options.cloud.ignore_classes = {0};
  cvo::RgbdCloudBuilder builder(options);
  const auto cloud = builder.build(frame);
  ASSERT_GT(cloud.size(), 1000u);
  ASSERT_EQ(cloud.semanticClasses(), 3);
  const auto& K = frame.intrinsics;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    ASSERT_EQ(cloud.semantics(i)[2], 1.0f);
    ASSERT_GE(K.fx * cloud.position(i).x() / cloud.position(i).z() + K.cx, 319.5);
  }
  frame.semantics = cv::Mat();
  EXPECT_THROW(builder.build(frame), std::invalid_argument) << "segmentation expected";
  frame.semantics = cv::Mat(240, 320, CV_8UC1, cv::Scalar(1));
  EXPECT_THROW(builder.build(frame), std::invalid_argument) << "segmentation size mismatch";
}

}  // namespace
