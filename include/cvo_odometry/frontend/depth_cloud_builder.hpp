// Image + metric depth (+ segmentation) to a labeled cloud in the camera's optical frame (z
// forward, x right, y down). The RGB-D and stereo front ends both end here.
#pragma once

#include <memory>
#include <optional>
#include <vector>

#include <opencv2/core.hpp>

#include "cvo_odometry/core/intensity_image.hpp"
#include "cvo_odometry/core/labeled_cloud.hpp"
#include "cvo_odometry/frontend/float_buffer_pool.hpp"
#include "cvo_odometry/frontend/pinhole_intrinsics.hpp"
#include "cvo_odometry/frontend/point_selector.hpp"
#include "cvo_odometry/frontend/ray_table.hpp"

namespace cvo {

struct CloudBuilderOptions {
  // The cloud's depth range (metres). Nearer depths are dropped when raw depth or disparity
  // becomes metres; farther ones stay in the depth image, for the feature tracker (a far corner
  // is tracked well through large motions, where near ones are lost), and only the cloud leaves
  // them out.
  double min_depth = 0.1;
  double max_depth = 10.0;
  int crop_top_rows = 0;  // rows at the top never selected (KITTI: sky and stereo-less band)
  SelectorOptions selector;
  // At most one point of a frame in each cube of this edge (metres; 0: every selected pixel),
  // the first selected: pixels chosen in the image crowd together in 3D on near surfaces, where
  // each point adds kernel pairs to every registration sum (PointSpacing).
  double min_point_spacing = 0.0;
  // Blur levels of the grey image attached to each cloud for the photometric rotation stage
  // (sigmas ..., 2, 1, 0 px; 0: no image attached).
  int image_levels = 2;
  int semantic_classes = 0;  // > 0: a segmentation image is expected
  // Classes no stage uses: moving things (people, vehicles) and what has no reliable depth (sky).
  std::vector<int> ignore_classes;
  // Their pixels grown by this much (px) before anything is left out: labels are never
  // pixel-exact, and a corner on the outline moves with the object.
  int ignore_border_px = 8;

  // Throws std::invalid_argument naming the option that makes no sense.
  void validate() const;
};

struct FrontendStats {
  SelectionStats selection;
  // The largest shift (px) of an ignored region moved to the depth image's instant (LabelTiming;
  // only shifts beyond ignore_border_px are made); 0: none.
  int label_motion_px = 0;
  std::size_t spaced_out = 0;  // selected points left out for min_point_spacing
  std::size_t valid_depth_pixels = 0;
  double matching_ms = 0.0;  // stereo matching, part of time_ms
  double time_ms = 0.0;
};

// What the front end made of a frame besides its cloud: the grey image and the metric depth
// (CV_32FC1, NaN where invalid or nearer than min_depth, beyond max_depth kept), for the feature
// tracker.
struct FrameImages {
  cv::Mat grey;
  cv::Mat depth;
  // CV_8UC1, non-zero where no stage may use the pixel (an ignored class, grown by
  // ignore_border_px); empty when every pixel may be used. The one place that decides it: the
  // cloud, the feature tracks and the photometric stage all read it.
  cv::Mat excluded;
};

// The grey image for the photometric stage: `levels` blurs of `image` (8-bit BGR or grey), or
// null when levels is 0 or the distortion model is not one CameraModel projects. With `buffers`,
// the levels are written into buffers taken from it and handed back when the image is destroyed.
// `excluded` (CV_8UC1 of the image's size, or empty): pixels the stage must not use.
std::shared_ptr<const IntensityImage> intensityImage(
    const cv::Mat& image, const PinholeIntrinsics& intrinsics, int levels,
    const std::shared_ptr<FloatBufferPool>& buffers = nullptr, const cv::Mat& excluded = cv::Mat());

// Rays (x/z, y/z) through pixel centres (or sub-pixel positions), undistorted when the
// intrinsics carry distortion.
std::vector<cv::Point2f> normalisedRays(const std::vector<cv::Point2f>& pixels,
                                        const PinholeIntrinsics& intrinsics);
std::vector<cv::Point2f> normalisedRays(const std::vector<cv::Point>& pixels,
                                        const PinholeIntrinsics& intrinsics);

// When the frame was taken, for labelled objects that move: labels describe the colour image,
// and a depth image taken at another instant (RGB-D cameras whose streams are not synchronised:
// TUM's Kinect, up to half a frame apart) shows a moving object where it was or will be then,
// off its labels by its image speed times the gap.
struct LabelTiming {
  double stamp = 0.0;               // the labels' (colour image's) time (s): frame to frame, speed
  double depth_after_labels = 0.0;  // the depth image's stamp minus the labels' (s)
};

// How labelled regions moved from `previous` to `current` (CV_8UC1 masks of one size, non-zero
// where labelled): each connected region of `current` that shares pixels with one of
// `previous` of a like area (half to twice) moved as its centre did, or, where the image border
// cuts it, as its uncut edge did. A region new in view (or a segmentation flickering on), or
// one merging or splitting, has no motion.
struct LabelRegionMotions {
  cv::Mat regions;                                 // CV_32S: current's regions, 1.., 0 unlabelled
  std::vector<std::optional<cv::Point2d>> motion;  // by region (px)
  cv::Mat vanished;  // CV_8UC1: previous's regions that share no pixel with current's
};
LabelRegionMotions labelRegionMotions(const cv::Mat& previous, const cv::Mat& current);

class DepthCloudBuilder {
 public:
  explicit DepthCloudBuilder(const CloudBuilderOptions& options);

  // `depth_metres`: CV_32FC1, NaN where invalid, registered to `image` (8-bit BGR or grey); the
  // cloud takes the pixels within [min_depth, max_depth].
  // Throws std::invalid_argument naming the problem: empty or mismatched images, intrinsics that
  // make no sense or do not match the image, a missing or unusable segmentation image; throws
  // EmptyFrameError (a std::invalid_argument) when no pixel has depth in range or every selected
  // one is in an ignored class.
  // With `timing`, ignored regions that move are also left out where they are at the depth
  // image's instant (labelRegionMotions against the previous call's labels; nothing on the
  // first call or after a gap of over a second).
  LabeledCloud build(const cv::Mat& image, const cv::Mat& depth_metres,
                     const PinholeIntrinsics& intrinsics, const cv::Mat& semantics,
                     FrontendStats* stats, FrameImages* images = nullptr,
                     const LabelTiming* timing = nullptr);

  const CloudBuilderOptions& options() const { return options_; }

 private:
  CloudBuilderOptions options_;
  PointSelector selector_;
  RayTable rays_;
  // The photometric levels' buffers, reused from frame to frame (shared with the images, which
  // hand theirs back when destroyed, on whichever thread).
  std::shared_ptr<FloatBufferPool> level_buffers_;
  // The last timed frame's ignored pixels (at a quarter of the resolution) and its stamp.
  cv::Mat last_labels_;
  double last_labels_stamp_ = 0.0;
  // The pixels where labelled regions are at the depth image's instant (LabelTiming): each
  // region that moved since the last frame further than ignore_border_px takes in, moved by its
  // motion over the gap (the largest shift, px, into *moved_px), and, where the depth is older
  // than the colour, the last frame's regions gone from the labels. Empty when there are none.
  // Keeps `labels` for the next frame.
  cv::Mat labelsAtDepthInstant(const cv::Mat& labels, cv::Size size, const LabelTiming& timing,
                               int* moved_px);
};

}  // namespace cvo
