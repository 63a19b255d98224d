// rostest node: drives the nodelet (default sync_policy ordered, segmentation on) with real TUM
// frames carrying their own colour and depth stamps, 12-20 ms apart as the camera stamped them,
// and checks that every frame is paired with its own depth (frame 31's depth is nearer to colour
// 30 than to colour 31: nearest-stamp pairing gets it wrong), its labels included, and that the
// diagnostics report the learned offset; then that a source with other timing on the same topics
// is paired again once the offset is learned afresh.
#include <algorithm>
#include <cmath>
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

// Another source on the same topics (a driver restarted with other settings): stamps 1000 s
// later and depth stamped like its colour image, outside the window learned above. After a run
// of unpaired frames the offset is learned again and the frames pair with their own depth.
class OrderedSyncNewTiming : public cvo_test::TumTopicDriver {
 protected:
  static constexpr std::size_t kNewFrames = 30;
  void SetUp() override {
    std::vector<std::size_t> frames(kNewFrames);
    for (std::size_t k = 0; k < kNewFrames; ++k)
      frames[k] = k;
    ASSERT_NO_FATAL_FAILURE(connect(frames, true));
  }
};

TEST_F(OrderedSyncNewTiming, LearnsTheOffsetAgainAndPairsOnceMore) {
  const cvo::TumSequence sequence(std::string(CVO_TEST_DATA_DIR) + "/tum_fr1_xyz");
  const std::size_t before = waitFor(0);
  for (std::size_t k = 0; k < kNewFrames; ++k) {
    const double stamp = sequence.frames()[k].rgb_stamp + 1000.0;
    publish(colour(k, stamp), depth(k, stamp));
  }
  // The first frames of the new source go unpaired (10, or a few more with the arrival order),
  // the rest pair with their own depth once the offset is learned again.
  const std::size_t after = waitFor(before + 15);
  ASSERT_GE(after, before + 15) << "frames did not pair again with the new timing";
  for (std::size_t i = before; i < after; ++i) {
    const double stamp = indicator(i).header.stamp.toSec();
    bool own_colour_stamp = false;
    for (std::size_t k = 0; k < kNewFrames; ++k)
      own_colour_stamp |= std::abs(stamp - (sequence.frames()[k].rgb_stamp + 1000.0)) < 1e-6;
    EXPECT_TRUE(own_colour_stamp) << "indicator " << i << " at " << stamp;
  }
  const std::string offset = diagnostic("depth - colour stamp offset (ms)",
                                        [](const std::string& v) { return std::stod(v) > -1.0; });
  EXPECT_NEAR(std::stod(offset), 0.0, 1.0) << "the offset was not learned again";
}

}  // namespace

int main(int argc, char** argv) {
  return cvo_test::runRosTests(argc, argv, "test_ordered_sync");
}
