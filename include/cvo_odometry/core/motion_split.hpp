// Two motions among a frame's feature tracks (MotionPrior::second: an object moving through the
// view), and which of them the scene, the static world, follows. The tracks alone cannot say:
// a textured object can hold more of them than the background. What can: an object moving
// through the view is in front of what it hides, so the scene is the motion of the farther
// tracks; and the camera keeps its velocity, so the scene's motion is the one nearer the
// constant-velocity prediction. When that evidence is missing or contradicts itself the split is
// undecided, and the frame must not be trusted.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "cvo_odometry/core/motion_prior.hpp"

namespace cvo {

enum class SceneMotion { kFirst, kSecond, kUndecided };

struct MotionSplit {
  // Per tracked point (MotionPrior::tracked_points): 0 the first motion explains it better, 1
  // the second, -1 neither within the prior's inlier_px.
  std::vector<int> owner;
  int first_tracks = 0, second_tracks = 0;
  double first_depth = 0.0, second_depth = 0.0;  // median depth of each one's tracks (m)
  SceneMotion scene = SceneMotion::kUndecided;
  std::string why;  // how it was decided, or why it could not be
};

// Mean image distance (px) between where motions a and b (previous <- current) put the prior's
// tracked points: how far apart two motions are where it matters, on any scale.
double motionsApartPx(const MotionPrior& prior, const Eigen::Isometry3d& a,
                      const Eigen::Isometry3d& b);

// Splits the prior's tracks between its two motions and decides which the scene follows: the
// motion of the tracks behind, where the two motions' tracks are image neighbours and one's
// are in front in most pairs (occlusion; undecided when the tracks behind are by median depth
// half as far as the others or less: the evidence contradicts itself); else the farther
// tracks' when their median depth is at least `depth_ratio` times the other's and the
// constant-velocity prediction `predicted` (previous <- current) is not clearly nearer the
// other; else the motion with more tracks when the other has fewer than `lopsided_ratio` times
// as many, or when it is also the one nearer the prediction; else undecided. The prediction
// speaks only where its distances to the two motions differ by more than twice
// `prediction_error_px` (its recent error, px on the tracks; 0: unknown). Requires
// prior.second.solved.
MotionSplit splitMotions(const MotionPrior& prior, double depth_ratio, double lopsided_ratio,
                         const std::optional<Eigen::Isometry3d>& predicted,
                         double prediction_error_px = 0.0);

// The prior's third motion (MotionPrior::third) is one of its own: `min_tracks` tracks, moving
// them at least 1.5 x `moving_min_px` from where each of the other two motions puts them. A
// nearer one is read as that motion's own spread: a scene's near and far tracks under an RGB-D
// camera's depth lag came 2.5-6 px apart beside an object's motion (bench/dynamic_table.sh's
// cases, strides 1-3).
bool thirdMotionSeparate(const MotionPrior& prior, int min_tracks, double moving_min_px);

// Three motions (the prior's third solved: two objects, or one whose parts move apart): the scene
// follows the motion that splitMotions, with the same arguments, picks against each of the other
// two. Then the split's scene is kFirst, its owner 1 for the tracks either other motion explains
// better, and `*prior` reordered in place: that motion first, the others after it in their order.
// Else undecided, with each pair's reasons, and `*prior` as it was.
MotionSplit splitThreeMotions(MotionPrior* prior, double depth_ratio, double lopsided_ratio,
                              const std::optional<Eigen::Isometry3d>& predicted,
                              double prediction_error_px);

// Why the scene may not follow the motion it is taken to (the prior's first, or its second
// where `scene_is_second`): at least `min_tracks` tracks, and a fifth as many as that motion's
// own, that none of the prior's motions explains lie, by median depth, at least 1.5 times as
// far as the motion's own tracks. An object near the camera then holds the motion, and the
// scene behind it, its tracks too broken up by the step to form one, none. Empty when the
// evidence does not say so.
std::string sceneBehindItsMotion(const MotionPrior& prior, bool scene_is_second, int min_tracks);

// Why a later frame's tracks cannot place it where an earlier frame's split of motions was left
// undecided: `split_points` are that frame's tracked points (the start frame's corners, from which
// `now`'s tracks start too) and `owner` their motion (MotionSplit::owner). When `now`'s inliers
// keep at least `min_tracks` of one side's tracks and, of every other side, less than
// `other_side_share` times that side's rate, they follow one side, whose motion is the scene's as
// likely as the object's. Empty when the sides move alike (both kept) or too few are kept.
std::string oneSideOfUndecidedSplit(
    const std::vector<Eigen::Vector3d, Eigen::aligned_allocator<Eigen::Vector3d>>& split_points,
    const std::vector<int>& owner, const MotionPrior& now, int min_tracks, double other_side_share);

// The prior as the scene sees it: the scene's motion first, its own tracks alone as the inliers
// (those the other motion explains better left out), the other motion second with its own.
MotionPrior sceneFirst(const MotionPrior& prior, const MotionSplit& split);

}  // namespace cvo
