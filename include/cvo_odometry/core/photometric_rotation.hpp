// The photometric rotation stage (after CVO, when CvoParams::photometric_rotation is on).
//
// Why: an RGB-D camera's depth and colour are not captured at the same instant (the Kinect of
// TUM fr1 stamps depth 12-20 ms before colour, and its geometry behaves as if older still), and
// the registration of depth geometry reports the rotation of the depth's time. The colour image
// fixes rotation best: image-plane motion is dominated by rotation, hardly by depth errors.
// So the CVO pose (translation and rotation) starts a robust Gauss-Newton alignment of the
// current cloud's own intensities with the reference image (6-DoF, coarse blur level first,
// Huber weights at 1.345 x the residuals' MAD scale), and only its rotation is kept: the
// translation stays CVO's, which the depth observes better than the image does.
//
// Stereo, where depth and image are simultaneous (CvoParams::photometric_translation and
// photometric_tracks): the stage keeps its translation too, and the feature prior's inlier tracks
// join the intensities as reprojection errors (TrackReprojection), the intensities counted with
// their cluster-robust information (README "Tracks in the photometric stage").
#pragma once

#include <cstddef>
#include <string>

#include <Eigen/Geometry>

#include "cvo_odometry/core/block_pool.hpp"
#include "cvo_odometry/core/cvo_params.hpp"
#include "cvo_odometry/core/intensity_image.hpp"
#include "cvo_odometry/core/labeled_cloud.hpp"
#include "cvo_odometry/core/motion_prior.hpp"
#include "cvo_odometry/core/pixel_region.hpp"

namespace cvo {

struct PhotometricReport {
  bool applied = false;
  std::string skipped;          // why the stage left CVO's rotation, empty when applied
  int iterations = 0;           // Gauss-Newton iterations over all levels
  std::size_t points = 0;       // points inside the reference image at the last iteration
  double correction_deg = 0.0;  // angle between CVO's rotation and the refined one
  double correlation = 0.0;     // of the cloud's intensities with the reference's at the result
  std::size_t tracks = 0;       // feature tracks joined at the last iteration (0: none)
  double time_ms = 0.0;
};

struct PhotometricRotationResult {
  Eigen::Isometry3d transform = Eigen::Isometry3d::Identity();  // reference <- current
  PhotometricReport report;
};

// The feature prior's inlier tracks as a second set of residuals (CvoParams::photometric_tracks):
// their points live in the frame the prior tracked from, `prior_from_reference` away.
struct PhotometricTracks {
  const MotionPrior* prior = nullptr;
  Eigen::Isometry3d prior_from_reference = Eigen::Isometry3d::Identity();
};

// `reference_from_current`: CVO's estimate. Returns it unchanged (with `skipped` set) when the
// images' levels differ, too few points (< params.min_tracking_points, divided by the point stride
// of a blurred level) land in the reference image, the solve degenerates, the intensities correlate
// below 0.5 at the result (the images do not show the same scene: a black frame, a covered lens),
// or the rotation's correction exceeds params.photometric_max_correction (the translation, kept
// only with photometric_translation, has no bound of its own). `tracks` count only with
// params.photometric_tracks, and only when at least 6 are in front and the intensities fill at
// least 24 cells; report.tracks says how many joined. The points are evaluated on `pool` (null:
// this thread); the result is the same on any thread count. No sample is taken where either
// image excludes its pixel (IntensityImage::usable) nor, in the reference image, inside
// `reference_left_out` (a moving object's region there; may be null).
PhotometricRotationResult refineRotationPhotometrically(
    const IntensityImage& reference, const IntensityImage& current, const LabeledCloud& cloud,
    const Eigen::Isometry3d& reference_from_current, const CvoParams& params,
    BlockPool* pool = nullptr, const PhotometricTracks* tracks = nullptr,
    const PixelRegion* reference_left_out = nullptr);

}  // namespace cvo
