// What the odometry refuses to trust, on real TUM frames with real feature tracks whose motion is
// then bent: a pose turned away from the tracks, and a registration nobody can judge to a
// frame placed by a guess.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

#include "cvo_odometry/core/keyframe_odometry.hpp"
#include "cvo_odometry/core/lie_group.hpp"
#include "cvo_odometry/frontend/feature_tracker.hpp"
#include "cvo_odometry/frontend/odometry_settings.hpp"
#include "cvo_odometry/frontend/rgbd_cloud_builder.hpp"
#include "cvo_odometry/frontend/tum_sequence.hpp"

namespace {

const std::string kData = CVO_TEST_DATA_DIR;
const std::string kConfig = std::string(CVO_SOURCE_DIR) + "/config/";
constexpr double kFrame = 1.0 / 30.0;

struct Frame {
  std::shared_ptr<const cvo::LabeledCloud> cloud;
  cvo::FrameImages images;
};

class TumTracked {
 public:
  TumTracked() : sequence_(kData + "/tum_fr1_xyz") {
    settings_ = cvo::loadOdometrySettings(kConfig + "tum_rgbd.yaml");
    settings_.depth_scale = 5000.0;
    settings_.cvo.backend = cvo::BackendChoice::kCpu;
    builder_ = std::make_unique<cvo::RgbdCloudBuilder>(settings_.rgbdOptions());
  }
  Frame frame(std::size_t k) {
    cvo::RgbdFrame f;
    sequence_.load(k, &f.image, &f.depth);
    f.intrinsics = cvo::tumIntrinsics("fr1");
    Frame out;
    out.cloud = std::make_shared<const cvo::LabeledCloud>(builder_->build(f, nullptr, &out.images));
    return out;
  }
  // Previous <- current from the corners of frame `from` tracked into frame `to`.
  cvo::MotionPrior prior(std::size_t from, std::size_t to) {
    cvo::FeatureTracker tracker(settings_.features);
    const Frame a = frame(from), b = frame(to);
    const cvo::PinholeIntrinsics K = cvo::tumIntrinsics("fr1");
    tracker.track(a.images.grey, a.images.depth, K);
    return tracker.track(b.images.grey, b.images.depth, K);
  }
  const cvo::CvoParams& params() const { return settings_.cvo; }

 private:
  cvo::TumSequence sequence_;
  cvo::OdometrySettings settings_;
  std::unique_ptr<cvo::RgbdCloudBuilder> builder_;
};

// The prior with `motion` (previous <- current) as its motion and its tracks seen where that
// motion puts them: tracks as consistent as real ones, of a motion off the truth.
cvo::MotionPrior seenBy(cvo::MotionPrior prior, const Eigen::Isometry3d& motion) {
  prior.motion = motion;
  const Eigen::Isometry3d current_from_previous = prior.motion.inverse();
  for (std::size_t k = 0; k < prior.points.size(); ++k) {
    const Eigen::Vector3d p = current_from_previous * prior.points[k];
    prior.observations[k] = p.head<2>() / p.z();
  }
  for (std::size_t k = 0; k < prior.tracked_points.size(); ++k) {
    const Eigen::Vector3d p = current_from_previous * prior.tracked_points[k];
    prior.tracked_observations[k] = p.head<2>() / p.z();
  }
  prior.second = {};
  return prior;
}

// The prior's motion turned by `degrees` about the camera's y axis.
cvo::MotionPrior turned(const cvo::MotionPrior& prior, double degrees) {
  Eigen::Isometry3d turn = Eigen::Isometry3d::Identity();
  turn.linear() = Eigen::AngleAxisd(degrees * M_PI / 180.0, Eigen::Vector3d::UnitY()).matrix();
  return seenBy(prior, prior.motion * turn);
}

// The prior's motion moved sideways (the previous camera's x) so that its inlier tracks miss the
// true motion by a median of `median_px`: a motion off by a centimetre or so.
cvo::MotionPrior shifted(const cvo::MotionPrior& prior, double median_px) {
  std::vector<double> px_per_metre;
  for (const Eigen::Vector3d& point : prior.points)
    px_per_metre.push_back(prior.focal_px / point.z());
  std::nth_element(px_per_metre.begin(), px_per_metre.begin() + px_per_metre.size() / 2,
                   px_per_metre.end());
  Eigen::Isometry3d shift = Eigen::Isometry3d::Identity();
  shift.translation().x() = median_px / px_per_metre[px_per_metre.size() / 2];
  return seenBy(prior, shift * prior.motion);
}

cvo::OdometryFrame odometryFrame(double stamp, const Frame& frame,
                                 std::optional<cvo::MotionPrior> prior) {
  cvo::OdometryFrame f;
  f.stamp = stamp;
  f.cloud = frame.cloud;
  f.prior = std::move(prior);
  return f;
}

// Tracks of a motion turned 0.8 deg from the truth: within track_agreement_px (10 px) of the
// registered pose nearly everywhere, yet turned past max_track_rotation_gap (0.5 deg): refused.
TEST(TrustRules, APoseTurnedFromTheTracksIsNotTrusted) {
  TumTracked tum;
  const cvo::MotionPrior real = tum.prior(0, 1);
  ASSERT_TRUE(real.solved) << real.problem;
  cvo::KeyframeOdometry honest(tum.params()), bent(tum.params());
  for (auto* odometry : {&honest, &bent})
    odometry->process(odometryFrame(0.0, tum.frame(0), {}));
  const cvo::OdometryUpdate right = honest.process(odometryFrame(kFrame, tum.frame(1), real));
  EXPECT_TRUE(right.trusted()) << right.problem;
  EXPECT_LT(right.track_rotation_gap_deg, 0.3);
  const cvo::OdometryUpdate off =
      bent.process(odometryFrame(kFrame, tum.frame(1), turned(real, 0.8)));
  EXPECT_FALSE(off.trusted());
  EXPECT_NE(off.problem.find("turns"), std::string::npos) << off.problem;
}

// With the moving classes left out of the frame by the segmentation, the tracks see only the
// rest of the view and fix its turn less well: twice max_track_rotation_gap is allowed, and no
// more.
TEST(TrustRules, WithMovingClassesLeftOutTwiceTheTurnIsAllowed) {
  TumTracked tum;
  const cvo::MotionPrior real = tum.prior(0, 1);
  ASSERT_TRUE(real.solved) << real.problem;
  // The pixel bound wide enough for a turn past twice the gap to be judged by the turn alone.
  cvo::CvoParams params = tum.params();
  params.track_agreement_px = 25.0;
  cvo::KeyframeOdometry within(params), beyond(params), unlabelled(params);
  for (auto* odometry : {&within, &beyond, &unlabelled})
    odometry->process(odometryFrame(0.0, tum.frame(0), {}));
  cvo::OdometryFrame labelled = odometryFrame(kFrame, tum.frame(1), turned(real, 0.8));
  labelled.moving_classes_left_out = true;
  const cvo::OdometryUpdate kept = within.process(labelled);
  EXPECT_TRUE(kept.trusted()) << kept.problem;
  EXPECT_GT(kept.track_rotation_gap_deg, 0.5);
  cvo::OdometryFrame far = odometryFrame(kFrame, tum.frame(1), turned(real, 1.3));
  far.moving_classes_left_out = true;
  const cvo::OdometryUpdate refused = beyond.process(far);
  EXPECT_FALSE(refused.trusted());
  EXPECT_NE(refused.problem.find("twice max_track_rotation_gap"), std::string::npos)
      << refused.problem;
  // The same turn without labels: refused at the gap itself.
  const cvo::OdometryUpdate plain =
      unlabelled.process(odometryFrame(kFrame, tum.frame(1), turned(real, 0.8)));
  EXPECT_FALSE(plain.trusted());
}

// Tracks that miss the registered pose by 7.5 px (median) while most lie within
// track_agreement_px (10 px): a registration the tracks allow. With a cosine below weak_cosine
// (raised here above this pair's cosine) as well, the two weak signs together refuse it; the
// real tracks with the same cosine, or the same tracks with a cosine above the bound, are
// trusted.
TEST(TrustRules, AWeakAlignmentThatTheTracksMissIsNotTrusted) {
  TumTracked tum;
  const cvo::MotionPrior first = tum.prior(0, 1), real = tum.prior(1, 2);
  ASSERT_TRUE(first.solved) << first.problem;
  ASSERT_TRUE(real.solved) << real.problem;
  cvo::CvoParams strict = tum.params();
  strict.weak_cosine = 0.99;
  cvo::KeyframeOdometry plain(tum.params()), weak(strict), weak_real(strict);
  for (auto* odometry : {&plain, &weak, &weak_real}) {
    odometry->process(odometryFrame(0.0, tum.frame(0), {}));
    const cvo::OdometryUpdate one = odometry->process(odometryFrame(kFrame, tum.frame(1), first));
    ASSERT_TRUE(one.trusted()) << one.problem;
  }
  const cvo::MotionPrior off = shifted(real, 7.5);
  const cvo::OdometryUpdate allowed = plain.process(odometryFrame(2 * kFrame, tum.frame(2), off));
  ASSERT_TRUE(allowed.trusted()) << allowed.problem;
  EXPECT_GT(allowed.track_error_px, 0.6 * strict.track_agreement_px);
  EXPECT_LT(allowed.cosine, strict.weak_cosine) << "the pair's cosine is weak for `strict`";
  EXPECT_GT(allowed.cosine, tum.params().weak_cosine);
  const cvo::OdometryUpdate refused = weak.process(odometryFrame(2 * kFrame, tum.frame(2), off));
  EXPECT_FALSE(refused.trusted());
  EXPECT_NE(refused.problem.find("weak alignment"), std::string::npos) << refused.problem;
  const cvo::OdometryUpdate kept = weak_real.process(odometryFrame(2 * kFrame, tum.frame(2), real));
  EXPECT_TRUE(kept.trusted()) << kept.problem;
}

// The prior with every `nth` inlier track seen 40 px right of where its motion puts it: of the
// tracks, about 1 - 1/nth agree with any pose near the truth.
cvo::MotionPrior withStrayTracks(cvo::MotionPrior prior, std::size_t nth) {
  for (std::size_t k = 0; k < prior.observations.size(); k += nth)
    prior.observations[k].x() += 40.0 / prior.focal_px;
  return prior;
}

// Until a frame since the start is trusted nothing tells whether something moves in view: the
// first registration needs moving_track_agreement (0.9) of the tracks, later ones
// min_track_agreement (0.75). With one track in six astray (about 83 % agree) the first frame
// is refused and the third, after a trusted second, is not.
TEST(TrustRules, TheFirstRegistrationAfterAStartNeedsTheMovingAgreement) {
  TumTracked tum;
  const cvo::MotionPrior first = tum.prior(0, 1), second = tum.prior(1, 2);
  ASSERT_TRUE(first.solved) << first.problem;
  ASSERT_TRUE(second.solved) << second.problem;
  cvo::KeyframeOdometry at_start(tum.params()), later(tum.params());
  for (auto* odometry : {&at_start, &later})
    odometry->process(odometryFrame(0.0, tum.frame(0), {}));
  const cvo::OdometryUpdate refused =
      at_start.process(odometryFrame(kFrame, tum.frame(1), withStrayTracks(first, 6)));
  EXPECT_FALSE(refused.trusted());
  EXPECT_NE(refused.problem.find("moving_track_agreement"), std::string::npos) << refused.problem;
  const cvo::OdometryUpdate one = later.process(odometryFrame(kFrame, tum.frame(1), first));
  ASSERT_TRUE(one.trusted()) << one.problem;
  const cvo::OdometryUpdate two =
      later.process(odometryFrame(2 * kFrame, tum.frame(2), withStrayTracks(second, 6)));
  EXPECT_TRUE(two.trusted()) << two.problem;
  EXPECT_LT(two.track_agreement, tum.params().moving_track_agreement);
  EXPECT_GE(two.track_agreement, tum.params().min_track_agreement);
}

// A frame lost for another reason (here a speed limit it breaks) is placed by its confident
// tracks and becomes the reference; the next frame, with no tracks to judge its registration to
// it, is not trusted there (its pose would be the guess's times a right motion) but registered
// to the last trusted frame instead.
TEST(TrustRules, NoTracksNoTrustAfterAFramePlacedByAGuess) {
  TumTracked tum;
  const cvo::MotionPrior real = tum.prior(0, 1);
  ASSERT_TRUE(real.solved) << real.problem;
  cvo::KeyframeOdometry odometry(tum.params());
  odometry.process(odometryFrame(0.0, tum.frame(0), {}));
  cvo::CvoParams slow = tum.params();
  slow.max_linear_speed = 0.01;  // m/s: the camera moves 0.3 m/s here
  odometry.setParams(slow);
  const cvo::OdometryUpdate lost = odometry.process(odometryFrame(kFrame, tum.frame(1), real));
  ASSERT_EQ(lost.state, cvo::TrackingState::kLost) << lost.problem;
  ASSERT_TRUE(lost.new_keyframe) << "placed by the prior, it is the next frame's reference";
  odometry.setParams(tum.params());
  const cvo::OdometryUpdate next = odometry.process(odometryFrame(2 * kFrame, tum.frame(2), {}));
  EXPECT_NE(next.problem.find("placed by a guess"), std::string::npos) << next.problem;
  EXPECT_EQ(next.state, cvo::TrackingState::kRecovered) << next.problem;
  EXPECT_EQ(next.dt, 2 * kFrame) << "registered to frame 0, the last trusted one";
  // With tracks from the last trusted frame the same registration is judged, and trusted.
  cvo::KeyframeOdometry judged(tum.params());
  judged.process(odometryFrame(0.0, tum.frame(0), {}));
  judged.setParams(slow);
  judged.process(odometryFrame(kFrame, tum.frame(1), real));
  judged.setParams(tum.params());
  cvo::MotionPrior from_start = tum.prior(0, 2);
  from_start.from_stamp = 0.0;
  const cvo::OdometryUpdate checked =
      judged.process(odometryFrame(2 * kFrame, tum.frame(2), from_start));
  EXPECT_TRUE(checked.trusted()) << checked.problem;
}

// The second lost frame in a row whose tracks find no motion restarts tracking, and the next
// frames' tracks start there, rather than frames being lost until max_lost_frames: tracks from
// the last anchor, further away with every frame, would find none either. The first lost frame,
// a second whose tracks still find the motion, and one without tracks at all (a hand over the
// lens) stay lost.
TEST(TrustRules, TheSecondLostFrameWhoseTracksFindNoMotionRestarts) {
  TumTracked tum;
  cvo::CvoParams slow = tum.params();
  slow.max_linear_speed = 0.01;  // m/s: the camera moves 0.3 m/s here, so frames 1 and 2 are lost
  ASSERT_GT(slow.max_lost_frames, 2);
  enum class Tracks { kNone, kNoMotion, kReaching };
  const auto run = [&](Tracks tracks) {
    cvo::KeyframeOdometry odometry(tum.params());
    odometry.process(odometryFrame(0.0, tum.frame(0), {}));
    odometry.setParams(slow);
    std::vector<cvo::OdometryUpdate> updates;
    for (std::size_t k : {1, 2}) {
      std::optional<cvo::MotionPrior> prior;
      if (tracks != Tracks::kNone) {
        prior = tum.prior(0, k);
        prior->from_stamp = 0.0;
        if (tracks == Tracks::kNoMotion) {
          prior->solved = false;  // as PnP finding no motion among them
          prior->problem = "no motion";
        }
      }
      updates.push_back(
          odometry.process(odometryFrame(static_cast<double>(k) * kFrame, tum.frame(k), prior)));
    }
    return updates;
  };
  const std::vector<cvo::OdometryUpdate> no_motion = run(Tracks::kNoMotion);
  EXPECT_EQ(no_motion[0].state, cvo::TrackingState::kLost) << no_motion[0].problem;
  EXPECT_FALSE(no_motion[0].restart_tracks);
  ASSERT_EQ(no_motion[1].state, cvo::TrackingState::kReset) << no_motion[1].problem;
  EXPECT_TRUE(no_motion[1].restart_tracks) << "the next frame's tracks start from the restart";
  EXPECT_NE(no_motion[1].problem.find("restart: the second lost frame"), std::string::npos)
      << no_motion[1].problem;
  const cvo::MotionPrior two_steps = tum.prior(0, 2);
  ASSERT_TRUE(two_steps.solved && two_steps.inliers >= tum.params().min_prior_inliers)
      << two_steps.problem;
  EXPECT_EQ(run(Tracks::kReaching)[1].state, cvo::TrackingState::kLost);
  EXPECT_EQ(run(Tracks::kNone)[1].state, cvo::TrackingState::kLost);
}

// With the moving classes left out of a frame, something that moves is in view and what it hid
// is missing from the registration: only the tracks judge it, and only a registration started
// from their motion is trusted. Without tracks, or from the still guess (tracks that judge but
// are too unsure to start from), the same frame 1 is trusted unlabelled and refused labelled.
TEST(TrustRules, WithMovingClassesLeftOutOnlyARegistrationFromTheTracksIsTrusted) {
  TumTracked tum;
  const cvo::MotionPrior real = tum.prior(0, 1);
  ASSERT_TRUE(real.solved) << real.problem;
  cvo::MotionPrior unsure = real;
  unsure.inlier_ratio = 0.5 * tum.params().min_prior_inlier_ratio;  // judges, guesses nothing
  const auto run = [&](std::optional<cvo::MotionPrior> prior, bool labelled) {
    cvo::KeyframeOdometry odometry(tum.params());
    odometry.process(odometryFrame(0.0, tum.frame(0), {}));
    cvo::OdometryFrame f = odometryFrame(kFrame, tum.frame(1), std::move(prior));
    f.moving_classes_left_out = labelled;
    return odometry.process(f);
  };
  for (const bool labelled : {false, true}) {
    SCOPED_TRACE(labelled ? "labelled" : "unlabelled");
    const cvo::OdometryUpdate from_tracks = run(real, labelled);
    EXPECT_TRUE(from_tracks.trusted()) << from_tracks.problem;
    EXPECT_EQ(from_tracks.guess, cvo::GuessKind::kFeatures);
    const cvo::OdometryUpdate untracked = run(std::nullopt, labelled);
    const cvo::OdometryUpdate still = run(unsure, labelled);
    EXPECT_EQ(untracked.trusted(), !labelled) << untracked.problem;
    EXPECT_EQ(still.trusted(), !labelled) << still.problem;
    if (labelled) {
      EXPECT_NE(untracked.problem.find("no feature tracks to judge"), std::string::npos)
          << untracked.problem;
      EXPECT_NE(still.problem.find("identity guess, not the feature tracks' motion"),
                std::string::npos)
          << still.problem;
    }
  }
}

}  // namespace
