// FeatureTracker on real TUM frames: the corners of each frame are found on a thread beside it,
// from copies of the caller's images (which the caller may reuse at once); a tracker reset or
// destroyed while that thread runs waits for it.
#include <gtest/gtest.h>

#include <limits>

#include <opencv2/imgproc.hpp>

#include "cvo_odometry/frontend/depth_conversion.hpp"
#include "cvo_odometry/frontend/disparity_offset_calibration.hpp"
#include "cvo_odometry/frontend/feature_tracker.hpp"
#include "cvo_odometry/frontend/tum_sequence.hpp"

namespace {

const std::string kTum = std::string(CVO_TEST_DATA_DIR) + "/tum_fr1_xyz";

struct GreyFrame {
  cv::Mat grey, depth;
};

GreyFrame load(const cvo::TumSequence& sequence, std::size_t k) {
  cv::Mat image, depth;
  sequence.load(k, &image, &depth);
  GreyFrame frame;
  cv::cvtColor(image, frame.grey, cv::COLOR_BGR2GRAY);
  frame.depth = cvo::depthToMetres(depth, 5000.0, 0.1, 10.0);
  return frame;
}

}  // namespace

TEST(FeatureTracker, ImagesTheCallerReusesDoNotChangeThePriors) {
  const cvo::TumSequence sequence(kTum);
  const cvo::PinholeIntrinsics K = cvo::tumIntrinsics("fr1");
  cvo::FeatureTracker prompt({}), delayed({}), viewed({});
  for (std::size_t k = 0; k < 6; ++k) {
    const GreyFrame frame = load(sequence, k);
    const cvo::MotionPrior a = prompt.track(frame.grey, frame.depth, K);
    // The caller's buffers may change once track() returns: the corners' thread has its own.
    GreyFrame reused{frame.grey.clone(), frame.depth.clone()};
    const cvo::MotionPrior b = delayed.track(reused.grey, reused.depth, K);
    reused.grey.setTo(0);
    reused.depth.setTo(0);
    // A view into a larger image (border wider than the KLT window, which OpenCV's pyramid
    // would otherwise take as its first level) is copied too.
    cv::Mat padded;
    cv::copyMakeBorder(frame.grey, padded, 40, 40, 40, 40, cv::BORDER_REFLECT_101);
    const cvo::MotionPrior c =
        viewed.track(padded(cv::Rect(40, 40, frame.grey.cols, frame.grey.rows)), frame.depth, K);
    padded.setTo(0);
    EXPECT_TRUE(prompt.seeded());  // waits: the next frame has corners to track
    if (k == 0) {
      EXPECT_FALSE(a.solved);
      continue;
    }
    ASSERT_TRUE(a.solved) << a.problem;
    ASSERT_TRUE(b.solved) << b.problem;
    EXPECT_GT(a.inliers, 100);
    EXPECT_EQ(a.inliers, b.inliers);
    EXPECT_LT((a.motion.matrix() - b.motion.matrix()).norm(), 1e-12) << "frame " << k;
    ASSERT_TRUE(c.solved) << c.problem;
    EXPECT_EQ(a.inliers, c.inliers);
    EXPECT_LT((a.motion.matrix() - c.motion.matrix()).norm(), 1e-12) << "frame " << k;
    EXPECT_GT(a.seed_ms, 0.0);  // the previous frame's corners took time, beside it
  }
}

TEST(FeatureTracker, ResetOrDestructionWhileCornersAreFoundIsSafe) {
  const cvo::TumSequence sequence(kTum);
  const cvo::PinholeIntrinsics K = cvo::tumIntrinsics("fr1");
  const GreyFrame first = load(sequence, 0), second = load(sequence, 1);
  {
    cvo::FeatureTracker tracker({});
    tracker.track(first.grey, first.depth, K);
  }  // destroyed with its corners' thread running
  cvo::FeatureTracker tracker({});
  tracker.track(first.grey, first.depth, K);
  tracker.reset();
  EXPECT_FALSE(tracker.seeded());
  EXPECT_FALSE(tracker.hasPreviousFrame());
  const cvo::MotionPrior after_reset = tracker.track(second.grey, second.depth, K);
  EXPECT_FALSE(after_reset.solved);
  EXPECT_NE(after_reset.problem.find("no corners"), std::string::npos) << after_reset.problem;
}

// A new disparity offset moves the kept corners along their rays: with the tracker's unbounded
// range (what the pipeline gives it) corners beyond the cloud's max_depth stay and the next frame
// is solved from them; the cloud's bound would have dropped every one of these far corners.
TEST(FeatureTracker, RemappedCornersBeyondTheCloudsMaxDepthStay) {
  const cvo::TumSequence sequence(kTum);
  const cvo::PinholeIntrinsics K = cvo::tumIntrinsics("fr1");
  GreyFrame first = load(sequence, 0), second = load(sequence, 1);
  first.depth *= 100.0;  // 50-200 m: beyond a 40 m cap
  second.depth *= 100.0;
  const double focal_baseline = 388.0, cap = 40.0;
  cvo::FeatureTracker unbounded({}), capped({});
  unbounded.track(first.grey, first.depth, K);
  capped.track(first.grey, first.depth, K);
  const double infinite = std::numeric_limits<double>::infinity();
  unbounded.remapDepths(cvo::depthAtNewOffset(0.0, 0.05, focal_baseline, 0.1, infinite));
  capped.remapDepths(cvo::depthAtNewOffset(0.0, 0.05, focal_baseline, 0.1, cap));
  EXPECT_TRUE(unbounded.seeded());
  EXPECT_FALSE(capped.seeded());
  const cvo::MotionPrior prior = unbounded.track(second.grey, second.depth, K);
  ASSERT_TRUE(prior.solved) << prior.problem;
  EXPECT_GT(prior.inliers, 100);
}
