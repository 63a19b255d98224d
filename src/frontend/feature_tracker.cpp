#include "cvo_odometry/frontend/feature_tracker.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <exception>
#include <limits>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

#include "cvo_odometry/core/labeled_cloud.hpp"
#include "cvo_odometry/core/motion_split.hpp"
#include "cvo_odometry/core/robust_scale.hpp"
#include "cvo_odometry/frontend/depth_cloud_builder.hpp"

namespace cvo {

namespace {

// Fewest tracks a PnP solution is worth trying with.
constexpr std::size_t kMinTracks = 8;
// Pyramid levels of the backward (checking) track.
constexpr int kBackwardLevels = 1;
// A corner's response is at least this fraction of the strongest one's (OpenCV's suggestion).
constexpr double kCornerQuality = 0.01;
// Fewest RANSAC inliers a PnP motion is taken with.
constexpr std::size_t kMinPnpInliers = 6;
// RANSAC's iterations at most: the first motion's, and the second's, which searches the first one's
// outliers (and the third's, the outliers of both). Where an object moves its tracks are most of
// those and a sample of them comes early; where nothing moves they are noise and the search runs to
// its cap (at 100: 4 ms a KITTI frame, 3.5 ms a TUM one, half the feature prior's time). At 50,
// bench/dynamic_table.sh's cases (--extra, strides 1 and 2, with and without labels) gave the same
// totals of tracked, lost and silent frames and error as the search at 100 with the outliers in
// reverse order, i.e. as another draw of its random samples; at 30 more silent frames and error.
constexpr int kFirstMotionIterations = 100;
constexpr int kSecondMotionIterations = 50;

// A second motion is apart from the first in depth when its tracks' median depth miss is
// further from the first's tracks' than this many spreads of a median of as many misses ...
constexpr double kDepthApartSpreads = 5.0;
// (the spread of the median of n samples: 1.25 sigma / sqrt(n) for a normal distribution)
constexpr double kMedianSpread = 1.25;
// ... and at least half of its tracks start within this many corner spacings of where the
// frame they start from saw such a second motion.
constexpr double kDepthShiftedNearSpacings = 3.0;

// How far the depth the current frame's `depth` (CV_32FC1, or empty) has at `pixel` is from the
// depth `current_from_previous` puts the previous frame's `point` at, over that depth squared
// (RGB-D and stereo depth noise grow with its square); NaN without a depth.
double depthMiss(const cv::Mat& depth, const cv::Point2f& pixel, const cv::Point3f& point,
                 const Eigen::Isometry3d& current_from_previous) {
  const int u = cvRound(pixel.x), v = cvRound(pixel.y);
  if (depth.type() != CV_32FC1 || u < 0 || v < 0 || u >= depth.cols || v >= depth.rows) {
    return std::numeric_limits<double>::quiet_NaN();
  }
  const double measured = depth.at<float>(v, u);
  const double z = (current_from_previous * Eigen::Vector3d(point.x, point.y, point.z)).z();
  if (!(measured > 0.0) || !std::isfinite(measured) || !(z > 0.0)) {
    return std::numeric_limits<double>::quiet_NaN();
  }
  return (measured - z) / (z * z);
}

// current <- previous from tracks (the previous frame's points, the current image's normalised
// rays) by EPnP in RANSAC (at most `iterations`) with the inlier threshold `threshold`
// (normalised units), refined by Levenberg-Marquardt on the inliers; none when RANSAC finds too
// few.
std::optional<Eigen::Isometry3d> solvePnp(const std::vector<cv::Point3f>& points,
                                          const std::vector<cv::Point2f>& observed,
                                          double threshold, int iterations) {
  cv::Mat rvec, tvec;
  std::vector<int> inliers;
  const cv::Matx33d identity = cv::Matx33d::eye();
  const bool solved =
      cv::solvePnPRansac(points, observed, identity, cv::noArray(), rvec, tvec, false, iterations,
                         static_cast<float>(threshold), 0.999, inliers, cv::SOLVEPNP_EPNP);
  if (!solved || inliers.size() < kMinPnpInliers) return std::nullopt;
  std::vector<cv::Point3f> inlier_points;
  std::vector<cv::Point2f> inlier_observed;
  for (int i : inliers) {
    inlier_points.push_back(points[static_cast<std::size_t>(i)]);
    inlier_observed.push_back(observed[static_cast<std::size_t>(i)]);
  }
  cv::solvePnPRefineLM(inlier_points, inlier_observed, identity, cv::noArray(), rvec, tvec);
  cv::Matx33d R;
  cv::Rodrigues(rvec, R);
  Eigen::Isometry3d current_from_previous = Eigen::Isometry3d::Identity();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c)
      current_from_previous.linear()(r, c) = R(r, c);
    current_from_previous.translation()[r] = tvec.at<double>(r);
  }
  return current_from_previous;
}

// A track off the first motion has slipped on a repeating texture when KLT, started where that
// motion puts it, settles within its inlier distance with a patch error at most this share of
// its own track's, plus this slack (grey levels).
constexpr float kSlippedErrorShare = 1.5f;
constexpr float kSlippedErrorSlack = 2.0f;
// A second motion at least this share of whose tracks slipped is the texture's, not an object's.
constexpr double kSlippedShare = 0.5;

// The previous frame's point X, moved by current <- previous, lands within `threshold` of the
// ray x where the current image sees it.
bool reprojects(const Eigen::Isometry3d& current_from_previous, const Eigen::Vector3d& X,
                const Eigen::Vector2d& x, double threshold) {
  const Eigen::Vector3d p = current_from_previous * X;
  return p.z() > 1e-6 && (p.head<2>() / p.z() - x).norm() <= threshold;
}

// A motion of the tracks `among` (indices into `points` and their normalised rays `observed`)
// by solvePnp, and those of them it puts within `threshold`, in order: the second and third
// motions, each among the tracks the motions before leave out.
struct TracksMotion {
  Eigen::Isometry3d current_from_previous;
  std::vector<std::size_t> inliers;
};
std::optional<TracksMotion> motionAmong(const std::vector<cv::Point3f>& points,
                                        const std::vector<cv::Point2f>& observed,
                                        const std::vector<std::size_t>& among, double threshold) {
  std::vector<cv::Point3f> some_points;
  std::vector<cv::Point2f> some_observed;
  for (std::size_t k : among) {
    some_points.push_back(points[k]);
    some_observed.push_back(observed[k]);
  }
  const std::optional<Eigen::Isometry3d> motion =
      solvePnp(some_points, some_observed, threshold, kSecondMotionIterations);
  if (!motion || !motion->matrix().allFinite()) return std::nullopt;
  TracksMotion out{*motion, {}};
  for (std::size_t k : among) {
    const Eigen::Vector3d X(points[k].x, points[k].y, points[k].z);
    if (reprojects(*motion, X, Eigen::Vector2d(observed[k].x, observed[k].y), threshold)) {
      out.inliers.push_back(k);
    }
  }
  return out;
}

}  // namespace

void FeatureTrackerOptions::validate() const {
  if (max_corners < static_cast<int>(kMinTracks)) {
    throw std::invalid_argument("feature_corners must be >= " + std::to_string(kMinTracks));
  }
  if (!(min_distance > 0.0) || window < 5 || levels < 0 || levels > 8 || !(max_flow_error > 0.0) ||
      !(ransac_px > 0.0) || grid_columns < 0 || grid_columns > 1000 || !(object_apart_px >= 0.0)) {
    throw std::invalid_argument("feature tracker options make no sense");
  }
}

FeatureTracker::FeatureTracker(const FeatureTrackerOptions& options) : options_(options) {
  options_.validate();
}

FeatureTracker::~FeatureTracker() {
  finishSeeding();
}

void FeatureTracker::finishSeeding() {
  if (!seeding_.valid()) return;
  std::string failure;
  try {
    seeding_.get();
  } catch (const std::exception& e) {
    failure = e.what();
  } catch (...) {
    failure = "an unknown error";
  }
  if (!failure.empty()) {
    recycle(candidate_);
    seed_problem_ = "finding the previous frame's corners failed: " + failure;
  }
}

void FeatureTracker::recycle(Corners& corners) {
  if (!corners.pyramid.empty()) spare_pyramid_ = std::move(corners.pyramid);
  corners = Corners();
}

void FeatureTracker::frameJudged(bool trusted, std::shared_ptr<const PixelRegion> moving_region) {
  candidate_kept_ = trusted;
  candidate_region_ = std::move(moving_region);
}

void FeatureTracker::settleCandidate() {
  if (!candidate_pending_) return;
  candidate_pending_ = false;
  // An untrusted frame's corners are dropped while an anchor is left to track from.
  if (!candidate_kept_ && !anchor_.empty()) {
    recycle(candidate_);
  } else {
    recycle(anchor_);
    anchor_ = std::move(candidate_);
    anchor_.moving_region = std::move(candidate_region_);
    candidate_ = Corners();
  }
  candidate_kept_ = true;
  candidate_region_.reset();
}

bool FeatureTracker::seeded() {
  finishSeeding();
  settleCandidate();
  return !anchor_.points.empty();
}

void FeatureTracker::remapDepths(const std::function<float(float)>& new_depth) {
  finishSeeding();
  for (Corners* corners : {&anchor_, &candidate_}) {
    std::size_t kept = 0;
    for (std::size_t k = 0; k < corners->points.size(); ++k) {
      const float scale = rayScale(corners->points[k].z, new_depth);
      if (std::isnan(scale)) continue;
      corners->points[kept] = corners->points[k] * scale;
      corners->pixels[kept++] = corners->pixels[k];
    }
    corners->points.resize(kept);
    corners->pixels.resize(kept);
  }
}

void FeatureTracker::reset() {
  finishSeeding();
  recycle(anchor_);
  recycle(candidate_);
  candidate_pending_ = false;
  candidate_kept_ = true;
  candidate_region_.reset();
  seed_problem_.clear();
  seed_ms_ = 0.0;
  has_previous_ = false;
}

std::vector<cv::Mat> FeatureTracker::pyramid(const cv::Mat& grey,
                                             std::vector<cv::Mat> reuse) const {
  // OpenCV writes into the buffers that have the right size. Level 0 is always a copy (not the
  // caller's image, which a view with a wide enough border would be): the caller may reuse its
  // image, and these buffers are written again two frames on.
  std::vector<cv::Mat> levels = std::move(reuse);
  cv::buildOpticalFlowPyramid(grey, levels, cv::Size(options_.window, options_.window),
                              options_.levels, true, cv::BORDER_REFLECT_101, cv::BORDER_CONSTANT,
                              false);
  return levels;
}

void FeatureTracker::seed(const cv::Mat& grey, const cv::Mat& depth, const PinholeIntrinsics& K,
                          int crop_top_rows, std::vector<cv::Mat> levels) {
  candidate_.pyramid = std::move(levels);
  if (grey.empty() || depth.size() != grey.size() || depth.type() != CV_32FC1) return;
  // Only the rows below the crop, with depth, can hold a corner (KITTI: a quarter of the image
  // skipped); the measure reads the rows above them.
  const std::vector<cv::Point2f>& corners =
      corners_.find(grey, depth, crop_top_rows, options_.max_corners, kCornerQuality,
                    options_.min_distance, options_.grid_columns);
  const std::vector<cv::Point2f> rays = normalisedRays(corners, K);
  for (std::size_t k = 0; k < corners.size(); ++k) {
    const float z = depth.at<float>(cvRound(corners[k].y), cvRound(corners[k].x));
    if (!std::isfinite(z) || !(z > 0.0f)) continue;
    candidate_.points.emplace_back(rays[k].x * z, rays[k].y * z, z);
    candidate_.pixels.push_back(corners[k]);
  }
}

MotionPrior FeatureTracker::track(const cv::Mat& grey, const cv::Mat& depth,
                                  const PinholeIntrinsics& K, int crop_top_rows,
                                  const cv::Mat& excluded, double stamp) {
  finishSeeding();
  settleCandidate();
  if (!excluded.empty() && (excluded.size() != grey.size() || excluded.type() != CV_8UC1)) {
    throw std::invalid_argument("the excluded pixels' mask must be 8-bit, of the image's size");
  }
  // A corner whose KLT window reaches an excluded object is dragged along by it: corners and
  // tracks keep half a window further away than the cloud does.
  cv::Mat kept_away;
  if (!excluded.empty() && cv::countNonZero(excluded) > 0) {
    const int side = options_.window | 1;
    cv::dilate(excluded, kept_away,
               cv::getStructuringElement(cv::MORPH_RECT, cv::Size(side, side)));
  }
  try {
    return trackAndSeed(grey, depth, K, crop_top_rows, kept_away, stamp);
  } catch (...) {
    // The next frame must not be tracked from an older one: start over from it.
    reset();
    throw;
  }
}

MotionPrior FeatureTracker::trackAndSeed(const cv::Mat& grey, const cv::Mat& depth,
                                         const PinholeIntrinsics& K, int crop_top_rows,
                                         const cv::Mat& excluded, double stamp) {
  const auto start = std::chrono::steady_clock::now();
  std::vector<cv::Mat> current = pyramid(grey, std::move(spare_pyramid_));
  std::vector<cv::Point2f> depth_shifted;
  MotionPrior prior = anchor_.empty() ? MotionPrior{}
                                      : solve(current, depth, grey.size(), K, excluded,
                                              &depth_shifted);
  prior.from_stamp = anchor_.stamp;
  if (anchor_.points.empty()) {
    prior.problem =
        seed_problem_.empty() ? "no corners of a previous frame to track" : seed_problem_;
  }
  prior.seed_ms = seed_ms_;
  seed_problem_.clear();
  seed_ms_ = 0.0;
  // This frame's corners are found into the candidate, which frameJudged() settles; none if
  // the search cannot even start.
  candidate_ = Corners();
  candidate_.stamp = stamp;
  candidate_.depth_shifted = std::move(depth_shifted);
  candidate_pending_ = true;
  candidate_kept_ = true;
  candidate_region_.reset();
  has_previous_ = true;
  // Copies, into the buffers of the last ones (the search for them is finished): the caller may
  // reuse its images once this returns.
  grey.copyTo(seed_grey_);
  depth.copyTo(seed_depth_);
  // No corner where no stage may look: the search takes corners only where depth is.
  if (!excluded.empty()) seed_depth_.setTo(std::numeric_limits<float>::quiet_NaN(), excluded);
  seeding_ = std::async(std::launch::async, [this, K, crop_top_rows,
                                             levels = std::move(current)]() mutable {
    const auto begin = std::chrono::steady_clock::now();
    seed(seed_grey_, seed_depth_, K, crop_top_rows, std::move(levels));
    seed_ms_ =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - begin).count();
  });
  prior.time_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return prior;
}

MotionPrior FeatureTracker::solve(const std::vector<cv::Mat>& current, const cv::Mat& depth,
                                  const cv::Size& size, const PinholeIntrinsics& K,
                                  const cv::Mat& excluded,
                                  std::vector<cv::Point2f>* depth_shifted) const {
  MotionPrior prior;
  const cv::Size window(options_.window, options_.window);
  const cv::TermCriteria stop(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 30, 0.01);
  std::vector<cv::Point2f> forward, backward;
  std::vector<unsigned char> ok_forward, ok_backward;
  std::vector<float> errors;
  const std::vector<cv::Point2f>& seen = anchor_.pixels;
  cv::calcOpticalFlowPyrLK(anchor_.pyramid, current, seen, forward, ok_forward, errors, window,
                           options_.levels, stop);
  backward = seen;
  // The check starts at home (the initial flow): a right track has nothing to search for, so
  // one level above the image will do; a wrong one still moves away or fails, and RANSAC's
  // inliers judge what passes. 0.4x the cost of all levels (TUM 2.1 -> 0.9 ms, KITTI 3.8 ->
  // 1.4 ms a frame), the prior alone as accurate (README "Large motions").
  cv::calcOpticalFlowPyrLK(current, anchor_.pyramid, forward, backward, ok_backward, cv::noArray(),
                           window, std::min(options_.levels, kBackwardLevels), stop,
                           cv::OPTFLOW_USE_INITIAL_FLOW);
  std::vector<cv::Point3f> points;
  std::vector<cv::Point2f> pixels, from_pixels;  // where tracks are now, and were
  std::vector<float> track_errors;
  std::vector<bool> on_object;  // seen on the moving object in the previous frame
  for (std::size_t k = 0; k < seen.size(); ++k) {
    const cv::Point2f& p = forward[k];
    const bool inside = p.x >= 0 && p.y >= 0 && p.x < size.width && p.y < size.height;
    if (!ok_forward[k] || !ok_backward[k] || !inside ||
        cv::norm(backward[k] - seen[k]) > options_.max_flow_error) {
      continue;
    }
    // A corner that went behind an excluded object is not seen any more.
    if (!excluded.empty() && excluded.at<std::uint8_t>(cvRound(std::min(p.y, size.height - 1.0f)),
                                                       cvRound(std::min(p.x, size.width - 1.0f)))) {
      continue;
    }
    points.push_back(anchor_.points[k]);
    pixels.push_back(p);
    from_pixels.push_back(seen[k]);
    track_errors.push_back(errors[k]);
    on_object.push_back(anchor_.moving_region &&
                        anchor_.moving_region->contains(seen[k].x, seen[k].y));
  }
  prior.tracks = static_cast<int>(points.size());
  if (points.size() < kMinTracks) {
    prior.problem = "only " + std::to_string(points.size()) + " corners tracked";
    return prior;
  }
  const std::vector<cv::Point2f> observed = normalisedRays(pixels, K);
  const double focal = 0.5 * (K.fx + K.fy);
  const double threshold = options_.ransac_px / focal;
  // With the object's corners known from the last frame, the first motion is solved from the
  // scene's alone (while enough of them are left).
  const auto scene_tracks =
      static_cast<std::size_t>(std::count(on_object.begin(), on_object.end(), false));
  const bool separate = scene_tracks >= kMinTracks && scene_tracks < points.size();
  std::optional<Eigen::Isometry3d> first;
  if (separate) {
    std::vector<cv::Point3f> scene_points;
    std::vector<cv::Point2f> scene_observed;
    for (std::size_t k = 0; k < points.size(); ++k) {
      if (on_object[k]) continue;
      scene_points.push_back(points[k]);
      scene_observed.push_back(observed[k]);
    }
    first = solvePnp(scene_points, scene_observed, threshold, kFirstMotionIterations);
  }
  if (!first) first = solvePnp(points, observed, threshold, kFirstMotionIterations);
  if (!first) {
    prior.problem = "PnP found no consistent motion";
    return prior;
  }
  const Eigen::Isometry3d& current_from_previous = *first;
  if (!current_from_previous.matrix().allFinite()) {
    prior.problem = "PnP gave no finite motion";
    return prior;
  }
  prior.solved = true;
  prior.motion = current_from_previous.inverse();
  prior.focal_px = focal;
  prior.inlier_px = options_.ransac_px;
  prior.image_width = size.width;
  prior.image_height = size.height;
  if (CameraModel::supportsDistortion(K.distortion.size())) {
    prior.camera = CameraModel(K.fx, K.fy, K.cx, K.cy, K.distortion);
  }
  // The inliers of the refined motion are the tracks that judge CVO.
  prior.tracked_points.reserve(points.size());
  prior.tracked_observations.reserve(points.size());
  std::vector<std::size_t> rest;                      // the tracks the first motion leaves out
  std::vector<bool> off_first(points.size(), false);  // not within its inlier distance
  for (std::size_t k = 0; k < points.size(); ++k) {
    const Eigen::Vector3d X(points[k].x, points[k].y, points[k].z);
    const Eigen::Vector2d x(observed[k].x, observed[k].y);
    prior.tracked_points.push_back(X);
    prior.tracked_observations.push_back(x);
    prior.tracked_pixels.emplace_back(pixels[k].x, pixels[k].y);
    off_first[k] = !reprojects(current_from_previous, X, x, threshold);
    if ((separate && on_object[k]) || off_first[k]) {
      rest.push_back(k);
      continue;
    }
    prior.points.push_back(X);
    prior.observations.push_back(x);
    prior.inlier_pixels.emplace_back(pixels[k].x, pixels[k].y);
  }
  prior.inliers = static_cast<int>(prior.points.size());
  prior.inlier_ratio = static_cast<double>(prior.inliers) / static_cast<double>(points.size());
  // The tracks it leaves out may follow one motion of their own: an object moving through the
  // view. Its motion and its tracks' pixels let the odometry judge which one the scene follows
  // and leave the other's region out.
  if (rest.size() < kMinTracks) return prior;
  const std::optional<TracksMotion> second = motionAmong(points, observed, rest, threshold);
  if (!second) return prior;
  MotionPrior::SecondMotion& out = prior.second;
  std::vector<bool> on_second(points.size(), false);
  for (std::size_t k : second->inliers) {
    out.pixels.emplace_back(pixels[k].x, pixels[k].y);
    on_second[k] = true;
    if (separate && on_object[k]) ++out.known_object;
  }
  out.inliers = static_cast<int>(out.pixels.size());
  out.solved = out.pixels.size() >= kMinPnpInliers;
  if (out.solved) {
    const std::vector<bool> slipped = slippedTracks(current, points, from_pixels, track_errors,
                                                    on_second, current_from_previous, prior.camera);
    prior.slipped = static_cast<int>(std::count(slipped.begin(), slipped.end(), true));
    // Mostly slipped tracks: a repeating texture, not an object.
    if (prior.slipped >= kSlippedShare * out.inliers) out.solved = false;
  }
  out.motion = second->current_from_previous.inverse();
  if (!out.solved) return prior;
  // Only beside a second motion moving_min_px from the first (KeyframeOdometry's test in the
  // image): on a still scene the search would run to its cap on noise, 2 ms a frame.
  if (motionsApartPx(prior, prior.motion, out.motion) >= options_.object_apart_px) {
    std::vector<std::size_t> off_both;  // the tracks neither motion puts within the distance
    for (std::size_t k = 0; k < points.size(); ++k) {
      if (off_first[k] && !on_second[k]) off_both.push_back(k);
    }
    solveThirdMotion(current, points, observed, from_pixels, track_errors, off_both,
                     current_from_previous, threshold, &prior);
  }
  // Apart in depth: the second motion's tracks' depth misses (measured in the current frame
  // against the first motion's prediction) have a median far outside what the first motion's
  // own tracks' misses allow a median of as many. TUM with a board approaching from 1.2 m
  // (bench/dynamic_table.sh's "towards"): its tracks move within 4 px of the scene's in the
  // image, but miss by 10-20 mm, 6-30 such spreads; a still scene's second motions (near and
  // far tracks of an RGB-D camera) stay within 4, but for single frames (6.8 at stride 3), so
  // the same region must miss in the frame before too.
  std::vector<double> first_misses, second_misses;
  for (std::size_t k = 0; k < points.size(); ++k) {
    const double miss = depthMiss(depth, pixels[k], points[k], current_from_previous);
    if (std::isfinite(miss)) (on_second[k] ? second_misses : first_misses).push_back(miss);
  }
  if (first_misses.size() < kMinTracks || second_misses.size() < kMinPnpInliers) return prior;
  const double centre = medianInPlace(first_misses);
  for (double& miss : first_misses) miss = std::abs(miss - centre);
  const double spread = 1.4826 * medianInPlace(first_misses);
  const double median_spread = kMedianSpread * spread / std::sqrt(second_misses.size());
  if (!(spread > 0.0) ||
      !(std::abs(medianInPlace(second_misses) - centre) > kDepthApartSpreads * median_spread)) {
    return prior;
  }
  // Where the tracks started: near where the anchor's own second motion missed, if it did.
  const double near_px = kDepthShiftedNearSpacings * options_.min_distance;
  std::size_t again = 0;
  for (std::size_t k = 0; k < points.size(); ++k) {
    if (!on_second[k]) continue;
    depth_shifted->push_back(pixels[k]);
    for (const cv::Point2f& p : anchor_.depth_shifted) {
      if (cv::norm(p - from_pixels[k]) <= near_px) {
        ++again;
        break;
      }
    }
  }
  out.apart_in_depth = 2 * again >= static_cast<std::size_t>(out.inliers);
  return prior;
}

void FeatureTracker::solveThirdMotion(
    const std::vector<cv::Mat>& current, const std::vector<cv::Point3f>& points,
    const std::vector<cv::Point2f>& observed, const std::vector<cv::Point2f>& from_pixels,
    const std::vector<float>& track_errors, const std::vector<std::size_t>& among,
    const Eigen::Isometry3d& first, double threshold, MotionPrior* prior) const {
  if (among.size() < kMinTracks) return;
  const std::optional<TracksMotion> third = motionAmong(points, observed, among, threshold);
  if (!third || third->inliers.size() < kMinPnpInliers) return;
  std::vector<bool> on_third(points.size(), false);
  for (std::size_t k : third->inliers)
    on_third[k] = true;
  const auto inliers = static_cast<int>(third->inliers.size());
  // Mostly slipped tracks: a repeating texture, as for the second motion.
  const std::vector<bool> slipped =
      slippedTracks(current, points, from_pixels, track_errors, on_third, first, prior->camera);
  if (std::count(slipped.begin(), slipped.end(), true) >= kSlippedShare * inliers) return;
  prior->third.solved = true;
  prior->third.motion = third->current_from_previous.inverse();
  prior->third.inliers = inliers;
}

std::vector<bool> FeatureTracker::slippedTracks(const std::vector<cv::Mat>& current,
                                                const std::vector<cv::Point3f>& points,
                                                const std::vector<cv::Point2f>& from_pixels,
                                                const std::vector<float>& track_errors,
                                                const std::vector<bool>& which,
                                                const Eigen::Isometry3d& current_from_previous,
                                                const std::optional<CameraModel>& camera) const {
  // On a repeating texture (a keyboard's keys, tiles, a fence) KLT can slip by one period, both
  // ways alike, and the slipped tracks agree on a motion of their own: a second motion where
  // nothing moves. Such a track, started again where the first motion puts it, settles there.
  std::vector<bool> slipped(points.size(), false);
  if (!camera) return slipped;
  std::vector<std::size_t> tried;
  std::vector<cv::Point2f> starts, ends;
  for (std::size_t k = 0; k < points.size(); ++k) {
    if (!which[k]) continue;
    const Eigen::Vector3d p =
        current_from_previous * Eigen::Vector3d(points[k].x, points[k].y, points[k].z);
    if (!(p.z() > 1e-6)) continue;
    const Eigen::Vector2d pixel = camera->project(p);
    tried.push_back(k);
    starts.push_back(from_pixels[k]);
    ends.emplace_back(static_cast<float>(pixel.x()), static_cast<float>(pixel.y()));
  }
  if (tried.empty()) return slipped;
  const std::vector<cv::Point2f> predicted = ends;
  std::vector<unsigned char> ok;
  std::vector<float> errors;
  const cv::TermCriteria stop(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 30, 0.01);
  // One level: the search stays near where the first motion puts the track.
  cv::calcOpticalFlowPyrLK(anchor_.pyramid, current, starts, ends, ok, errors,
                           cv::Size(options_.window, options_.window), 0, stop,
                           cv::OPTFLOW_USE_INITIAL_FLOW);
  for (std::size_t i = 0; i < tried.size(); ++i) {
    const std::size_t k = tried[i];
    if (!ok[i] || cv::norm(ends[i] - predicted[i]) > options_.ransac_px) continue;
    slipped[k] = errors[i] <= kSlippedErrorShare * track_errors[k] + kSlippedErrorSlack;
  }
  return slipped;
}

}  // namespace cvo
