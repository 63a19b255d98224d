// rostest node: bad input and tracking failures through the nodelet, with real TUM frames
// published here and the backend made to fail mid-run by the inject_backend_fault_after hook.
// Malformed input (no camera_info yet, NaN intrinsics, mismatched sizes, a wrong encoding) is
// skipped and counted, per reason, with the latest reason in the diagnostics; frames with nothing
// to track (no valid depth, too few points, a blank image, a large jump) are reported lost, never
// as trusted poses, with a grown covariance; good frames after all of it are tracked again, on the
// CPU after the backend failure.
#include <cmath>
#include <limits>

#include <opencv2/imgproc.hpp>

#include "rostest_main.hpp"
#include "tum_topic_driver.hpp"

namespace {

namespace enc = sensor_msgs::image_encodings;

class BadInput : public cvo_test::TumTopicDriver {
 protected:
  void SetUp() override {
    ASSERT_NO_FATAL_FAILURE(connect({0, 1, 2, 3, 4, 5, 6, 7, 8, 36}, false, false));
  }

  // The next frame time: stamps only go forward here.
  double next() { return t0_ + dt_ * static_cast<double>(++tick_); }

  sensor_msgs::ImagePtr depthFrom(const cv::Mat& metres, double stamp) const {
    return cv_bridge::CvImage(header(stamp), enc::TYPE_32FC1, metres).toImageMsg();
  }

  const double t0_ = 2000.0, dt_ = 1.0 / 30.0;
  int tick_ = 0;
};

bool atLeast(const std::string& value, long n) {
  return std::stol(value) >= n;
}

TEST_F(BadInput, MalformedInputIsSkippedFailuresAreFlaggedAndTrackingResumes) {
  // No camera_info yet: skipped, nothing published.
  publish(0, next());
  ASSERT_EQ(waitForSkipped(1), 1);
  EXPECT_EQ(waitFor(0), 0u);
  EXPECT_EQ(diagnostic("skipped: no camera_info yet"), "1");
  EXPECT_EQ(diagnostic("latest skip reason").rfind("no camera_info yet: ", 0), 0u)
      << diagnostic("latest skip reason");
  // NaN intrinsics: skipped.
  sensor_msgs::CameraInfo nan_info = cameraInfo();
  nan_info.K[0] = nan_info.P[0] = std::numeric_limits<double>::quiet_NaN();
  ASSERT_NO_FATAL_FAILURE(publishInfo(nan_info));
  publish(1, next());
  ASSERT_EQ(waitForSkipped(2), 2);
  EXPECT_EQ(waitFor(0), 0u);
  EXPECT_EQ(diagnostic("skipped: unreadable message"), "1");
  EXPECT_NE(diagnostic("latest skip reason").find("non-finite"), std::string::npos)
      << diagnostic("latest skip reason");

  ASSERT_NO_FATAL_FAILURE(publishInfo(cameraInfo()));
  publish(2, next());
  ASSERT_EQ(waitFor(1), 1u);
  EXPECT_EQ(indicator(0).state, "first_frame");
  publish(3, next());
  ASSERT_EQ(waitFor(2), 2u);
  EXPECT_EQ(indicator(1).state, "tracking") << indicator(1).problem;
  EXPECT_TRUE(indicator(1).trusted);

  // Depth of another size, and a colour encoding we do not read: skipped.
  cv::Mat small;
  cv::resize(depths_.at(4), small, cv::Size(320, 240), 0, 0, cv::INTER_NEAREST);
  double t = next();
  publish(colour(4, t), depthFrom(small, t));
  t = next();
  cv::Mat wide;
  images_.at(4).convertTo(wide, CV_16UC3, 256.0);
  publish(cv_bridge::CvImage(header(t), enc::BGR16, wide).toImageMsg(), depth(4, t));
  ASSERT_EQ(waitForSkipped(4), 4);
  EXPECT_EQ(waitFor(2), 2u);
  // Per reason: the depth of another size is refused by the odometry, the colour encoding is
  // unreadable.
  EXPECT_EQ(diagnostic("skipped: no camera_info yet"), "1");
  EXPECT_EQ(diagnostic("skipped: unreadable message"), "2");
  EXPECT_EQ(diagnostic("skipped: refused by the odometry"), "1");
  EXPECT_EQ(diagnostic("skipped: repeated stamp"), "0");
  EXPECT_EQ(diagnostic("skipped: internal error"), "0");

  // No valid depth: a lost frame, published as the flagged guess with a grown covariance.
  t = next();
  publish(colour(4, t), depthFrom(cv::Mat::zeros(480, 640, CV_32FC1), t));
  ASSERT_EQ(waitFor(3), 3u);
  EXPECT_EQ(indicator(2).state, "lost");
  EXPECT_FALSE(indicator(2).trusted);
  EXPECT_TRUE(indicator(2).published);
  EXPECT_EQ(indicator(2).problem, "no pixel has valid depth");

  // Valid depth in a 10x10 patch only: too few points to track. (A new colour image: one
  // repeating the previous frame's would be a stale frame, skipped.)
  cv::Mat patch(480, 640, CV_32FC1, cv::Scalar(0));
  depths_.at(4)(cv::Rect(300, 200, 10, 10)).copyTo(patch(cv::Rect(300, 200, 10, 10)));
  t = next();
  publish(colour(5, t), depthFrom(patch, t));
  ASSERT_EQ(waitFor(4), 4u);
  EXPECT_EQ(indicator(3).state, "lost");
  EXPECT_NE(indicator(3).problem.find("too few points"), std::string::npos) << indicator(3).problem;

  // A black image over real depth: registered more than once (retries), judged lost.
  t = next();
  publish(cv_bridge::CvImage(header(t), enc::BGR8, cv::Mat::zeros(480, 640, CV_8UC3)).toImageMsg(),
          depth(5, t));
  ASSERT_EQ(waitFor(5), 5u);
  EXPECT_EQ(indicator(4).state, "lost");
  EXPECT_GE(indicator(4).attempts, 2);
  EXPECT_FALSE(indicator(4).trusted);
  EXPECT_EQ(indicator(4).lost_frames, 3u);

  // Back to real frames: tracked against frame 3, the last good one.
  publish(6, next());
  ASSERT_EQ(waitFor(6), 6u);
  EXPECT_EQ(indicator(5).state, "tracking") << indicator(5).problem;
  EXPECT_TRUE(indicator(5).trusted);
  EXPECT_EQ(indicator(5).lost_frames, 0u);

  // Frame 36 one frame after frame 6: a 0.3 m jump, not trusted.
  publish(36, next());
  ASSERT_EQ(waitFor(7), 7u);
  EXPECT_FALSE(indicator(6).trusted) << indicator(6).state;

  publish(7, next());
  ASSERT_EQ(waitFor(8), 8u);
  EXPECT_TRUE(indicator(7).trusted) << indicator(7).problem;
  // The hook made the backend fail mid-run; the CPU took over and said so.
  EXPECT_NE(indicator(7).backend.find("fallback"), std::string::npos) << indicator(7).backend;
  EXPECT_NE(indicator(7).message.find("GPU failed"), std::string::npos) << indicator(7).message;

  // Odometry: one message per frame with a pose (keep_guess publishes lost frames too); the
  // guessed frames add at least (max_linear_speed * dt)^2 to the position variance.
  const auto odoms = odometry();
  ASSERT_EQ(odoms.size(), 8u);
  const double guessed = std::pow(5.0 * dt_, 2);
  EXPECT_LT(odoms[1].pose.covariance[0], 1e-4) << "a trusted registration is tight";
  EXPECT_GT(odoms[2].pose.covariance[0] - odoms[1].pose.covariance[0], 0.99 * guessed);
  EXPECT_GT(odoms[4].pose.covariance[0] - odoms[3].pose.covariance[0], 0.99 * guessed);

  // Diagnostics count all of it.
  EXPECT_TRUE(atLeast(diagnostic("skipped frames", [](auto v) { return atLeast(v, 4); }), 4));
  EXPECT_TRUE(atLeast(diagnostic("lost frames", [](auto v) { return atLeast(v, 4); }), 4));
  EXPECT_TRUE(atLeast(diagnostic("backend fallbacks", [](auto v) { return atLeast(v, 1); }), 1));
}

}  // namespace

int main(int argc, char** argv) {
  return cvo_test::runRosTests(argc, argv, "test_bad_input");
}
