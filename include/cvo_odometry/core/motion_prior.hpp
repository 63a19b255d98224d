// A motion estimate independent of CVO, from feature tracks (the front end's FeatureTracker):
// the previous frame's corners tracked into the current image and the motion solved from them.
// The odometry starts CVO from it and checks CVO's result against its inlier tracks.
#pragma once

#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <Eigen/StdVector>

#include "cvo_odometry/core/camera_model.hpp"

namespace cvo {

struct MotionPrior {
  bool solved = false;  // a motion was found (see problem otherwise)
  // The frame the tracks start from ("previous" below): the last trusted one (FeatureTracker's
  // anchor), by its stamp; NaN: the frame before the current one.
  double from_stamp = std::numeric_limits<double>::quiet_NaN();
  Eigen::Isometry3d motion = Eigen::Isometry3d::Identity();  // previous <- current (camera)
  int tracks = 0;   // previous frame corners with depth tracked into the current image
  int inliers = 0;  // tracks consistent with `motion`
  // Of the second motion's tracks, those that, started again where `motion` puts them, settle
  // there as well (a repeating texture); a second motion of mostly such tracks is not solved.
  int slipped = 0;
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
  std::vector<Eigen::Vector2f, Eigen::aligned_allocator<Eigen::Vector2f>> tracked_pixels;
  double inlier_px = 0.0;  // a track within this reprojection error (px) is a motion's inlier
  // Where the current image sees the inlier tracks (pixels), and the camera that projects
  // points there (null when its distortion model is not one CameraModel has).
  std::vector<Eigen::Vector2f, Eigen::aligned_allocator<Eigen::Vector2f>> inlier_pixels;
  std::optional<CameraModel> camera;
  int image_width = 0, image_height = 0;
  // A second motion among the tracks the first leaves out, when enough of them agree on one: an
  // object moving through the view (previous <- current as if that object stood still).
  struct SecondMotion {
    bool solved = false;
    Eigen::Isometry3d motion = Eigen::Isometry3d::Identity();
    int inliers = 0;
    // Of the inliers, those that start in the object's region of the frame the tracks start
    // from (the first motion is then solved from the other tracks).
    int known_object = 0;
    std::vector<Eigen::Vector2f, Eigen::aligned_allocator<Eigen::Vector2f>> pixels;
    // Its tracks' depths in the current frame miss the first motion's prediction alike, frame
    // after frame (FeatureTracker: median miss against the first motion's tracks' spread), where
    // the image may not tell the motions apart: an object moving along the view's rays.
    bool apart_in_depth = false;
  } second;
  // A third motion among the tracks neither of those explains: two objects moving through the
  // view (people walking past each other). The scene follows the one the two-motion evidence
  // picks against each of the others (splitThreeMotions).
  struct ThirdMotion {
    bool solved = false;
    Eigen::Isometry3d motion = Eigen::Isometry3d::Identity();  // previous <- current
    int inliers = 0;
  } third;
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
