// countSilentFailures (core/trajectory_evaluation.hpp): a trusted frame is judged against the
// trusted frame before it, never against an untrusted guess between them, and not across a
// restart.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "cvo_odometry/core/trajectory_evaluation.hpp"

namespace {

constexpr int kFrames = 10;
constexpr double kDt = 1.0 / 30.0;

double stampOf(int k) {
  return 100.0 + k * kDt;
}

// The camera 1 cm further along x and 0.2 degrees further about z every frame.
Eigen::Isometry3d truthAt(int k) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() =
      Eigen::AngleAxisd(0.2 * k * M_PI / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  pose.translation() << 0.01 * k, 0.002 * k, 0.0;
  return pose;
}

Eigen::Isometry3d shifted(const Eigen::Isometry3d& pose, double dx) {
  Eigen::Isometry3d out = pose;
  out.translation().x() += dx;
  return out;
}

struct Recorded {
  cvo::AssociatedPoses poses;
  std::vector<double> trusted;

  Recorded() {
    for (int k = 0; k < kFrames; ++k) {
      poses.stamps.push_back(stampOf(k));
      poses.ground_truth.push_back(truthAt(k));
      poses.estimate.push_back(truthAt(k));
      trusted.push_back(stampOf(k));
    }
  }
  void distrust(int k) { trusted.erase(std::find(trusted.begin(), trusted.end(), stampOf(k))); }
};

// Proves: a correct trajectory has no silent failure, every trusted frame but the first judged.
TEST(SilentFailures, CorrectTrajectoryHasNone) {
  const Recorded run;
  const cvo::SilentFailures s = cvo::countSilentFailures(run.poses, run.trusted);
  EXPECT_EQ(s.judged, static_cast<std::size_t>(kFrames - 1));
  EXPECT_EQ(s.failures, 0u);
}

// Proves: a trusted frame whose pose is consistent with an untrusted guess before it, but wrong
// from the last trusted frame, is a silent failure: the guess is no baseline.
TEST(SilentFailures, WrongTrustedFrameAfterAGuessIsJudgedAgainstThePreviousTrusted) {
  Recorded run;
  // Frame 5 is a lost frame's guess 5 cm off; frame 6 continues from the guess (right relative
  // to it, 5 cm off relative to frame 4) and is reported as trusted.
  for (int k = 5; k < kFrames; ++k)
    run.poses.estimate[k] = shifted(truthAt(k), 0.05);
  run.distrust(5);
  const cvo::SilentFailures s = cvo::countSilentFailures(run.poses, run.trusted);
  EXPECT_EQ(s.judged, static_cast<std::size_t>(kFrames - 2)) << "frame 5 is not judged";
  EXPECT_EQ(s.failures, 1u) << "frame 6 against frame 4 is 5 cm off";

  // Trusted all along, frame 5 itself would be the failure: the same count, another frame.
  Recorded all_trusted;
  for (int k = 5; k < kFrames; ++k)
    all_trusted.poses.estimate[k] = shifted(truthAt(k), 0.05);
  EXPECT_EQ(cvo::countSilentFailures(all_trusted.poses, all_trusted.trusted).failures, 1u);
}

// Proves: a wrong untrusted guess does not make the right trusted frame after it a failure
// (it is judged against the trusted frame before the guess, from which it is right).
TEST(SilentFailures, RightTrustedFrameAfterAWrongGuessIsNoFailure) {
  Recorded run;
  run.poses.estimate[5] = shifted(truthAt(5), 0.3);  // a wild guess, not trusted
  run.distrust(5);
  const cvo::SilentFailures s = cvo::countSilentFailures(run.poses, run.trusted);
  EXPECT_EQ(s.judged, static_cast<std::size_t>(kFrames - 2));
  EXPECT_EQ(s.failures, 0u);
}

// Proves: the pair across a restart stamp is not judged (the odometry started anew there, its
// pose jumps back to the origin), while the same jump without the restart is a failure.
TEST(SilentFailures, PairAcrossARestartIsNotJudged) {
  Recorded run;
  // Restarted at frame 6: poses from there on start again at the identity.
  for (int k = 6; k < kFrames; ++k)
    run.poses.estimate[k] = truthAt(6).inverse() * truthAt(k);
  const cvo::SilentFailures without = cvo::countSilentFailures(run.poses, run.trusted);
  EXPECT_EQ(without.judged, static_cast<std::size_t>(kFrames - 1));
  EXPECT_EQ(without.failures, 1u) << "the jump back to the origin";
  const cvo::SilentFailures with =
      cvo::countSilentFailures(run.poses, run.trusted, 0.5, 0.02, 1.0, {stampOf(6)});
  EXPECT_EQ(with.judged, static_cast<std::size_t>(kFrames - 2)) << "(5, 6) not judged";
  EXPECT_EQ(with.failures, 0u);
  // The judged pairs' error leaves the jump out: the steps are the truth's.
  EXPECT_GT(without.translation_rmse, 0.01);
  EXPECT_NEAR(with.translation_rmse, 0.0, 1e-9);
  EXPECT_NEAR(with.rotation_rmse_deg, 0.0, 1e-6);
  // A restart stamp between an untrusted frame and the trusted one after it ends the stretch
  // too: frame 5 untrusted, restart stamped at frame 5, frame 6 not judged against frame 4.
  run.distrust(5);
  const cvo::SilentFailures across =
      cvo::countSilentFailures(run.poses, run.trusted, 0.5, 0.02, 1.0, {stampOf(5)});
  EXPECT_EQ(across.judged, static_cast<std::size_t>(kFrames - 3));
  EXPECT_EQ(across.failures, 0u);
}

// Proves the rule's bounds: a translation error is a failure only above both half the step and
// 2 cm; a rotation error above 1 degree always is.
TEST(SilentFailures, ErrorsAreJudgedByTheStepAndTheFloors) {
  const auto failuresWith = [](const Eigen::Isometry3d& error) {
    Recorded run;
    // Frame 5 carries the error; frames after it repeat the truth's steps from frame 5's pose.
    run.poses.estimate[5] = truthAt(5) * error;
    for (int k = 6; k < kFrames; ++k)
      run.poses.estimate[k] = run.poses.estimate[5] * truthAt(5).inverse() * truthAt(k);
    return cvo::countSilentFailures(run.poses, run.trusted).failures;
  };
  Eigen::Isometry3d small = Eigen::Isometry3d::Identity(), large = small, turned = small,
                    slightly_turned = small;
  small.translation() << 0.015, 0.0, 0.0;  // above half the 1 cm step, below 2 cm
  large.translation() << 0.03, 0.0, 0.0;   // above both
  turned.linear() =
      Eigen::AngleAxisd(1.5 * M_PI / 180.0, Eigen::Vector3d::UnitY()).toRotationMatrix();
  slightly_turned.linear() =
      Eigen::AngleAxisd(0.5 * M_PI / 180.0, Eigen::Vector3d::UnitY()).toRotationMatrix();
  EXPECT_EQ(failuresWith(small), 0u);
  EXPECT_EQ(failuresWith(large), 1u);
  EXPECT_EQ(failuresWith(slightly_turned), 0u);
  EXPECT_EQ(failuresWith(turned), 1u);
}

}  // namespace
