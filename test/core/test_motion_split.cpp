// Two motions among a frame's tracks (core/motion_split.hpp) on synthetic priors whose tracks
// follow known motions: a background far away and an object patch near the camera, moving on
// its own. Which one the scene follows is decided by occlusion, then the depth ratio, then track
// counts, with the constant-velocity prediction able to veto.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <optional>
#include <set>
#include <utility>

#include "cvo_odometry/core/cvo_params.hpp"
#include "cvo_odometry/core/motion_split.hpp"

namespace {

constexpr double kFocal = 500.0, kCx = 320.0, kCy = 240.0;
constexpr int kWidth = 640, kHeight = 480;

// The camera's motion between the frames (previous <- current): 2 cm right, 1 cm forward, a
// 0.3 degree turn.
Eigen::Isometry3d cameraMotion() {
  Eigen::Isometry3d m = Eigen::Isometry3d::Identity();
  m.linear() = Eigen::AngleAxisd(0.3 * M_PI / 180.0, Eigen::Vector3d::UnitY()).toRotationMatrix();
  m.translation() << 0.02, 0.0, 0.01;
  return m;
}

// The motion that explains an object's tracks when the object moved by `moved` (metres, the
// previous camera's axes) while the camera moved by `camera`: current = camera^-1 (X + moved).
Eigen::Isometry3d objectMotion(const Eigen::Isometry3d& camera, const Eigen::Vector3d& moved) {
  Eigen::Isometry3d shift = Eigen::Isometry3d::Identity();
  shift.translation() = -moved;
  return shift * camera;
}

struct Scene {
  cvo::MotionPrior prior;
  std::vector<int> truth;  // per track: 0 follows prior.motion, 1 prior.second.motion
};

// A grid of tracks over pixels [u0, u1] x [v0, v1] (previous image) at depth z, every `step` px,
// moved by `motion` (previous <- current) into the current image.
void addTracks(Scene* scene, const Eigen::Isometry3d& motion, int which, double u0, double u1,
               double v0, double v1, double step, double z,
               const std::function<bool(double, double)>& skip = nullptr) {
  cvo::MotionPrior& p = scene->prior;
  const Eigen::Isometry3d current_from_previous = motion.inverse();
  for (double v = v0; v <= v1 + 1e-9; v += step) {
    for (double u = u0; u <= u1 + 1e-9; u += step) {
      if (skip && skip(u, v)) continue;
      const Eigen::Vector3d X(z * (u - kCx) / kFocal, z * (v - kCy) / kFocal, z);
      const Eigen::Vector3d c = current_from_previous * X;
      const Eigen::Vector2d x = c.head<2>() / c.z();
      p.tracked_points.push_back(X);
      p.tracked_observations.push_back(x);
      p.tracked_pixels.emplace_back(static_cast<float>(kFocal * x.x() + kCx),
                                    static_cast<float>(kFocal * x.y() + kCy));
      scene->truth.push_back(which);
    }
  }
}

Scene emptyScene(const Eigen::Isometry3d& first, const Eigen::Isometry3d& second) {
  Scene scene;
  cvo::MotionPrior& p = scene.prior;
  p.solved = true;
  p.motion = first;
  p.second.solved = true;
  p.second.motion = second;
  p.focal_px = kFocal;
  p.inlier_px = 1.5;
  p.image_width = kWidth;
  p.image_height = kHeight;
  return scene;
}

// The object (1 m away, a dense patch in the middle: more tracks than the background) in front
// of the background (4 m, sparse, all around it): the object's tracks neighbour the
// background's. The object's motion comes first, as PnP on the majority would give it.
Scene occludingObject() {
  const Eigen::Isometry3d camera = cameraMotion();
  const Eigen::Isometry3d object = objectMotion(camera, Eigen::Vector3d(0.05, 0.0, 0.0));
  Scene scene = emptyScene(object, camera);
  const double u0 = 240, u1 = 400, v0 = 160, v1 = 320;
  addTracks(&scene, object, 0, u0, u1, v0, v1, 10.0, 1.0);
  addTracks(&scene, camera, 1, 20, 620, 20, 460, 40.0, 4.0, [&](double u, double v) {
    return u >= u0 - 5 && u <= u1 + 5 && v >= v0 - 5 && v <= v1 + 5;  // hidden behind it
  });
  return scene;
}

// The object (1 m) and the background (4 m) in separate parts of the image, more than the
// neighbour reach (7.5 % of the width) apart: only the depth ratio tells them apart. The
// background's motion comes first.
Scene separateObject() {
  const Eigen::Isometry3d camera = cameraMotion();
  const Eigen::Isometry3d object = objectMotion(camera, Eigen::Vector3d(0.05, 0.0, 0.0));
  Scene scene = emptyScene(camera, object);
  addTracks(&scene, camera, 0, 20, 300, 20, 460, 20.0, 4.0);
  addTracks(&scene, object, 1, 440, 600, 160, 320, 20.0, 1.0);
  return scene;
}

// Both at 2 m, apart in the image: `first_count` and `second_count` tracks (rows of 10).
Scene similarDepths(int first_count, int second_count) {
  const Eigen::Isometry3d camera = cameraMotion();
  const Eigen::Isometry3d object = objectMotion(camera, Eigen::Vector3d(0.05, 0.0, 0.0));
  Scene scene = emptyScene(camera, object);
  const auto rows = [](int count) { return (count + 9) / 10; };
  addTracks(&scene, camera, 0, 20, 200, 20, 20 + 20.0 * (rows(first_count) - 1), 20.0, 2.0);
  addTracks(&scene, object, 1, 400, 580, 20, 20 + 20.0 * (rows(second_count) - 1), 20.0, 2.0);
  return scene;
}

int count(const std::vector<int>& v, int value) {
  return static_cast<int>(std::count(v.begin(), v.end(), value));
}

const cvo::CvoParams kParams;  // the odometry's own ratios

cvo::MotionSplit split(const cvo::MotionPrior& prior,
                       const std::optional<Eigen::Isometry3d>& predicted = std::nullopt,
                       double depth_ratio = kParams.motion_split_depth_ratio) {
  return cvo::splitMotions(prior, depth_ratio, kParams.motion_split_ratio, predicted);
}

// Proves: each track goes to the motion that moved it; occlusion between neighbouring tracks
// names the background (the tracks behind) even when the object holds more tracks, and wins
// over a constant-velocity prediction that points at the object and over a depth ratio that
// cannot be met.
TEST(MotionSplit, OcclusionPicksTheTracksBehindEvenWhenTheObjectHoldsMore) {
  const Scene scene = occludingObject();
  const int object_tracks = count(scene.truth, 0), background_tracks = count(scene.truth, 1);
  ASSERT_GT(object_tracks, background_tracks) << "the object must hold more tracks";
  ASSERT_GT(background_tracks, 50);

  const cvo::MotionSplit s = split(scene.prior);
  EXPECT_EQ(s.owner, scene.truth) << "each track to the motion that moved it";
  EXPECT_EQ(s.first_tracks, object_tracks);
  EXPECT_EQ(s.second_tracks, background_tracks);
  EXPECT_NEAR(s.first_depth, 1.0, 1e-9);
  EXPECT_NEAR(s.second_depth, 4.0, 1e-9);
  EXPECT_EQ(s.scene, cvo::SceneMotion::kSecond) << s.why;
  EXPECT_NE(s.why.find("in front"), std::string::npos) << s.why;

  // The object's own motion as the prediction: occlusion is the stronger evidence.
  const cvo::MotionSplit vetoed = split(scene.prior, scene.prior.motion);
  EXPECT_EQ(vetoed.scene, cvo::SceneMotion::kSecond) << vetoed.why;
  // A depth ratio no median meets: occlusion alone still decides.
  const cvo::MotionSplit strict = split(scene.prior, std::nullopt, 100.0);
  EXPECT_EQ(strict.scene, cvo::SceneMotion::kSecond) << strict.why;
}

// Proves: without neighbouring tracks the farther tracks' motion is the scene's by the depth
// ratio, whichever holds more tracks, but a constant-velocity prediction clearly nearer the
// other motion leaves it undecided (the frame must not be trusted); a prediction nearer the
// farther motion, or one that is clearly nearer neither, leaves the depth ratio's word.
TEST(MotionSplit, DepthRatioAloneGivesWayToAPredictionNearTheOtherMotion) {
  const Scene scene = separateObject();
  const cvo::MotionSplit plain = split(scene.prior);
  EXPECT_EQ(plain.owner, scene.truth);
  EXPECT_EQ(plain.why.find("in front"), std::string::npos) << "no neighbours: " << plain.why;
  EXPECT_EQ(plain.scene, cvo::SceneMotion::kFirst) << plain.why;

  const cvo::MotionSplit against = split(scene.prior, scene.prior.second.motion);
  EXPECT_EQ(against.scene, cvo::SceneMotion::kUndecided) << against.why;
  EXPECT_NE(against.why.find("constant-velocity prediction"), std::string::npos) << against.why;

  const cvo::MotionSplit agreeing = split(scene.prior, scene.prior.motion);
  EXPECT_EQ(agreeing.scene, cvo::SceneMotion::kFirst) << agreeing.why;

  // Halfway between the two motions: near neither clearly, the depth ratio decides.
  Eigen::Isometry3d halfway = scene.prior.motion;
  halfway.translation() =
      0.5 * (scene.prior.motion.translation() + scene.prior.second.motion.translation());
  const cvo::MotionSplit unclear = split(scene.prior, halfway);
  EXPECT_EQ(unclear.scene, cvo::SceneMotion::kFirst) << unclear.why;
}

// Proves: a prediction at the other motion vetoes the depth ratio only where its distances to
// the two motions differ by more than twice its recent error (a handheld camera's one-step
// velocity is pixels off): as noisy as the motions are apart, it leaves the depth ratio's word.
TEST(MotionSplit, APredictionAsNoisyAsTheMotionsAreApartVetoesNothing) {
  const Scene scene = separateObject();
  const double apart =
      cvo::motionsApartPx(scene.prior, scene.prior.motion, scene.prior.second.motion);
  ASSERT_GT(apart, 4.0);
  const auto splitWithError = [&](double error_px) {
    return cvo::splitMotions(scene.prior, kParams.motion_split_depth_ratio,
                             kParams.motion_split_ratio, scene.prior.second.motion, error_px);
  };
  const cvo::MotionSplit sure = splitWithError(0.4 * apart);
  EXPECT_EQ(sure.scene, cvo::SceneMotion::kUndecided) << sure.why;
  const cvo::MotionSplit noisy = splitWithError(0.6 * apart);
  EXPECT_EQ(noisy.scene, cvo::SceneMotion::kFirst) << noisy.why;
}

// Proves: at similar depths a lopsided split picks the motion with far more tracks (first or
// second), a prediction nearer the smaller one vetoes it, and a balanced split is undecided
// unless the prediction is nearer the motion with more tracks.
TEST(MotionSplit, LopsidedSplitAtSimilarDepthsPicksTheLarger) {
  const Scene first_larger = similarDepths(100, 20);
  const cvo::MotionSplit a = split(first_larger.prior);
  EXPECT_EQ(a.owner, first_larger.truth);
  ASSERT_EQ(a.first_tracks, 100);
  ASSERT_EQ(a.second_tracks, 20);
  EXPECT_EQ(a.scene, cvo::SceneMotion::kFirst) << a.why;

  const Scene second_larger = similarDepths(20, 100);
  const cvo::MotionSplit b = split(second_larger.prior);
  EXPECT_EQ(b.scene, cvo::SceneMotion::kSecond) << b.why;
  // The prediction at the smaller one's motion: undecided.
  const cvo::MotionSplit vetoed = split(second_larger.prior, second_larger.prior.motion);
  EXPECT_EQ(vetoed.scene, cvo::SceneMotion::kUndecided) << vetoed.why;

  const Scene balanced = similarDepths(60, 50);
  const cvo::MotionSplit c = split(balanced.prior);
  EXPECT_EQ(c.scene, cvo::SceneMotion::kUndecided) << c.why;
  const cvo::MotionSplit d = split(balanced.prior, balanced.prior.motion);
  EXPECT_EQ(d.scene, cvo::SceneMotion::kFirst) << d.why;
  const cvo::MotionSplit e = split(balanced.prior, balanced.prior.second.motion);
  EXPECT_EQ(e.scene, cvo::SceneMotion::kUndecided) << e.why;
}

// Proves: a balanced split at similar depths, undecided on the tracks alone, follows the first
// motion when most of the second motion's tracks start on the object the last trusted frame
// found (MotionPrior::SecondMotion::known_object), not when fewer than half do, and not when the
// constant-velocity prediction points at the second motion.
TEST(MotionSplit, TheObjectKnownFromTheLastFrameSettlesABalancedSplit) {
  Scene balanced = similarDepths(60, 50);
  balanced.prior.second.inliers = 50;
  balanced.prior.second.known_object = 24;
  EXPECT_EQ(split(balanced.prior).scene, cvo::SceneMotion::kUndecided);
  balanced.prior.second.known_object = 40;
  const cvo::MotionSplit known = split(balanced.prior);
  EXPECT_EQ(known.scene, cvo::SceneMotion::kFirst) << known.why;
  EXPECT_NE(known.why.find("object's of the last trusted frame"), std::string::npos) << known.why;
  const cvo::MotionSplit against = split(balanced.prior, balanced.prior.second.motion);
  EXPECT_EQ(against.scene, cvo::SceneMotion::kUndecided) << against.why;
}

// The prior of a later frame whose tracks start where `scene`'s do: as inliers, the first `keep`
// tracks of each motion (truth 0 and 1), in the start frame's coordinates as the tracker gives
// them.
cvo::MotionPrior laterFrame(const Scene& scene, int keep_first, int keep_second) {
  cvo::MotionPrior later;
  int kept[2] = {0, 0};
  const int keep[2] = {keep_first, keep_second};
  for (std::size_t k = 0; k < scene.truth.size(); ++k) {
    const int side = scene.truth[k];
    if (kept[side] >= keep[side]) continue;
    ++kept[side];
    later.points.push_back(scene.prior.tracked_points[k]);
  }
  return later;
}

// Proves: after a balanced split left undecided, a later frame whose inliers keep one side's
// tracks and hardly any of the other's follows that side, whose motion is the scene's as likely
// as the object's: it is named, with each side's count. Both sides kept alike (the motions agree
// now), too few kept, or tracks that start elsewhere (another start frame) say nothing.
TEST(MotionSplit, AFrameKeepingOneSideOfAnUndecidedSplitIsNamed) {
  const Scene balanced = similarDepths(60, 50);
  const cvo::MotionSplit s = split(balanced.prior);
  ASSERT_EQ(s.scene, cvo::SceneMotion::kUndecided) << s.why;
  const auto& points = balanced.prior.tracked_points;
  const int min_tracks = kParams.min_prior_inliers;
  const auto judge = [&](const cvo::MotionPrior& later) {
    return cvo::oneSideOfUndecidedSplit(points, s.owner, later, min_tracks, 0.25);
  };

  const std::string second_side = judge(laterFrame(balanced, 2, 45));
  EXPECT_NE(second_side.find("one side"), std::string::npos) << second_side;
  EXPECT_NE(second_side.find("45 of that side's 50 tracks, 2 of the other's 60"), std::string::npos)
      << second_side;
  EXPECT_FALSE(judge(laterFrame(balanced, 55, 3)).empty());
  // Both sides at similar rates, or the other side at a quarter of the first's rate: alike.
  EXPECT_EQ(judge(laterFrame(balanced, 40, 30)), "");
  EXPECT_EQ(judge(laterFrame(balanced, 60, 13)), "");
  // One side, but fewer than min_prior_inliers of it.
  EXPECT_EQ(judge(laterFrame(balanced, 0, min_tracks - 1)), "");
  // Tracks from another start frame's corners match none of the split's.
  cvo::MotionPrior elsewhere = laterFrame(balanced, 0, 45);
  for (Eigen::Vector3d& p : elsewhere.points)
    p.x() += 0.01;
  EXPECT_EQ(judge(elsewhere), "");
}

// Proves: occlusion that contradicts the depths by far leaves the split undecided. A truck
// (8 m, most tracks) driving along, the road just below it (6 m, the camera's motion: nearer, so
// "in front" of the truck's tracks it neighbours) and the background far away (40 m, beyond the
// neighbour reach): the pairs make the truck's tracks the ones behind, though the camera's
// motion's tracks are five times as far by median depth.
TEST(MotionSplit, OcclusionThatContradictsTheDepthsIsUndecided) {
  const Eigen::Isometry3d camera = cameraMotion();
  const Eigen::Isometry3d truck = objectMotion(camera, Eigen::Vector3d(0.5, 0.0, 0.0));
  Scene scene = emptyScene(truck, camera);
  addTracks(&scene, truck, 0, 240, 400, 160, 320, 10.0, 8.0);
  addTracks(&scene, camera, 1, 240, 400, 330, 370, 20.0, 6.0);  // the road below it
  addTracks(&scene, camera, 1, 20, 620, 20, 100, 20.0, 40.0);   // far away, above
  const cvo::MotionSplit s = split(scene.prior);
  ASSERT_EQ(s.first_tracks, count(scene.truth, 0));
  ASSERT_GT(s.second_depth, 2.0 * s.first_depth) << s.why;
  EXPECT_EQ(s.scene, cvo::SceneMotion::kUndecided) << s.why;
  EXPECT_NE(s.why.find("second motion's track in front"), std::string::npos)
      << "the road's tracks must be in front of the truck's: " << s.why;
  EXPECT_NE(s.why.find("contradicts itself"), std::string::npos) << s.why;
}

// Proves: sceneFirst puts the scene's motion first (swapping when the scene follows the second)
// and gives each motion its own tracks only: the inlier set is the scene's tracks, the second
// motion's pixels the object's, no track in both.
TEST(MotionSplit, SceneFirstSwapsMotionsAndGivesExclusiveInlierSets) {
  const Scene scene = occludingObject();
  const cvo::MotionSplit s = split(scene.prior);
  ASSERT_EQ(s.scene, cvo::SceneMotion::kSecond) << s.why;
  const cvo::MotionPrior out = cvo::sceneFirst(scene.prior, s);
  EXPECT_TRUE(out.motion.isApprox(scene.prior.second.motion, 1e-12)) << "swapped";
  EXPECT_TRUE(out.second.motion.isApprox(scene.prior.motion, 1e-12));
  ASSERT_EQ(out.inliers, s.second_tracks);
  ASSERT_EQ(static_cast<int>(out.points.size()), s.second_tracks);
  ASSERT_EQ(out.inlier_pixels.size(), out.points.size());
  ASSERT_EQ(out.observations.size(), out.points.size());
  EXPECT_EQ(out.second.inliers, s.first_tracks);
  ASSERT_EQ(static_cast<int>(out.second.pixels.size()), s.first_tracks);
  // Among the tracks the object's motion leaves: the object's own count against nothing.
  EXPECT_NEAR(out.inlier_ratio,
              static_cast<double>(s.second_tracks) /
                  static_cast<double>(scene.prior.tracked_points.size() - s.first_tracks),
              1e-12);
  EXPECT_GT(out.inlier_ratio,
            static_cast<double>(s.second_tracks) / scene.prior.tracked_points.size());
  // The background's points (4 m) are the inliers, the object's pixels the second's.
  for (const Eigen::Vector3d& X : out.points)
    EXPECT_NEAR(X.z(), 4.0, 1e-9);
  std::set<std::pair<float, float>> background, object;
  for (std::size_t k = 0; k < scene.truth.size(); ++k) {
    const auto px =
        std::make_pair(scene.prior.tracked_pixels[k].x(), scene.prior.tracked_pixels[k].y());
    (scene.truth[k] == 1 ? background : object).insert(px);
  }
  std::set<std::pair<float, float>> inliers;
  for (const auto& p : out.inlier_pixels) {
    inliers.insert({p.x(), p.y()});
    EXPECT_EQ(background.count({p.x(), p.y()}), 1u) << "an inlier pixel not the background's";
  }
  for (const auto& p : out.second.pixels) {
    EXPECT_EQ(object.count({p.x(), p.y()}), 1u) << "a second-motion pixel not the object's";
    EXPECT_EQ(inliers.count({p.x(), p.y()}), 0u) << "a pixel in both sets";
  }
  // The scene's inliers agree with the scene's motion, not the object's.
  EXPECT_DOUBLE_EQ(cvo::trackAgreement(out, out.motion, 0.5).fraction, 1.0);
  EXPECT_LT(cvo::trackAgreement(out, out.second.motion, 1.5).fraction, 0.05);

  // The scene first already: nothing swapped, the first motion's tracks the inliers.
  const Scene separate = separateObject();
  const cvo::MotionSplit t = split(separate.prior);
  ASSERT_EQ(t.scene, cvo::SceneMotion::kFirst) << t.why;
  const cvo::MotionPrior kept = cvo::sceneFirst(separate.prior, t);
  EXPECT_TRUE(kept.motion.isApprox(separate.prior.motion, 1e-12));
  EXPECT_TRUE(kept.second.motion.isApprox(separate.prior.second.motion, 1e-12));
  EXPECT_EQ(kept.inliers, t.first_tracks);
  EXPECT_EQ(kept.second.inliers, t.second_tracks);
}

// Proves: motionsApartPx is 0 for equal motions, symmetric, and grows with the motions'
// difference (about in proportion for small differences).
TEST(MotionSplit, MotionsApartGrowsWithTheirDifference) {
  const Scene scene = separateObject();
  const Eigen::Isometry3d camera = cameraMotion();
  EXPECT_EQ(cvo::motionsApartPx(scene.prior, camera, camera), 0.0);
  double last = 0.0;
  std::vector<double> apart;
  for (const double cm : {0.5, 1.0, 2.0, 4.0, 8.0}) {
    const Eigen::Isometry3d other = objectMotion(camera, Eigen::Vector3d(0.01 * cm, 0.0, 0.0));
    const double d = cvo::motionsApartPx(scene.prior, camera, other);
    EXPECT_GT(d, last) << cm << " cm";
    EXPECT_NEAR(cvo::motionsApartPx(scene.prior, other, camera), d, 1e-6 * d) << "symmetric";
    apart.push_back(d);
    last = d;
  }
  EXPECT_NEAR(apart[1] / apart[0], 2.0, 0.1);
  EXPECT_NEAR(apart[2] / apart[1], 2.0, 0.1);
  // A turn counts too: 1 degree moves every point at least focal * 1 deg (in radians) px, more
  // off the axis (by 1 + x^2, x <= 0.6 here).
  Eigen::Isometry3d turned = camera;
  turned.linear() = camera.linear() *
                    Eigen::AngleAxisd(M_PI / 180.0, Eigen::Vector3d::UnitY()).toRotationMatrix();
  const double turn = cvo::motionsApartPx(scene.prior, camera, turned);
  EXPECT_GT(turn, 0.99 * kFocal * M_PI / 180.0);
  EXPECT_LT(turn, 1.4 * kFocal * M_PI / 180.0);
}

}  // namespace

// The object's patch (1 m, its motion first) with the background around it (4 m) whose tracks
// follow no motion the prior has (a step too large for them to form one): each is moved
// `miss_px` off where the camera's motion puts it, in alternating directions.
Scene objectBeforeBrokenBackground(double miss_px) {
  Scene scene = occludingObject();
  scene.prior.second.solved = false;
  for (std::size_t k = 0; k < scene.truth.size(); ++k) {
    if (scene.truth[k] != 1) continue;
    const double sign = k % 2 == 0 ? 1.0 : -1.0;
    scene.prior.tracked_observations[k] += Eigen::Vector2d(sign, -sign) * (miss_px / kFocal);
  }
  return scene;
}

// Proves: tracks that follow no motion, far behind the one the scene is taken to follow, say
// the scene may be them (the reason names both depths); tracks the motion explains at any depth,
// or unexplained ones no farther than its own, or fewer than min_tracks, say nothing; with the
// scene taken to be the second motion, the first's tracks are not unexplained.
TEST(MotionSplit, TracksFollowingNoMotionFarBehindTheSceneMotionDoubtIt) {
  const int min_tracks = kParams.min_prior_inliers;
  const Scene broken = objectBeforeBrokenBackground(8.0);
  ASSERT_GE(count(broken.truth, 1), min_tracks);
  const std::string why = cvo::sceneBehindItsMotion(broken.prior, false, min_tracks);
  EXPECT_NE(why.find("follow no motion lie behind"), std::string::npos) << why;
  EXPECT_NE(why.find("4 and 1 m"), std::string::npos) << why;

  // A still scene, near and far: its one motion explains every track.
  Scene still = emptyScene(cameraMotion(), cameraMotion());
  still.prior.second.solved = false;
  addTracks(&still, cameraMotion(), 0, 240, 400, 160, 320, 10.0, 1.0);
  addTracks(&still, cameraMotion(), 0, 20, 620, 20, 460, 40.0, 4.0);
  EXPECT_EQ(cvo::sceneBehindItsMotion(still.prior, false, min_tracks), "");
  // Background tracks off their motion by less than the inlier bound follow it.
  Scene close = objectBeforeBrokenBackground(0.5 * broken.prior.inlier_px);
  close.prior.second.solved = true;  // the camera's motion, as occludingObject gives it
  EXPECT_EQ(cvo::sceneBehindItsMotion(close.prior, true, min_tracks), "");
  close.prior.second.solved = false;
  EXPECT_NE(cvo::sceneBehindItsMotion(close.prior, false, min_tracks), "");

  // Fewer unexplained tracks than min_tracks: no evidence.
  EXPECT_EQ(cvo::sceneBehindItsMotion(broken.prior, false, count(broken.truth, 1) + 1), "");

  // The unexplained tracks nearer than the motion's: a near object that formed no motion.
  Scene swapped = broken;
  for (std::size_t k = 0; k < swapped.truth.size(); ++k) {
    const double scale = swapped.truth[k] == 1 ? 0.2 : 4.0;  // background 0.8 m, object 4 m
    swapped.prior.tracked_points[k] *= scale;
  }
  swapped.prior.motion = Eigen::Isometry3d::Identity();  // explains none of the rescaled ones
  swapped.prior.second.solved = false;
  EXPECT_EQ(cvo::sceneBehindItsMotion(swapped.prior, false, min_tracks), "");

  // The scene taken to be the second motion (the background's, explained) and the object's
  // tracks the first's: no track is left unexplained.
  const Scene two = occludingObject();
  EXPECT_EQ(cvo::sceneBehindItsMotion(two.prior, true, min_tracks), "");
  EXPECT_EQ(cvo::sceneBehindItsMotion(two.prior, false, min_tracks), "");
}

namespace {

// A third motion for the scene's tracks labelled 2.
void withThird(Scene* scene, const Eigen::Isometry3d& third) {
  scene->prior.third.solved = true;
  scene->prior.third.motion = third;
}

// Each motion's inlier count: its tracks (labels 0, 1 and 2).
void countThreeMotions(Scene* scene) {
  scene->prior.inliers = count(scene->truth, 0);
  scene->prior.second.inliers = count(scene->truth, 1);
  scene->prior.third.inliers = count(scene->truth, 2);
}

// Two objects (1 m, a dense patch left of centre: most tracks; 1.5 m, right of centre) in front
// of the background (4 m, sparse, all around them). PnP's order: the nearer object, the other,
// then the background, the fewest.
Scene twoObjects() {
  const Eigen::Isometry3d camera = cameraMotion();
  const Eigen::Isometry3d near = objectMotion(camera, Eigen::Vector3d(0.05, 0.0, 0.0));
  const Eigen::Isometry3d far = objectMotion(camera, Eigen::Vector3d(-0.04, 0.02, 0.0));
  Scene scene = emptyScene(near, far);
  withThird(&scene, camera);
  const auto inside = [](double u, double v) {
    return v >= 155 && v <= 325 && ((u >= 115 && u <= 285) || (u >= 375 && u <= 525));
  };
  addTracks(&scene, near, 0, 120, 280, 160, 320, 10.0, 1.0);
  addTracks(&scene, far, 1, 380, 520, 160, 320, 15.0, 1.5);
  addTracks(&scene, camera, 2, 20, 620, 20, 460, 60.0, 4.0, inside);
  countThreeMotions(&scene);
  return scene;
}

// splitThreeMotions on a copy of `prior`, which `*scene_first` receives as the split leaves it.
cvo::MotionSplit splitThree(const cvo::MotionPrior& prior, cvo::MotionPrior* scene_first) {
  *scene_first = prior;
  return cvo::splitThreeMotions(scene_first, kParams.motion_split_depth_ratio,
                                kParams.motion_split_ratio, std::nullopt, 0.0);
}

}  // namespace

// Proves: with three motions, the scene is the one the two-motion rules pick against each of the
// others, here the third (the background, behind both objects and the fewest tracks); the prior
// comes back with it first, its own tracks the scene's and both objects' the other motion's.
TEST(MotionSplit, OfThreeMotionsTheSceneIsTheOneThatWinsAgainstEach) {
  const Scene scene = twoObjects();
  ASSERT_LT(scene.prior.third.inliers, scene.prior.second.inliers);
  cvo::MotionPrior scene_first;
  const cvo::MotionSplit s = splitThree(scene.prior, &scene_first);
  ASSERT_EQ(s.scene, cvo::SceneMotion::kFirst) << s.why;
  EXPECT_NE(s.why.find("the third, which wins against each"), std::string::npos) << s.why;
  EXPECT_TRUE(scene_first.motion.isApprox(cameraMotion(), 1e-12));
  EXPECT_TRUE(scene_first.second.motion.isApprox(scene.prior.motion, 1e-12));
  EXPECT_TRUE(scene_first.third.motion.isApprox(scene.prior.second.motion, 1e-12));
  ASSERT_EQ(s.owner.size(), scene.truth.size());
  for (std::size_t k = 0; k < s.owner.size(); ++k)
    EXPECT_EQ(s.owner[k], scene.truth[k] == 2 ? 0 : 1) << "track " << k;
  const cvo::MotionPrior out = cvo::sceneFirst(scene_first, s);
  EXPECT_EQ(out.inliers, count(scene.truth, 2));
  EXPECT_EQ(out.second.inliers, count(scene.truth, 0) + count(scene.truth, 1));
  for (const Eigen::Vector3d& X : out.points)
    EXPECT_NEAR(X.z(), 4.0, 1e-9);

  // The background's motion first already: the prior comes back as it was.
  Scene ordered = scene;
  ordered.prior.motion = cameraMotion();
  ordered.prior.third.motion = scene.prior.motion;
  cvo::MotionPrior kept;
  const cvo::MotionSplit t = splitThree(ordered.prior, &kept);
  ASSERT_EQ(t.scene, cvo::SceneMotion::kFirst) << t.why;
  EXPECT_NE(t.why.find("the first, which wins"), std::string::npos) << t.why;
  EXPECT_TRUE(kept.motion.isApprox(cameraMotion(), 1e-12));
  EXPECT_TRUE(kept.third.motion.isApprox(scene.prior.motion, 1e-12));
}

// Proves: three motions at similar depths, apart in the image, with as many tracks each: no pair
// is decided, so none wins against each and the split is undecided with every pair's reason; the
// prior keeps its order.
TEST(MotionSplit, ThreeMotionsNoneOfWhichWinsAgainstEachAreUndecided) {
  const Eigen::Isometry3d camera = cameraMotion();
  const Eigen::Isometry3d a = objectMotion(camera, Eigen::Vector3d(0.05, 0.0, 0.0));
  const Eigen::Isometry3d b = objectMotion(camera, Eigen::Vector3d(-0.05, 0.0, 0.0));
  Scene scene = emptyScene(camera, a);
  withThird(&scene, b);
  addTracks(&scene, camera, 0, 20, 120, 20, 120, 20.0, 2.0);
  addTracks(&scene, a, 1, 260, 360, 20, 120, 20.0, 2.0);
  addTracks(&scene, b, 2, 500, 600, 20, 120, 20.0, 2.0);
  countThreeMotions(&scene);
  cvo::MotionPrior after;
  const cvo::MotionSplit s = splitThree(scene.prior, &after);
  EXPECT_EQ(s.scene, cvo::SceneMotion::kUndecided) << s.why;
  EXPECT_NE(s.why.find("none wins against each"), std::string::npos) << s.why;
  for (const char* pair : {"first against second", "first against third", "second against third"})
    EXPECT_NE(s.why.find(pair), std::string::npos) << pair << ": " << s.why;
  EXPECT_TRUE(after.motion.matrix() == scene.prior.motion.matrix());
  EXPECT_TRUE(after.second.motion.matrix() == scene.prior.second.motion.matrix());
  EXPECT_TRUE(after.third.motion.matrix() == scene.prior.third.motion.matrix());
  EXPECT_EQ(after.inliers, scene.prior.inliers);
  EXPECT_EQ(after.second.inliers, scene.prior.second.inliers);
  EXPECT_EQ(after.third.inliers, scene.prior.third.inliers);
}
