// A motion estimate independent of CVO, from feature tracks (the front end's FeatureTracker):
// the keyframe's corners tracked into the current image and the motion solved from them. The
// odometry starts CVO from it and checks CVO's result against its inlier tracks.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <Eigen/StdVector>

namespace cvo {

struct MotionPrior {
  bool solved = false;  // a motion was found (see problem otherwise)
  Eigen::Isometry3d motion = Eigen::Isometry3d::Identity();  // keyframe <- current (camera)
  int tracks = 0;   // keyframe corners with depth tracked into the current image
  int inliers = 0;  // tracks consistent with `motion`
  double inlier_ratio = 0.0;
  // The inlier tracks: keyframe points (camera frame) and where the current image sees them
  // (normalised, undistorted image coordinates x/z, y/z).
  std::vector<Eigen::Vector3d, Eigen::aligned_allocator<Eigen::Vector3d>> points;
  std::vector<Eigen::Vector2d, Eigen::aligned_allocator<Eigen::Vector2d>> observations;
  double focal_px = 0.0;        // pixels per normalised unit: converts errors to pixels
  bool wants_keyframe = false;  // few tracks are left: a new keyframe would restore them
  std::string problem;          // why no motion was solved
  double time_ms = 0.0;
};

// The fraction of the prior's inlier tracks that `motion` (keyframe <- current) reprojects within
// `max_error_px` of where the current image sees them; -1 without tracks.
double trackAgreement(const MotionPrior& prior, const Eigen::Isometry3d& motion,
                      double max_error_px);

}  // namespace cvo
