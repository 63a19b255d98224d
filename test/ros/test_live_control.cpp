// rostest node: drives the nodelet with real TUM frames published here (exact sync, segmentation
// on) and checks the live controls: segmentation wired into the clouds, dynamic_reconfigure
// changing ell_min for the next frame, a malformed frame skipped while later frames still give
// odometry, time going backwards and the reset service both restarting the odometry.
#include <algorithm>

#include <dynamic_reconfigure/Reconfigure.h>
#include <std_srvs/Empty.h>

#include "rostest_main.hpp"
#include "tum_topic_driver.hpp"

namespace {

class LiveControl : public cvo_test::TumTopicDriver {
 protected:
  void SetUp() override { ASSERT_NO_FATAL_FAILURE(connect({0, 1, 2, 3, 4, 5, 6, 7}, true)); }

  // Frame `k` with its depth in an 8-bit encoding the nodelet must refuse.
  void publishMalformed(std::size_t k, double stamp) {
    cv::Mat bytes;
    depths_.at(k).convertTo(bytes, CV_8U, 50.0);
    publish(
        colour(k, stamp),
        cv_bridge::CvImage(header(stamp), sensor_msgs::image_encodings::MONO8, bytes).toImageMsg());
  }
};

TEST_F(LiveControl, ReconfigureMalformedFramesTimeJumpAndReset) {
  const double t0 = 1000.0, dt = 1.0 / 30.0;
  publish(0, t0);
  ASSERT_EQ(waitFor(1), 1u);
  publish(1, t0 + dt);
  ASSERT_EQ(waitFor(2), 2u);
  EXPECT_TRUE(indicator(0).first_frame);
  EXPECT_FALSE(indicator(1).first_frame);
  EXPECT_TRUE(indicator(1).converged) << indicator(1).message;
  EXPECT_NEAR(indicator(1).final_lengthscale, 0.02, 1e-9);  // the preset's ell_min
  const auto fields = cloudFields();
  EXPECT_NE(std::find(fields.begin(), fields.end(), "label"), fields.end())
      << "segmentation labels in the debug cloud";

  // dynamic_reconfigure: ell_min 0.02 -> 0.03, visible in the next report.
  dynamic_reconfigure::Reconfigure change;
  dynamic_reconfigure::DoubleParameter ell_min;
  ell_min.name = "ell_min";
  ell_min.value = 0.03;
  change.request.config.doubles.push_back(ell_min);
  ASSERT_TRUE(
      ros::service::waitForService("cvo_odometry/set_parameters", ros::Duration(kEventTimeout)));
  ASSERT_TRUE(ros::service::call("cvo_odometry/set_parameters", change));
  publish(2, t0 + 2 * dt);
  ASSERT_EQ(waitFor(3), 3u);
  EXPECT_NEAR(indicator(2).final_lengthscale, 0.03, 1e-9);

  // A malformed frame (8-bit depth) is skipped; the next good frame still gives odometry.
  publishMalformed(3, t0 + 3 * dt);
  ASSERT_EQ(waitForSkipped(1), 1) << "the malformed frame was not skipped";
  EXPECT_EQ(waitFor(3), 3u) << "the malformed frame produced a report";
  publish(4, t0 + 4 * dt);
  ASSERT_EQ(waitFor(4), 4u);
  EXPECT_FALSE(indicator(3).first_frame) << "odometry continues after a skipped frame";

  // Time going backwards (a looping bag) restarts the odometry.
  publish(5, t0 - 10.0);
  ASSERT_EQ(waitFor(5), 5u);
  EXPECT_TRUE(indicator(4).first_frame);
  publish(6, t0 - 10.0 + dt);
  ASSERT_EQ(waitFor(6), 6u);
  EXPECT_FALSE(indicator(5).first_frame);

  // The reset service restarts it too.
  std_srvs::Empty reset;
  ASSERT_TRUE(ros::service::waitForService("cvo_odometry/reset", ros::Duration(kEventTimeout)));
  ASSERT_TRUE(ros::service::call("cvo_odometry/reset", reset));
  publish(7, t0 - 10.0 + 2 * dt);
  ASSERT_EQ(waitFor(7), 7u);
  EXPECT_TRUE(indicator(6).first_frame);
}

}  // namespace

int main(int argc, char** argv) {
  return cvo_test::runRosTests(argc, argv, "test_live_control");
}
