#include "cvo_odometry/core/motion_split.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>
#include <utility>
#include <vector>

#include "cvo_odometry/core/robust_scale.hpp"

namespace cvo {

namespace {

// A motion is clearly the nearer to a prediction when at most this fraction as far from it as
// the other.
constexpr double kClearlyNearer = 0.5;
// ... and its distances to the two differ by more than this many of its recent errors: a
// handheld camera's one-step velocity is several pixels off (TUM fr1_xyz: a median 3.5 px),
// and a board moving across beside the scene's motion is as near.
constexpr double kPredictionErrors = 2.0;
// Tracks of the two motions within this share of the image's width are neighbours; one is in
// front of the other when at least kFrontMargin nearer; the motion whose tracks are in front in
// kFrontShare of at least kMinNeighbourPairs such pairs hides the other.
constexpr double kNeighbourShare = 0.075;
constexpr double kFrontMargin = 0.05;
constexpr double kFrontShare = 0.75;
constexpr int kMinNeighbourPairs = 10;
// Occlusion and depth both take the object to be in front: tracks behind at the boundary whose
// median depth is this many times nearer than the other motion's contradict that. (KITTI with a
// truck driving along, stride 2: the road in front of the truck is its neighbour below, nearer,
// and made the truck's tracks the ones behind.)
constexpr double kContradictingDepthRatio = 2.0;
// A second motion at least this share of whose tracks start on the object of the frame they
// start from is that object's.
constexpr double kKnownObjectShare = 0.5;

// Reprojection error (px) of the prior's tracked point k under motion (previous <- current)
// given as current <- previous.
double errorPx(const MotionPrior& prior, std::size_t k,
               const Eigen::Isometry3d& current_from_previous) {
  const Eigen::Vector3d p = current_from_previous * prior.tracked_points[k];
  if (!(p.z() > 1e-6)) return INFINITY;
  return prior.focal_px * (p.head<2>() / p.z() - prior.tracked_observations[k]).norm();
}

}  // namespace

double motionsApartPx(const MotionPrior& prior, const Eigen::Isometry3d& a,
                      const Eigen::Isometry3d& b) {
  const Eigen::Isometry3d a_inv = a.inverse(), b_inv = b.inverse();
  double sum = 0.0;
  std::size_t n = 0;
  for (const Eigen::Vector3d& X : prior.tracked_points) {
    const Eigen::Vector3d pa = a_inv * X, pb = b_inv * X;
    if (!(pa.z() > 1e-6) || !(pb.z() > 1e-6)) continue;
    sum += prior.focal_px * (pa.head<2>() / pa.z() - pb.head<2>() / pb.z()).norm();
    ++n;
  }
  return n > 0 ? sum / static_cast<double>(n) : 0.0;
}

MotionSplit splitMotions(const MotionPrior& prior, double depth_ratio, double lopsided_ratio,
                         const std::optional<Eigen::Isometry3d>& predicted,
                         double prediction_error_px) {
  MotionSplit split;
  const Eigen::Isometry3d first = prior.motion.inverse(), second = prior.second.motion.inverse();
  std::vector<double> first_depths, second_depths;
  split.owner.assign(prior.tracked_points.size(), -1);
  for (std::size_t k = 0; k < prior.tracked_points.size(); ++k) {
    const double e1 = errorPx(prior, k, first), e2 = errorPx(prior, k, second);
    if (std::min(e1, e2) > prior.inlier_px) continue;
    split.owner[k] = e1 <= e2 ? 0 : 1;
    (e1 <= e2 ? first_depths : second_depths).push_back(prior.tracked_points[k].z());
  }
  split.first_tracks = static_cast<int>(first_depths.size());
  split.second_tracks = static_cast<int>(second_depths.size());
  std::ostringstream why;
  why.precision(3);
  why << "tracks split between two motions (" << split.first_tracks << " and "
      << split.second_tracks << " tracks";
  if (first_depths.empty() || second_depths.empty()) {
    // One explains every track the other does: no split after all.
    split.scene = first_depths.empty() ? SceneMotion::kSecond : SceneMotion::kFirst;
    split.why = "one motion explains every track";
    return split;
  }
  split.first_depth = medianInPlace(first_depths);
  split.second_depth = medianInPlace(second_depths);
  why << ", median depths " << split.first_depth << " and " << split.second_depth << " m)";
  // Where the two motions' tracks are neighbours in the image, the object's are in front.
  const double reach = kNeighbourShare * prior.image_width;
  int first_in_front = 0, second_in_front = 0;
  for (std::size_t i = 0; i < split.owner.size(); ++i) {
    if (split.owner[i] != 0) continue;
    for (std::size_t j = 0; j < split.owner.size(); ++j) {
      if (split.owner[j] != 1) continue;
      if ((prior.tracked_pixels[i] - prior.tracked_pixels[j]).norm() > reach) continue;
      const double zi = prior.tracked_points[i].z(), zj = prior.tracked_points[j].z();
      if (zi < (1.0 - kFrontMargin) * zj) ++first_in_front;
      if (zj < (1.0 - kFrontMargin) * zi) ++second_in_front;
    }
  }
  const int pairs = first_in_front + second_in_front;
  std::optional<SceneMotion> behind;  // the motion of what the other hides
  if (pairs >= kMinNeighbourPairs) {
    if (first_in_front >= kFrontShare * pairs) behind = SceneMotion::kSecond;
    if (second_in_front >= kFrontShare * pairs) behind = SceneMotion::kFirst;
    if (behind) {
      why << "; " << std::max(first_in_front, second_in_front) << " of " << pairs
          << " neighbouring pairs have the " << (behind == SceneMotion::kFirst ? "second" : "first")
          << " motion's track in front";
    }
  }
  if (behind) {
    const double behind_depth =
        *behind == SceneMotion::kFirst ? split.first_depth : split.second_depth;
    const double front_depth =
        *behind == SceneMotion::kFirst ? split.second_depth : split.first_depth;
    if (front_depth >= kContradictingDepthRatio * behind_depth) {
      why << ", yet those tracks are " << front_depth / behind_depth
          << " times as far by median depth: the evidence contradicts itself";
      split.why = why.str();
      return split;
    }
  }
  const SceneMotion farther = behind                                    ? *behind
                              : split.first_depth >= split.second_depth ? SceneMotion::kFirst
                                                                        : SceneMotion::kSecond;
  const double ratio = behind ? INFINITY
                              : std::max(split.first_depth, split.second_depth) /
                                    std::max(std::min(split.first_depth, split.second_depth), 1e-9);
  // The prediction speaks only when it is clearly nearer one motion: the camera's velocity from
  // one step is a few pixels off, and two slow motions can be as near each other.
  std::optional<SceneMotion> nearer_prediction;
  if (predicted) {
    const double to_first = motionsApartPx(prior, *predicted, prior.motion);
    const double to_second = motionsApartPx(prior, *predicted, prior.second.motion);
    const bool told = std::abs(to_first - to_second) > kPredictionErrors * prediction_error_px;
    if (told && to_first <= kClearlyNearer * to_second) nearer_prediction = SceneMotion::kFirst;
    if (told && to_second <= kClearlyNearer * to_first) nearer_prediction = SceneMotion::kSecond;
  }
  const auto name = [](SceneMotion m) { return m == SceneMotion::kFirst ? "first" : "second"; };
  if (ratio >= depth_ratio) {
    // Occlusion between neighbours is the stronger evidence: a one-step velocity is a few pixels
    // off, as far as two slow motions are apart. Only the global depth ratio gives way to it.
    if (!behind && nearer_prediction && *nearer_prediction != farther) {
      why << ": the " << (behind ? "tracks behind" : "farther tracks") << " follow the "
          << name(farther) << " motion, the constant-velocity prediction the "
          << name(*nearer_prediction);
      split.why = why.str();
      return split;
    }
    split.scene = farther;
    why << ": the scene follows the " << (behind ? "tracks behind" : "farther tracks") << ", the "
        << name(farther) << " motion";
    split.why = why.str();
    return split;
  }
  const SceneMotion more =
      split.first_tracks >= split.second_tracks ? SceneMotion::kFirst : SceneMotion::kSecond;
  const double share = static_cast<double>(std::min(split.first_tracks, split.second_tracks)) /
                       std::max(split.first_tracks, split.second_tracks);
  if (share < lopsided_ratio && (!nearer_prediction || *nearer_prediction == more)) {
    split.scene = more;
    why << ": at similar depths, the scene follows the motion with far more tracks, the "
        << name(more);
    split.why = why.str();
    return split;
  }
  if (nearer_prediction && *nearer_prediction == more) {
    split.scene = more;
    why << ": at similar depths, the scene follows the motion with more tracks and nearer the "
           "constant-velocity prediction, the "
        << name(more);
    split.why = why.str();
    return split;
  }
  if (prior.second.known_object > 0 &&
      prior.second.known_object >= kKnownObjectShare * prior.second.inliers &&
      nearer_prediction != SceneMotion::kSecond) {
    // The tracks alone cannot tell, but the last trusted frame did: most of the second motion's
    // tracks start on the object found there (unless the prediction points at its motion).
    split.scene = SceneMotion::kFirst;
    why << ": at similar depths, the second motion's tracks are the object's of the last trusted "
           "frame ("
        << prior.second.known_object << " of " << prior.second.inliers
        << "): the scene follows the first motion";
    split.why = why.str();
    return split;
  }
  why << ": at similar depths (ratio " << ratio << " < " << depth_ratio << ")"
      << (nearer_prediction ? ", and the motion with more tracks is not the one nearer the "
                              "constant-velocity prediction"
                            : ", and the constant-velocity prediction does not tell them apart");
  split.why = why.str();
  return split;
}

MotionSplit splitThreeMotions(MotionPrior* prior, double depth_ratio, double lopsided_ratio,
                              const std::optional<Eigen::Isometry3d>& predicted,
                              double prediction_error_px) {
  const std::array<Eigen::Isometry3d, 3> motions{prior->motion, prior->second.motion,
                                                 prior->third.motion};
  const std::array<int, 3> tracks{prior->inliers, prior->second.inliers, prior->third.inliers};
  const std::array<const char*, 3> names{"first", "second", "third"};
  // One copy of the prior, given motions a and b as its first and second for each pair (the
  // tracker's own second keeps what it knows of its tracks).
  MotionPrior pair = *prior;
  const auto setPair = [&](MotionPrior* out, int a, int b) {
    out->motion = motions[a];
    if (a == 0 && b == 1) {
      out->second = prior->second;
      return;
    }
    out->second = MotionPrior::SecondMotion{};
    out->second.solved = true;
    out->second.motion = motions[b];
    out->second.inliers = tracks[b];
  };
  const std::array<std::pair<int, int>, 3> pairs{{{0, 1}, {0, 2}, {1, 2}}};
  std::array<MotionSplit, 3> splits;
  std::array<int, 3> wins{0, 0, 0};
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    const auto [a, b] = pairs[i];
    setPair(&pair, a, b);
    splits[i] = splitMotions(pair, depth_ratio, lopsided_ratio, predicted, prediction_error_px);
    if (splits[i].scene == SceneMotion::kFirst) ++wins[a];
    if (splits[i].scene == SceneMotion::kSecond) ++wins[b];
  }
  std::ostringstream why;
  why << "tracks split between three motions (" << tracks[0] << ", " << tracks[1] << " and "
      << tracks[2] << " tracks)";
  MotionSplit split;
  const auto won = std::find(wins.begin(), wins.end(), 2);
  if (won == wins.end()) {
    why << ": none wins against each of the others";
    for (std::size_t i = 0; i < pairs.size(); ++i) {
      why << "; " << names[pairs[i].first] << " against " << names[pairs[i].second] << ": "
          << splits[i].why;
    }
    split.why = why.str();
    return split;
  }
  const int scene = static_cast<int>(won - wins.begin());
  // A track is the scene's where it explains it better than one other motion and no other
  // motion explains it better.
  split.owner.assign(prior->tracked_points.size(), -1);
  std::vector<double> scene_depths, other_depths;
  for (std::size_t k = 0; k < split.owner.size(); ++k) {
    for (std::size_t i = 0; i < pairs.size(); ++i) {
      const auto [a, b] = pairs[i];
      if (a != scene && b != scene) continue;
      const int mine = a == scene ? 0 : 1;
      const int owner = splits[i].owner[k];
      if (owner == 1 - mine) split.owner[k] = 1;
      if (owner == mine && split.owner[k] < 0) split.owner[k] = 0;
    }
    if (split.owner[k] >= 0) {
      (split.owner[k] == 0 ? scene_depths : other_depths).push_back(prior->tracked_points[k].z());
    }
  }
  split.first_tracks = static_cast<int>(scene_depths.size());
  split.second_tracks = static_cast<int>(other_depths.size());
  if (!scene_depths.empty()) split.first_depth = medianInPlace(scene_depths);
  if (!other_depths.empty()) split.second_depth = medianInPlace(other_depths);
  split.scene = SceneMotion::kFirst;
  why << ": the scene follows the " << names[scene] << ", which wins against each of the others";
  split.why = why.str();
  if (scene == 0) return split;
  // The others in their order: the first goes second, the remaining one third.
  const int last = scene == 1 ? 2 : 1;
  setPair(prior, scene, 0);
  prior->second.pixels = prior->inlier_pixels;
  prior->third.motion = motions[last];
  prior->third.inliers = tracks[last];
  return split;
}

bool thirdMotionSeparate(const MotionPrior& prior, int min_tracks, double moving_min_px) {
  // At 1x moving_min_px more frames of one object were lost to the scene's spread; at 2x two
  // objects passing each other gave silent failures.
  constexpr double kApartFactor = 1.5;
  const double apart = kApartFactor * moving_min_px;
  return prior.third.solved && prior.third.inliers >= min_tracks &&
         motionsApartPx(prior, prior.motion, prior.third.motion) >= apart &&
         motionsApartPx(prior, prior.second.motion, prior.third.motion) >= apart;
}

std::string oneSideOfUndecidedSplit(
    const std::vector<Eigen::Vector3d, Eigen::aligned_allocator<Eigen::Vector3d>>& split_points,
    const std::vector<int>& owner, const MotionPrior& now, int min_tracks,
    double other_side_share) {
  const std::size_t n = std::min(split_points.size(), owner.size());
  int sides = 0;
  for (std::size_t k = 0; k < n; ++k)
    sides = std::max(sides, owner[k] + 1);
  if (sides < 2) return "";
  // Of each side's tracks, those among the inliers now: the same start points, since the tracks
  // start from the same frame's corners.
  std::vector<int> total(static_cast<std::size_t>(sides), 0), kept(total);
  for (std::size_t k = 0; k < n; ++k) {
    if (owner[k] >= 0) ++total[static_cast<std::size_t>(owner[k])];
  }
  for (const Eigen::Vector3d& point : now.points) {
    for (std::size_t k = 0; k < n; ++k) {
      if (owner[k] >= 0 && (split_points[k] - point).squaredNorm() < 1e-12) {
        ++kept[static_cast<std::size_t>(owner[k])];
        break;
      }
    }
  }
  // The side kept at the highest rate (kept / total), compared without division.
  std::size_t most = 0;
  for (std::size_t side = 1; side < kept.size(); ++side) {
    if (kept[side] * total[most] > kept[most] * total[side]) most = side;
  }
  if (kept[most] < min_tracks) return "";
  for (std::size_t side = 0; side < kept.size(); ++side) {
    if (side != most && kept[side] * total[most] >= other_side_share * kept[most] * total[side]) {
      return "";
    }
  }
  std::ostringstream why;
  why << "its tracks follow one side of a split of motions the frame before could not decide ("
      << kept[most] << " of that side's " << total[most] << " tracks";
  for (std::size_t side = 0; side < kept.size(); ++side) {
    if (side != most) why << ", " << kept[side] << " of the other's " << total[side];
  }
  why << ")";
  return why.str();
}

std::string sceneBehindItsMotion(const MotionPrior& prior, bool scene_is_second, int min_tracks) {
  // Over the dynamic cases and the still sequences (strides 1-5, two start frames, about
  // 8,300 trusted frames), tracks following no motion at 1.5x the depth flagged 13 frames: 9
  // more than half the step off, 2 of them silent failures (KITTI, a truck or a van driving
  // along at a run's start, the scene's tracks too broken up by stride 3 to form a motion), and
  // 2 right (TUM at stride 5, 43 far tracks against the scene's 259: range noise). Also asking
  // for a fifth as many as the scene motion's own keeps the 2 silent ones and 1 more (3 of 3
  // off), and neither right one. At 1.3x, 34 with 15 that far off.
  constexpr double kBehindRatio = 1.5;
  constexpr double kMinShare = 0.2;
  if (!prior.solved || static_cast<int>(prior.tracked_points.size()) < min_tracks) return "";
  const Eigen::Isometry3d first = prior.motion.inverse();
  const Eigen::Isometry3d second = prior.second.motion.inverse();
  const Eigen::Isometry3d third = prior.third.motion.inverse();
  std::vector<double> scene_depths, unexplained_depths;
  for (std::size_t k = 0; k < prior.tracked_points.size(); ++k) {
    const double depth = prior.tracked_points[k].z();
    if (errorPx(prior, k, first) <= prior.inlier_px) {
      if (!scene_is_second) scene_depths.push_back(depth);
    } else if (prior.second.solved && errorPx(prior, k, second) <= prior.inlier_px) {
      if (scene_is_second) scene_depths.push_back(depth);
    } else if (!prior.third.solved || errorPx(prior, k, third) > prior.inlier_px) {
      unexplained_depths.push_back(depth);
    }
  }
  if (static_cast<int>(unexplained_depths.size()) < min_tracks ||
      static_cast<double>(unexplained_depths.size()) <
          kMinShare * static_cast<double>(scene_depths.size()) ||
      scene_depths.empty()) {
    return "";
  }
  const std::size_t unexplained = unexplained_depths.size();
  const double scene_depth = medianInPlace(scene_depths);
  const double unexplained_depth = medianInPlace(unexplained_depths);
  if (!(unexplained_depth >= kBehindRatio * scene_depth)) return "";
  std::ostringstream why;
  why.precision(3);
  why << unexplained << " tracks that follow no motion lie behind the scene's motion's (median "
      << "depths " << unexplained_depth << " and " << scene_depth << " m): the scene may be them";
  return why.str();
}

MotionPrior sceneFirst(const MotionPrior& prior, const MotionSplit& split) {
  MotionPrior out = prior;
  const bool swap = split.scene == SceneMotion::kSecond;
  const int mine = swap ? 1 : 0;
  out.points.clear();
  out.observations.clear();
  out.inlier_pixels.clear();
  out.second.pixels.clear();
  for (std::size_t k = 0; k < split.owner.size(); ++k) {
    if (split.owner[k] == mine) {
      out.points.push_back(prior.tracked_points[k]);
      out.observations.push_back(prior.tracked_observations[k]);
      out.inlier_pixels.push_back(prior.tracked_pixels[k]);
    } else if (split.owner[k] >= 0) {
      out.second.pixels.push_back(prior.tracked_pixels[k]);
    }
  }
  out.inliers = static_cast<int>(out.points.size());
  out.second.inliers = static_cast<int>(out.second.pixels.size());
  // Of the tracks the other motion leaves: its own are no evidence against the scene's.
  const std::size_t left = prior.tracked_points.size() - out.second.pixels.size();
  out.inlier_ratio = left == 0 ? 0.0 : static_cast<double>(out.inliers) / left;
  if (swap) std::swap(out.motion, out.second.motion);
  return out;
}

}  // namespace cvo
