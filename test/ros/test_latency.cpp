// rostest node: the live default keeps latency bounded. A burst of 20 real TUM frames, stamped
// as they are sent and published faster than the nodelet registers them: the newest frame is
// always processed, every older frame that waited is dropped and counted (diagnostics and the
// indicator), and the latency from stamp to publish is reported. The assertions are on counts,
// not on how fast this machine is: however many frames a slow machine drops, processed +
// dropped is the number sent. The camera_transform parameter is published on /tf_static.
#include <cmath>
#include <string>

#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>

#include "rostest_main.hpp"
#include "tum_topic_driver.hpp"

namespace {

class Latency : public cvo_test::TumTopicDriver {
 protected:
  static constexpr std::size_t kFrames = 20;
  void SetUp() override {
    std::vector<std::size_t> frames;
    for (std::size_t k = 0; k < kFrames; ++k)
      frames.push_back(k);
    ASSERT_NO_FATAL_FAILURE(connect(frames, false));
  }

  // Waits until the indicator of `stamp` arrived; returns whether it did.
  bool waitForStamp(const ros::Time& stamp) {
    const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(kEventTimeout);
    while (ros::WallTime::now() < deadline) {
      {
        std::lock_guard<std::mutex> lock(record_.mutex);
        // Stamps went through a double (header()): equal to well below a microsecond.
        if (!record_.indicators.empty() &&
            std::abs((record_.indicators.back().header.stamp - stamp).toSec()) < 1e-6)
          return true;
      }
      ros::WallDuration(0.05).sleep();
    }
    return false;
  }
};

TEST_F(Latency, NewestFrameProcessedEveryDropCounted) {
  ros::Time last;
  for (std::size_t k = 0; k < kFrames; ++k) {
    last = ros::Time::now();
    publish(k, last.toSec());
    ros::WallDuration(0.002).sleep();  // distinct stamps
  }
  ASSERT_TRUE(waitForStamp(last)) << "the newest frame was not processed";
  const std::size_t processed = waitFor(1);
  const cvo_odometry::CvoIndicator newest = indicator(processed - 1);
  EXPECT_EQ(processed + newest.dropped_frames, kFrames)
      << processed << " processed, " << newest.dropped_frames << " dropped";
  const std::string expected = std::to_string(kFrames - processed);
  EXPECT_EQ(
      diagnostic("frames dropped for latency", [&](const std::string& v) { return v == expected; }),
      expected);
  EXPECT_EQ(
      diagnostic("frames", [&](const std::string& v) { return v == std::to_string(processed); }),
      std::to_string(processed));
  EXPECT_EQ(diagnostic("frames not synchronized"), "0");
  // Reported, from the stamps set at sending: positive, and below a limit only a hang reaches.
  const double latency_ms = std::stod(diagnostic("latency (ms, stamp to publish)"));
  EXPECT_GT(latency_ms, 0.0);
  EXPECT_LT(latency_ms, kEventTimeout * 1000.0);
  EXPECT_NEAR(newest.latency_ms, latency_ms, 1e-3 * latency_ms + 0.01);  // printed rounded
}

TEST_F(Latency, TheStatedCameraTransformIsPublished) {
  // Sent when the first frame names the camera's frame (the test above sent them).
  tf2_ros::Buffer buffer;
  tf2_ros::TransformListener listener(buffer);
  geometry_msgs::TransformStamped camera;
  ASSERT_NO_THROW(camera = buffer.lookupTransform("base_link", "camera_rgb_optical_frame",
                                                  ros::Time(0), ros::Duration(kEventTimeout)));
  EXPECT_NEAR(camera.transform.translation.x, 0.1, 1e-9);
  EXPECT_NEAR(camera.transform.translation.z, 0.3, 1e-9);
  // Optical z forward = base x, optical x = base -y: the quaternion (0.5, -0.5, 0.5, -0.5).
  const auto& q = camera.transform.rotation;
  EXPECT_NEAR(std::abs(0.5 * q.w - 0.5 * q.x + 0.5 * q.y - 0.5 * q.z), 1.0, 1e-9)
      << q.w << " " << q.x << " " << q.y << " " << q.z;
}

}  // namespace

int main(int argc, char** argv) {
  return cvo_test::runRosTests(argc, argv, "test_latency");
}
