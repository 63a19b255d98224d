// Self-calibration of a stereo rig's disparity offset from the odometry's own feature tracks.
//
// A rectified rig whose calibration is slightly off measures every disparity shifted by a
// constant (KITTI's rigs by about a quarter pixel: README "Stereo scale"). Depth z = f b / d then
// errs most at range, where d is small, and the odometry's translation comes out about 1 % long.
// A constant offset is observable from the data alone: a rigid motion must carry every tracked
// corner from its depth in one frame to its depth in the next, and a wrong offset bends near
// and far corners differently. Per frame pair the offset and the motion are solved together,
// minimising the corners' stereo reprojection error (left image position and disparity in the
// second frame, as stereo visual odometry does), and the offset's information left after the
// motion is marginalised out (its Schur complement) weighs that pair's estimate. One pair sees
// the offset only weakly (KITTI 06: 5-pair means scatter 0.12-0.49 px), so the estimate is the
// information-weighted mean over the pairs so far, trusted once enough pairs agree.
#pragma once

#include <optional>
#include <vector>

#include <Eigen/Geometry>
#include <Eigen/StdVector>

namespace cvo {

// A corner seen in two consecutive left images, with the matcher's raw disparity (pixels, no
// offset added) at both ends.
struct StereoTrack {
  Eigen::Vector2d before;   // normalised image coordinates (x / z, y / z) in the first frame
  Eigen::Vector2d after;    // in the second
  double disparity_before;  // px
  double disparity_after;   // px
};
using StereoTracks = std::vector<StereoTrack, Eigen::aligned_allocator<StereoTrack>>;

struct DisparityOffsetOptions {
  int min_tracks = 30;              // fewer tracks in a pair: the pair is not used
  int min_pairs = 5;                // pairs before an estimate is trusted
  double max_standard_error = 0.1;  // px: the trusted estimate's spread over the pairs
  double max_pair_offset = 3.0;     // px: a pair's solution beyond this is not used
  double pixel_sigma = 1.0;         // px, a track's position error in the second image
  double disparity_sigma = 0.5;     // px, a disparity's error
  double huber_threshold = 2.0;     // on the track's whitened residual norm
};

struct DisparityOffsetEstimate {
  double offset = 0.0;          // px, to add to every raw disparity
  double standard_error = 0.0;  // px, from the spread of the pairs' estimates
  int pairs = 0;                // pairs that contributed
  bool trusted = false;         // enough pairs, agreeing closely enough
};

class DisparityOffsetEstimator {
 public:
  explicit DisparityOffsetEstimator(const DisparityOffsetOptions& options = {});

  // One frame pair: the tracks, the motion carrying the first frame's points into the second
  // (second <- first, a start for the solve: the odometry's or the feature prior's), the focal
  // length (px) and focal length times baseline (px m), and the offset to linearise about (the
  // one in use). Returns whether the pair contributed.
  bool addPair(const StereoTracks& tracks, const Eigen::Isometry3d& second_from_first,
               double focal_px, double focal_baseline, double current_offset);

  // The weighted mean of the pairs so far (trusted or not); nothing before the first pair.
  std::optional<DisparityOffsetEstimate> estimate() const;
  void reset();

  // One pair's joint solve, exposed for tests: the pair's offset and its information (1 / px^2),
  // or nothing when the pair cannot say (too few tracks, a singular system, beyond the bound).
  struct PairSolution {
    double offset = 0.0;
    double information = 0.0;
    Eigen::Isometry3d second_from_first = Eigen::Isometry3d::Identity();
  };
  std::optional<PairSolution> solvePair(const StereoTracks& tracks,
                                        const Eigen::Isometry3d& second_from_first, double focal_px,
                                        double focal_baseline, double current_offset) const;

 private:
  DisparityOffsetOptions options_;
  double sum_weight_ = 0.0;          // sum of the pairs' information
  double sum_weight_squared_ = 0.0;  // for the effective number of pairs
  double sum_weighted_offset_ = 0.0;
  double sum_weighted_square_ = 0.0;
  int pairs_ = 0;
};

}  // namespace cvo
