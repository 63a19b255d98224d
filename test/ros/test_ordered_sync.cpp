// rostest node: drives the nodelet (default sync_policy ordered, segmentation on) with real TUM
// frames carrying their own colour and depth stamps, 12-20 ms apart as the camera stamped them,
// and checks that every frame is paired with its own depth (frame 31's depth is nearer to colour
// 30 than to colour 31: nearest-stamp pairing gets it wrong), its labels included, and that the
// diagnostics report the learned offset.
#include <algorithm>
#include <string>

#include "rostest_main.hpp"
#include "tum_topic_driver.hpp"

namespace {

const std::vector<std::size_t> kFrames = {25, 26, 27, 28, 29, 30, 31, 32, 33, 34, 35, 36};

class OrderedSync : public cvo_test::TumTopicDriver {
 protected:
  void SetUp() override { ASSERT_NO_FATAL_FAILURE(connect(kFrames, true)); }
};

TEST_F(OrderedSync, PairsEveryFrameWithItsOwnDepthAndLabels) {
  const cvo::TumSequence sequence(std::string(CVO_TEST_DATA_DIR) + "/tum_fr1_xyz");
  // All at once: the queues (ours and the nodelet's) hold them all, so the nodelet's speed
  // does not matter, and the pairer takes any arrival order.
  for (std::size_t k : kFrames) {
    const auto& stamps = sequence.frames()[k];
    publish(colour(k, stamps.rgb_stamp), depth(k, stamps.depth_stamp));
  }
  ASSERT_EQ(waitFor(kFrames.size()), kFrames.size());
  // Every frame handled once: the diagnostics count each processed frame, none skipped.
  const std::string processed =
      diagnostic("frames", [](const std::string& v) { return std::stoul(v) >= kFrames.size(); });
  EXPECT_EQ(processed, std::to_string(kFrames.size())) << "a frame was processed twice";
  EXPECT_EQ(waitFor(kFrames.size()), kFrames.size()) << "a frame was processed twice";
  EXPECT_EQ(diagnostic("skipped frames"), "0");
  for (std::size_t i = 0; i < kFrames.size(); ++i) {
    const auto report = indicator(i);
    // The odometry is stamped with the depth image's time: its own depth, not a neighbour's.
    EXPECT_EQ(report.header.stamp, ros::Time(sequence.frames()[kFrames[i]].depth_stamp))
        << "frame " << kFrames[i];
    if (i > 0) {
      EXPECT_TRUE(report.trusted) << "frame " << kFrames[i] << ": " << report.problem;
    }
  }
  const auto fields = cloudFields();
  EXPECT_NE(std::find(fields.begin(), fields.end(), "label"), fields.end())
      << "segmentation labels in the debug cloud";
  const std::string offset =
      diagnostic("depth - colour stamp offset (ms)", [](const std::string&) { return true; });
  ASSERT_FALSE(offset.empty()) << "no learned offset in the diagnostics";
  EXPECT_GT(std::stod(offset), -20.0);
  EXPECT_LT(std::stod(offset), -11.0);
  EXPECT_EQ(diagnostic("frames not synchronized", [](const std::string& v) { return v == "0"; }),
            "0");
}

}  // namespace

int main(int argc, char** argv) {
  return cvo_test::runRosTests(argc, argv, "test_ordered_sync");
}
