// Tracking-failure detection and recovery of KeyframeOdometry on real frames through the
// front end: frames that do not overlap, a blank image, no valid depth and a large jump are
// flagged and never reported as trusted poses; the policies and the recovery do what they say.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>

#include <opencv2/imgcodecs.hpp>

#include "cvo_odometry/core/keyframe_odometry.hpp"
#include "cvo_odometry/core/lie_group.hpp"
#include "cvo_odometry/core/params_io.hpp"
#include "cvo_odometry/core/trajectory_io.hpp"
#include "cvo_odometry/frontend/empty_frame_error.hpp"
#include "cvo_odometry/frontend/kitti_sequence.hpp"
#include "cvo_odometry/frontend/odometry_settings.hpp"
#include "cvo_odometry/frontend/rgbd_cloud_builder.hpp"
#include "cvo_odometry/frontend/stereo_cloud_builder.hpp"
#include "cvo_odometry/frontend/tum_sequence.hpp"
#include "kitti_frames.hpp"

namespace {

using cvo::KeyframeOdometry;
using cvo::LabeledCloud;
using cvo::OdometryUpdate;
using cvo::TrackingState;

const std::string kData = CVO_TEST_DATA_DIR;
const std::string kConfig = std::string(CVO_SOURCE_DIR) + "/config/";
constexpr double kFrame = 1.0 / 30.0;

cvo::CvoParams preset(const std::string& name) {
  cvo::CvoParams params = cvo::loadOdometrySettings(kConfig + name).cvo;
  params.backend = cvo::BackendChoice::kCpu;
  params.reference = cvo::ReferenceKind::kPreviousFrame;  // these cases are frame to frame
  return params;
}

// The TUM preset with the colour kernel on: its cosine then judges appearance too, so a frame
// whose image went blank over real depth is lost (the preset itself registers depth only and
// tracks such a frame by its geometry; see BlackImageUnderTheGeometricPreset).
cvo::CvoParams colourKernelPreset() {
  cvo::CvoParams params = preset("tum_rgbd.yaml");
  params.use_color = true;
  params.ell_min = 0.05;
  return params;
}

// Frames of the TUM fixture through the TUM preset's front end; images can be altered first.
class TumFrames {
 public:
  TumFrames() : sequence_(kData + "/tum_fr1_xyz") {
    cvo::OdometrySettings settings = cvo::loadOdometrySettings(kConfig + "tum_rgbd.yaml");
    settings.depth_scale = 5000.0;
    builder_ = std::make_unique<cvo::RgbdCloudBuilder>(settings.rgbdOptions());
  }
  cvo::RgbdFrame frame(std::size_t k) const {
    cvo::RgbdFrame f;
    sequence_.load(k, &f.image, &f.depth);
    f.intrinsics = cvo::tumIntrinsics("fr1");
    return f;
  }
  LabeledCloud cloud(const cvo::RgbdFrame& f) const { return builder_->build(f); }
  LabeledCloud cloud(std::size_t k) const { return cloud(frame(k)); }

 private:
  cvo::TumSequence sequence_;
  std::unique_ptr<cvo::RgbdCloudBuilder> builder_;
};

double angleDeg(const Eigen::Isometry3d& T) {
  return cvo::lie::logSO3(T.rotation()).norm() * 180.0 / M_PI;
}

void print(const char* what, const OdometryUpdate& u) {
  std::cout << what << ": " << cvo::toString(u.state) << ", cosine " << u.cosine << ", "
            << u.attempts << " attempt(s), motion " << u.motion.translation().norm() << " m "
            << angleDeg(u.motion) << " deg" << (u.problem.empty() ? "" : " (" + u.problem + ")")
            << "\n";
}

TEST(TrackingFailures, TheWholeTumFixtureTracksWithoutAFalseAlarm) {
  const TumFrames tum;
  KeyframeOdometry odometry(preset("tum_rgbd.yaml"));
  double lowest_cosine = 1.0;
  for (std::size_t k = 0; k < 37; ++k) {
    const OdometryUpdate u = odometry.process(k * kFrame, tum.cloud(k));
    if (k == 0) continue;
    EXPECT_EQ(u.state, TrackingState::kTracking) << "frame " << k << ": " << u.problem;
    EXPECT_EQ(u.attempts, 1);
    lowest_cosine = std::min(lowest_cosine, u.cosine);
  }
  std::cout << "lowest cosine over the fixture: " << lowest_cosine << "\n";
}

TEST(TrackingFailures, ABlankImageIsFlaggedNotTrusted) {
  const TumFrames tum;
  KeyframeOdometry odometry(colourKernelPreset());
  odometry.process(0.0, tum.cloud(0));
  const OdometryUpdate good = odometry.process(kFrame, tum.cloud(1));
  ASSERT_EQ(good.state, TrackingState::kTracking);
  cvo::RgbdFrame blank = tum.frame(2);
  blank.image.setTo(cv::Scalar::all(0));  // the camera delivered black, depth still real
  const OdometryUpdate u = odometry.process(2 * kFrame, tum.cloud(blank));
  print("blank image", u);
  EXPECT_EQ(u.state, TrackingState::kLost);
  EXPECT_EQ(u.attempts, 2) << "a recovery attempt comes first";
  EXPECT_NE(u.problem.find("cosine"), std::string::npos) << u.problem;
  // keep_guess: the pose is the constant-velocity guess from the last good frame.
  EXPECT_TRUE(u.has_pose);
  const Eigen::Isometry3d guess = good.pose * good.motion;
  EXPECT_LT((u.pose.matrix() - guess.matrix()).norm(), 1e-9);
  // The next good frame is registered to the last good one (frame 1), two intervals back.
  const OdometryUpdate next = odometry.process(3 * kFrame, tum.cloud(3));
  EXPECT_EQ(next.state, TrackingState::kTracking) << next.problem;
  EXPECT_NEAR(next.dt, 2 * kFrame, 1e-12);
  EXPECT_EQ(next.lost_frames, 0);
}

TEST(TrackingFailures, NoValidDepthIsALostFrame) {
  const TumFrames tum;
  KeyframeOdometry odometry(preset("tum_rgbd.yaml"));
  odometry.process(0.0, tum.cloud(0));
  odometry.process(kFrame, tum.cloud(1));
  cvo::RgbdFrame zero = tum.frame(2);
  zero.depth.setTo(cv::Scalar::all(0));
  EXPECT_THROW(tum.cloud(zero), cvo::EmptyFrameError);
  try {
    tum.cloud(zero);
  } catch (const cvo::EmptyFrameError& e) {
    const OdometryUpdate u = odometry.processLostFrame(2 * kFrame, e.what());
    EXPECT_EQ(u.state, TrackingState::kLost);
    EXPECT_EQ(u.attempts, 0);
    EXPECT_EQ(u.problem, "no pixel has valid depth");
  }
  // Too few points is lost without a registration too.
  const LabeledCloud full = tum.cloud(3);
  const LabeledCloud tiny = full.strided(full.size() / 50 + 1);  // about 50 points
  const OdometryUpdate u = odometry.process(3 * kFrame, tiny);
  EXPECT_EQ(u.state, TrackingState::kLost);
  EXPECT_EQ(u.lost_frames, 2);
  EXPECT_NE(u.problem.find("too few points"), std::string::npos) << u.problem;
}

TEST(TrackingFailures, ALargeJumpIsFlagged) {
  // Frames 0 and 36 are 0.39 m and 10 deg apart; stamped one frame apart that is 12 m/s.
  const TumFrames tum;
  KeyframeOdometry odometry(preset("tum_rgbd.yaml"));
  odometry.process(0.0, tum.cloud(0));
  const OdometryUpdate u = odometry.process(kFrame, tum.cloud(36));
  print("jump", u);
  EXPECT_NE(u.state, TrackingState::kTracking);
  EXPECT_NE(u.state, TrackingState::kRecovered);
}

TEST(TrackingFailures, StereoFramesWithoutOverlapAreFlagged) {
  // KITTI 06 frame 0, then the KITTI 00 pair (another road): nothing in common.
  const cvo::KittiSequence sequence(kData + "/kitti_06_stereo");
  const cvo::StereoFrontendOptions options =
      cvo::loadOdometrySettings(kConfig + "kitti_stereo.yaml").stereoOptions();
  cvo::StereoCloudBuilder builder(options);
  auto kitti06 = [&](std::size_t k) { return cvo_test::kittiCloud(sequence, builder, k); };
  cvo::StereoFrame other;
  other.left = cv::imread(kData + "/kitti_stereo_pair/left.png", cv::IMREAD_GRAYSCALE);
  other.right = cv::imread(kData + "/kitti_stereo_pair/right.png", cv::IMREAD_GRAYSCALE);
  other.intrinsics = cvo_test::pairIntrinsics();
  other.baseline = cvo_test::kPairBaseline;

  KeyframeOdometry odometry(preset("kitti_stereo.yaml"));
  odometry.process(0.0, kitti06(0));
  const OdometryUpdate good = odometry.process(0.1, kitti06(1));
  print("kitti 0-1", good);
  EXPECT_EQ(good.state, TrackingState::kTracking) << good.problem;
  const OdometryUpdate u = odometry.process(0.2, builder.build(other));
  print("kitti no overlap", u);
  EXPECT_EQ(u.state, TrackingState::kLost);
  EXPECT_LT((u.pose.matrix() - (good.pose * good.motion).matrix()).norm(), 1e-9)
      << "the guess, flagged";
  // Frame 2 is registered to frame 1, the last good one. Stamped 0.2 s after it, the
  // constant-velocity guess is 1.2 m too far and the first attempt fails; the retry from
  // identity with the first-frame lengthscale recovers the true motion.
  const OdometryUpdate back = odometry.process(0.3, kitti06(2));
  print("kitti back", back);
  EXPECT_EQ(back.state, TrackingState::kRecovered) << back.problem;
  const auto gt = cvo::readKittiTrajectory(kData + "/kitti_06_stereo/poses.txt");
  const Eigen::Isometry3d error = (gt[1].pose.inverse() * gt[2].pose).inverse() * back.motion;
  EXPECT_LT(error.translation().norm(), 0.05);
  EXPECT_LT(angleDeg(error), 0.2);
}

TEST(TrackingFailures, BlackImageUnderTheGeometricPreset) {
  // Depth still real: CVO tracks the frame by geometry; the photometric stage sees images that
  // do not match and keeps CVO's rotation instead of fitting noise.
  const TumFrames tum;
  KeyframeOdometry odometry(preset("tum_rgbd.yaml"));
  odometry.process(0.0, tum.cloud(0));
  const OdometryUpdate good = odometry.process(kFrame, tum.cloud(1));
  ASSERT_TRUE(good.photometric.applied) << good.photometric.skipped;
  EXPECT_GT(good.photometric.correlation, 0.9);
  cvo::RgbdFrame blank = tum.frame(2);
  blank.image.setTo(cv::Scalar::all(0));
  const OdometryUpdate u = odometry.process(2 * kFrame, tum.cloud(blank));
  print("black image, geometric preset", u);
  EXPECT_EQ(u.state, TrackingState::kTracking) << u.problem;
  EXPECT_FALSE(u.photometric.applied);
  EXPECT_NE(u.photometric.skipped.find("images do not match"), std::string::npos)
      << u.photometric.skipped;
}

TEST(TrackingFailures, PublishNothingReportsNoPoseForALostFrame) {
  const TumFrames tum;
  cvo::CvoParams params = colourKernelPreset();
  params.lost_frame_policy = cvo::LostFramePolicy::kPublishNothing;
  KeyframeOdometry odometry(params);
  odometry.process(0.0, tum.cloud(0));
  cvo::RgbdFrame blank = tum.frame(1);
  blank.image.setTo(cv::Scalar::all(255));
  const OdometryUpdate u = odometry.process(kFrame, tum.cloud(blank));
  EXPECT_EQ(u.state, TrackingState::kLost);
  EXPECT_FALSE(u.has_pose);
  const OdometryUpdate next = odometry.process(2 * kFrame, tum.cloud(2));
  EXPECT_EQ(next.state, TrackingState::kTracking) << next.problem;
  EXPECT_TRUE(next.has_pose);
}

TEST(TrackingFailures, ResetRestartsFromTheFrameAndHoldsThePose) {
  const TumFrames tum;
  cvo::CvoParams params = preset("tum_rgbd.yaml");
  params.lost_frame_policy = cvo::LostFramePolicy::kReset;
  KeyframeOdometry odometry(params);
  odometry.process(0.0, tum.cloud(0));
  const OdometryUpdate before = odometry.process(kFrame, tum.cloud(1));
  const OdometryUpdate jump = odometry.process(2 * kFrame, tum.cloud(36));
  EXPECT_EQ(jump.state, TrackingState::kReset);
  EXPECT_TRUE(jump.has_pose);
  EXPECT_EQ(jump.pose.matrix(), before.pose.matrix()) << "odom must not jump on a reset";
  // Frame 36 is the new reference: frame 35 is one real frame away from it.
  const OdometryUpdate next = odometry.process(3 * kFrame, tum.cloud(35));
  EXPECT_EQ(next.state, TrackingState::kTracking) << next.problem;
  EXPECT_LT(next.motion.translation().norm(), 0.03);
}

TEST(TrackingFailures, TooManyLostFramesInARowRestartTracking) {
  const TumFrames tum;
  cvo::CvoParams params = preset("tum_rgbd.yaml");
  params.max_lost_frames = 2;
  KeyframeOdometry odometry(params);
  odometry.process(0.0, tum.cloud(0));
  odometry.process(kFrame, tum.cloud(1));
  EXPECT_EQ(odometry.processLostFrame(2 * kFrame, "no depth").state, TrackingState::kLost);
  EXPECT_EQ(odometry.processLostFrame(3 * kFrame, "no depth").state, TrackingState::kLost);
  const OdometryUpdate reset = odometry.processLostFrame(4 * kFrame, "no depth");
  EXPECT_EQ(reset.state, TrackingState::kReset);
  EXPECT_FALSE(odometry.hasReference()) << "a frame without a cloud leaves no reference";
  const OdometryUpdate restart = odometry.process(5 * kFrame, tum.cloud(5));
  EXPECT_TRUE(restart.firstFrame());
  EXPECT_EQ(restart.pose.matrix(), reset.pose.matrix());
}

}  // namespace
