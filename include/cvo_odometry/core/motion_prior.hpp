// A motion estimate independent of CVO, from feature tracks (the front end's FeatureTracker):
// the previous frame's corners tracked into the current image and the motion solved from them.
// The odometry starts CVO from it and checks CVO's result against its inlier tracks.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <Eigen/StdVector>

namespace cvo {

struct MotionPrior {
  bool solved = false;  // a motion was found (see problem otherwise)
  Eigen::Isometry3d motion = Eigen::Isometry3d::Identity();  // previous <- current (camera)
  int tracks = 0;   // previous frame corners with depth tracked into the current image
  int inliers = 0;  // tracks consistent with `motion`
  double inlier_ratio = 0.0;
  // The inlier tracks: the previous frame's points (its camera frame) and where the current
  // image sees them (normalised, undistorted image coordinates x/z, y/z).
  std::vector<Eigen::Vector3d, Eigen::aligned_allocator<Eigen::Vector3d>> points;
  std::vector<Eigen::Vector2d, Eigen::aligned_allocator<Eigen::Vector2d>> observations;
  // Every track that passed the forward-backward check, inlier or not, in the same form: a user
  // that must not inherit the inlier test's bias (the disparity offset's estimate) judges them
  // itself.
  std::vector<Eigen::Vector3d, Eigen::aligned_allocator<Eigen::Vector3d>> tracked_points;
  std::vector<Eigen::Vector2d, Eigen::aligned_allocator<Eigen::Vector2d>> tracked_observations;
  double focal_px = 0.0;  // pixels per normalised unit: converts errors to pixels
  std::string problem;    // why no motion was solved
  double time_ms = 0.0;   // tracking and solving, on the caller's thread
  double seed_ms = 0.0;   // finding the previous frame's corners, on a thread beside its frame's
};

// How well `motion` (previous <- current) explains the prior's inlier tracks: the fraction it
// reprojects within `max_error_px` of where the current image sees them, the median error and
// the tracks' median image motion (px); -1 without tracks.
struct TrackAgreement {
  double fraction = -1.0;
  double median_px = -1.0;
  double median_flow_px = -1.0;  // how far the tracks moved in the image over the step
};
TrackAgreement trackAgreement(const MotionPrior& prior, const Eigen::Isometry3d& motion,
                              double max_error_px);

}  // namespace cvo
