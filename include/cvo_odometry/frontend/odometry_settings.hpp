// Every setting of the odometry below ROS: the core's (cvo_settings.hpp) and the front end's
// rows of the settings table, one aggregate that presets, the tools and the nodelet read.
#pragma once

#include <string>

#include "cvo_odometry/core/cvo_settings.hpp"
#include "cvo_odometry/core/disparity_offset_estimator.hpp"
#include "cvo_odometry/frontend/depth_cloud_builder.hpp"
#include "cvo_odometry/frontend/feature_tracker.hpp"
#include "cvo_odometry/frontend/rgbd_cloud_builder.hpp"
#include "cvo_odometry/frontend/stereo_cloud_builder.hpp"
#include "cvo_odometry/frontend/stereo_matcher.hpp"

namespace cvo {

struct OdometrySettings {
  CvoParams cvo;
  CloudBuilderOptions cloud;
  StereoMatcherOptions stereo;
  FeatureTrackerOptions features;
  double depth_scale = 1000.0;  // 16-bit depth units per metre
  // The cloud's least point spacing as a fraction of ell_min (CloudBuilderOptions'
  // min_point_spacing = point_spacing * ell_min; README "Point spacing"). Off by default: it
  // pays off only for near scenes, and there it trades accuracy for time.
  double point_spacing = 0.0;
  double disparity_offset = 0.0;  // px added to every stereo disparity (README "Stereo scale")
  bool estimate_disparity_offset = true;  // self-calibrate it from the feature tracks
  DisparityOffsetOptions disparity_offset_estimate;

  // Throws std::invalid_argument naming the first setting that makes no sense.
  void validate() const;

  // The front ends' options. The grey image levels only while the photometric stage, their
  // one user, is on (they cost a few ms a frame).
  CloudBuilderOptions cloudOptions() const;
  RgbdFrontendOptions rgbdOptions() const;
  StereoFrontendOptions stereoOptions() const;
  // The feature tracker's: `features`, with what the odometry takes for an object's motion.
  FeatureTrackerOptions trackerOptions() const;
};

template <class V>
void visitSettings(OdometrySettings& s, V&& v) {
  visitSettings(s.cvo, v);
  v(SettingInfo{"point_selector", "points",
                "which pixels become points: grid (uniform), fast (FAST corners) or mixed"},
    s.cloud.selector.kind);
  v(SettingInfo{"min_points", "points", "fewest selected points per frame", 100, 200000},
    s.cloud.selector.min_points);
  v(SettingInfo{"max_points", "points", "most selected points per frame", 100, 400000},
    s.cloud.selector.max_points);
  v(SettingInfo{"point_spacing", "points",
                "at most one point in each cube of this edge, as a fraction of ell_min (0: off)",
                0.0, 2.0},
    s.point_spacing);
  v(SettingInfo{"min_depth", "depth", "nearer points are not used (m)", 0.0, 1000.0},
    s.cloud.min_depth);
  v(SettingInfo{"max_depth", "depth",
                "farther points stay out of the cloud; the feature prior still tracks them (m)",
                0.01, 10000.0},
    s.cloud.max_depth);
  v(SettingInfo{"depth_scale", "depth", "16-bit depth units per metre (1000: ROS millimetres)",
                1e-3, 1e6},
    s.depth_scale);
  v(SettingInfo{"crop_top_rows", "points", "rows at the top never used (KITTI: sky)", 0, 100000},
    s.cloud.crop_top_rows);
  v(SettingInfo{"image_levels", "photometric",
                "blur levels of the grey image for the photometric stage (sigmas ..., 1, 0 px)", 0,
                6},
    s.cloud.image_levels);
  v(SettingInfo{"semantic_classes", "semantics",
                "classes of the segmentation images (0: no segmentation)", 0, 65536},
    s.cloud.semantic_classes);
  v(SettingInfo{"ignore_classes", "semantics",
                "class ids no stage uses (cloud, feature tracks, photometric stage): moving "
                "things such as people and vehicles, and sky",
                0, 65535},
    s.cloud.ignore_classes);
  v(SettingInfo{"ignore_border_px", "semantics",
                "ignored classes' pixels grown by this (px): labels are never pixel-exact", 0, 200},
    s.cloud.ignore_border_px);
  v(SettingInfo{"num_disparities", "stereo", "SGBM disparity range (a multiple of 16)", 16, 1024},
    s.stereo.num_disparities);
  v(SettingInfo{"block_size", "stereo", "SGBM block size (odd)", 1, 21}, s.stereo.block_size);
  v(SettingInfo{"disparity_offset", "stereo",
                "pixels added to every disparity before depth: a stereo calibration's correction",
                -5.0, 5.0},
    s.disparity_offset);
  v(SettingInfo{"estimate_disparity_offset", "stereo",
                "estimate the disparity offset from the feature tracks and use it once trusted "
                "(disparity_offset is the start)"},
    s.estimate_disparity_offset);
  v(SettingInfo{"disparity_offset_min_pairs", "stereo",
                "frame pairs before the estimated disparity offset is used", 2, 100000},
    s.disparity_offset_estimate.min_pairs);
  v(SettingInfo{"disparity_offset_max_error", "stereo",
                "the estimated disparity offset is used once its standard error is below this (px)",
                0.001, 10.0},
    s.disparity_offset_estimate.max_standard_error);
  v(SettingInfo{"sgbm_mode", "stereo", "SGBM variant: sgbm, hh (8 paths) or sgbm_3way (threaded)"},
    s.stereo.mode);
  v(SettingInfo{"stereo_depth", "stereo",
                "where stereo depth is matched: dense (SGBM at every pixel), quarter or half (at "
                "the pixels the front end uses, around SGBM at 1/4 or 1/2 resolution) or sparse "
                "(those pixels, the whole range searched)"},
    s.stereo.depth);
  v(SettingInfo{"feature_prior", "features",
                "track the previous frame's corners (KLT + PnP): a motion guess and a check "
                "independent of CVO"},
    s.features.enabled);
  v(SettingInfo{"feature_corners", "features", "most corners taken per frame", 8, 10000},
    s.features.max_corners);
  v(SettingInfo{"feature_min_distance", "features", "least distance between corners (px)", 1.0,
                200.0},
    s.features.min_distance);
  v(SettingInfo{"feature_grid", "features",
                "corners spread over square cells, this many across the image, none holding more "
                "than its share (0: off): a corner-rich moving object cannot take nearly all "
                "tracks",
                0, 1000},
    s.features.grid_columns);
  v(SettingInfo{"klt_window", "features", "KLT window (px)", 5, 101}, s.features.window);
  v(SettingInfo{"klt_levels", "features", "KLT pyramid levels above the image", 0, 8},
    s.features.levels);
  v(SettingInfo{"klt_max_error", "features",
                "a track is kept when its backward track returns within this (px)", 0.01, 20.0},
    s.features.max_flow_error);
  v(SettingInfo{"pnp_ransac_px", "features", "PnP inlier threshold (px)", 0.1, 50.0},
    s.features.ransac_px);
}

// Defaults, then the preset at `path` (empty: none), validated; FormatError names the file and
// line of a bad key or value.
OdometrySettings loadOdometrySettings(const std::string& path,
                                      const OdometrySettings& base = OdometrySettings());

}  // namespace cvo
