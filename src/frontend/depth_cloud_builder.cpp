#include "cvo_odometry/frontend/depth_cloud_builder.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "cvo_odometry/frontend/color_features.hpp"
#include "cvo_odometry/frontend/depth_conversion.hpp"
#include "cvo_odometry/frontend/empty_frame_error.hpp"
#include "cvo_odometry/frontend/point_spacing.hpp"
#include "cvo_odometry/frontend/semantic_image.hpp"

namespace cvo {

namespace {

std::string sizeText(const cv::Mat& m) {
  return std::to_string(m.cols) + "x" + std::to_string(m.rows);
}

// `mask` moved by `shift` px (rounded), zero where nothing moved in.
cv::Mat translated(const cv::Mat& mask, const cv::Point2d& shift) {
  const int dx = static_cast<int>(std::lround(shift.x)),
            dy = static_cast<int>(std::lround(shift.y));
  cv::Mat out = cv::Mat::zeros(mask.size(), mask.type());
  const int width = mask.cols - std::abs(dx), height = mask.rows - std::abs(dy);
  if (width > 0 && height > 0) {
    mask(cv::Rect(std::max(0, -dx), std::max(0, -dy), width, height))
        .copyTo(out(cv::Rect(std::max(0, dx), std::max(0, dy), width, height)));
  }
  return out;
}

// Labels further apart in time than this (s) tell no speed: a gap in the stream.
constexpr double kMaxLabelInterval = 1.0;

}  // namespace

void CloudBuilderOptions::validate() const {
  if (!(min_depth >= 0.0) || !(max_depth > min_depth)) {
    throw std::invalid_argument("depth range [" + std::to_string(min_depth) + ", " +
                                std::to_string(max_depth) + "] makes no sense");
  }
  if (crop_top_rows < 0) throw std::invalid_argument("crop_top_rows must be >= 0");
  if (!(min_point_spacing >= 0.0 && min_point_spacing <= 1e3)) {
    throw std::invalid_argument("min_point_spacing must be in [0, 1000] m, got " +
                                std::to_string(min_point_spacing));
  }
  if (selector.min_points < 1 || selector.max_points < selector.min_points) {
    throw std::invalid_argument("point count range [" + std::to_string(selector.min_points) + ", " +
                                std::to_string(selector.max_points) + "] makes no sense");
  }
  if (semantic_classes < 0) throw std::invalid_argument("semantic_classes must be >= 0");
  if (ignore_border_px < 0 || ignore_border_px > 200) {
    throw std::invalid_argument("ignore_border_px must be in [0, 200]");
  }
  if (image_levels < 0 || image_levels > 6) {
    throw std::invalid_argument("image_levels must be in [0, 6]");
  }
}

std::shared_ptr<const IntensityImage> intensityImage(
    const cv::Mat& image, const PinholeIntrinsics& K, int levels,
    const std::shared_ptr<FloatBufferPool>& buffers, const cv::Mat& excluded) {
  if (levels <= 0 || !CameraModel::supportsDistortion(K.distortion.size())) return nullptr;
  std::vector<std::uint8_t> excluded_pixels;
  if (!excluded.empty()) {
    if (excluded.size() != image.size() || excluded.type() != CV_8UC1) {
      throw std::invalid_argument("the excluded pixels' mask must be 8-bit, of the image's size");
    }
    excluded_pixels.resize(excluded.total());
    cv::Mat pixels(excluded.rows, excluded.cols, CV_8UC1, excluded_pixels.data());
    excluded.copyTo(pixels);
  }
  // Each level is written straight into its own buffer: no image is allocated and copied.
  std::vector<IntensityImage::Level> out(static_cast<std::size_t>(levels));
  const auto header = [&image, &buffers](IntensityImage::Level& level) {
    if (buffers) {
      level.values = buffers->take(image.total());
    } else {
      level.values.resize(image.total());
    }
    return cv::Mat(image.rows, image.cols, CV_32F, level.values.data());
  };
  cv::Mat sharp = header(out.back());  // the last level: unblurred
  toGrey(image).convertTo(sharp, CV_32F, 1.0 / 255.0);
  for (int l = 0; l + 1 < levels; ++l) {
    IntensityImage::Level& level = out[static_cast<std::size_t>(l)];
    level.blur_sigma = std::ldexp(1.0, levels - 2 - l);
    cv::Mat blurred = header(level);
    cv::GaussianBlur(sharp, blurred, cv::Size(), level.blur_sigma);
  }
  auto* built =
      new IntensityImage(image.cols, image.rows, CameraModel(K.fx, K.fy, K.cx, K.cy, K.distortion),
                         std::move(out), std::move(excluded_pixels));
  if (!buffers) return std::shared_ptr<const IntensityImage>(built);
  return std::shared_ptr<const IntensityImage>(built, [buffers](IntensityImage* done) {
    for (IntensityImage::Level& level : done->releaseLevels())
      buffers->give(std::move(level.values));
    delete done;
  });
}

std::vector<cv::Point2f> normalisedRays(const std::vector<cv::Point2f>& pixels,
                                        const PinholeIntrinsics& K) {
  std::vector<cv::Point2f> rays(pixels.size());
  if (pixels.empty()) return rays;
  if (K.distortion.empty()) {
    for (std::size_t k = 0; k < pixels.size(); ++k) {
      rays[k] = cv::Point2f(static_cast<float>((pixels[k].x - K.cx) / K.fx),
                            static_cast<float>((pixels[k].y - K.cy) / K.fy));
    }
    return rays;
  }
  const cv::Matx33d camera(K.fx, 0, K.cx, 0, K.fy, K.cy, 0, 0, 1);
  cv::undistortPoints(pixels, rays, camera, K.distortion);
  return rays;
}

std::vector<cv::Point2f> normalisedRays(const std::vector<cv::Point>& pixels,
                                        const PinholeIntrinsics& K) {
  // Integer coordinates are exact in float: the same rays as the pixels' own.
  return normalisedRays(std::vector<cv::Point2f>(pixels.begin(), pixels.end()), K);
}

LabelRegionMotions labelRegionMotions(const cv::Mat& previous, const cv::Mat& current) {
  if (previous.size() != current.size() || previous.type() != CV_8UC1 ||
      current.type() != CV_8UC1) {
    throw std::invalid_argument("labelRegionMotions: two 8-bit masks of one size");
  }
  LabelRegionMotions out;
  cv::Mat before_regions, before_stats, before_centres, now_stats, now_centres;
  const int before_count =
      cv::connectedComponentsWithStats(previous, before_regions, before_stats, before_centres, 8);
  const int now_count =
      cv::connectedComponentsWithStats(current, out.regions, now_stats, now_centres, 8);
  out.motion.assign(static_cast<std::size_t>(now_count), std::nullopt);
  // Pixels each region (of current) shares with each region of previous.
  std::vector<int> shared(static_cast<std::size_t>(now_count) * before_count, 0);
  for (int v = 0; v < current.rows; ++v) {
    const int* now_row = out.regions.ptr<int>(v);
    const int* before_row = before_regions.ptr<int>(v);
    for (int u = 0; u < current.cols; ++u) {
      if (now_row[u] > 0 && before_row[u] > 0) {
        ++shared[static_cast<std::size_t>(now_row[u]) * before_count + before_row[u]];
      }
    }
  }
  // Regions of previous that share no pixel with current: gone from view, or flickering off.
  std::vector<bool> continued(static_cast<std::size_t>(before_count), false);
  for (int r = 1; r < now_count; ++r) {
    for (int p = 1; p < before_count; ++p)
      continued[p] = continued[p] || shared[static_cast<std::size_t>(r) * before_count + p] > 0;
  }
  out.vanished = cv::Mat::zeros(previous.size(), CV_8UC1);
  for (int v = 0; v < previous.rows; ++v) {
    const int* before_row = before_regions.ptr<int>(v);
    std::uint8_t* gone = out.vanished.ptr<std::uint8_t>(v);
    for (int u = 0; u < previous.cols; ++u)
      gone[u] = before_row[u] > 0 && !continued[before_row[u]] ? 255 : 0;
  }
  const auto stat = [](const cv::Mat& stats, int region, int which) {
    return stats.at<int>(region, which);
  };
  for (int r = 1; r < now_count; ++r) {
    const int* row = &shared[static_cast<std::size_t>(r) * before_count];
    const int p = static_cast<int>(std::max_element(row + 1, row + before_count) - row);
    if (before_count < 2 || row[p] == 0) continue;  // new in view, or flickering on
    // Regions merging or splitting have no one motion.
    const double area_ratio = static_cast<double>(stat(now_stats, r, cv::CC_STAT_AREA)) /
                              stat(before_stats, p, cv::CC_STAT_AREA);
    if (area_ratio < 0.5 || area_ratio > 2.0) continue;
    cv::Point2d moved;
    for (int axis = 0; axis < 2; ++axis) {
      const int first = axis == 0 ? cv::CC_STAT_LEFT : cv::CC_STAT_TOP;
      const int extent = axis == 0 ? cv::CC_STAT_WIDTH : cv::CC_STAT_HEIGHT;
      const int size = axis == 0 ? current.cols : current.rows;
      const int lo_now = stat(now_stats, r, first), lo_before = stat(before_stats, p, first);
      const int hi_now = lo_now + stat(now_stats, r, extent);
      const int hi_before = lo_before + stat(before_stats, p, extent);
      const bool cut_low = lo_now == 0 || lo_before == 0;
      const bool cut_high = hi_now == size || hi_before == size;
      // Where the image border cuts the region, its centre moves slower than it does: the
      // edge the border does not cut moves as it does.
      double shift = now_centres.at<double>(r, axis) - before_centres.at<double>(p, axis);
      if (cut_low && !cut_high) shift = hi_now - hi_before;
      if (cut_high && !cut_low) shift = lo_now - lo_before;
      (axis == 0 ? moved.x : moved.y) = shift;
    }
    out.motion[static_cast<std::size_t>(r)] = moved;
  }
  return out;
}

cv::Mat DepthCloudBuilder::labelsAtDepthInstant(const cv::Mat& labels, cv::Size size,
                                                const LabelTiming& timing, int* moved_px) {
  // A quarter of the resolution (any labelled pixel marks its cell): a few tenths of a ms.
  constexpr int kScale = 4;
  const cv::Size cells((size.width + kScale - 1) / kScale, (size.height + kScale - 1) / kScale);
  cv::Mat small = cv::Mat::zeros(cells, CV_8UC1);  // empty labels: every label gone
  if (!labels.empty()) {
    cv::resize(labels, small, cells, 0, 0, cv::INTER_AREA);
    small = small > 0;
  }
  cv::Mat at_depth_instant;  // empty while nothing is added
  const auto add = [&](const cv::Mat& pixels) {
    at_depth_instant = at_depth_instant.empty() ? pixels : (at_depth_instant | pixels);
  };
  const double interval = timing.stamp - last_labels_stamp_;
  if (!last_labels_.empty() && last_labels_.size() == small.size() &&
      timing.depth_after_labels != 0.0 && interval > 0.0 && interval <= kMaxLabelInterval) {
    const LabelRegionMotions motions = labelRegionMotions(last_labels_, small);
    // The depth's instant: ahead of the labels (depth after colour), or behind.
    const double to_depth = timing.depth_after_labels / interval * kScale;
    const double most = std::max(size.width, size.height) / 8.0;  // px
    for (std::size_t r = 1; r < motions.motion.size(); ++r) {
      if (!motions.motion[r]) continue;
      cv::Point2d shift = *motions.motion[r] * to_depth;
      const double length = cv::norm(shift);
      if (length > most) shift *= most / length;
      // The border takes in motion up to its own width.
      if (std::max(std::abs(shift.x), std::abs(shift.y)) <= options_.ignore_border_px) continue;
      cv::Mat pixels;  // the region's cells at the labels' resolution, then its labelled pixels
      cv::resize(motions.regions == static_cast<int>(r), pixels, size, 0, 0, cv::INTER_NEAREST);
      add(translated(pixels & labels, shift));
      *moved_px = std::max(
          *moved_px, static_cast<int>(std::lround(std::max(std::abs(shift.x), std::abs(shift.y)))));
    }
    // Depth older than the colour: what left the labels since the last frame (out of view, or
    // missed by the segmentation) may still be in the depth, near where it was labelled then.
    if (timing.depth_after_labels < 0.0 && cv::countNonZero(motions.vanished) > 0) {
      cv::Mat gone;
      cv::resize(motions.vanished, gone, size, 0, 0, cv::INTER_NEAREST);
      add(gone);
    }
  }
  last_labels_ = cv::countNonZero(small) > 0 ? small : cv::Mat();
  last_labels_stamp_ = timing.stamp;
  return at_depth_instant;
}

DepthCloudBuilder::DepthCloudBuilder(const CloudBuilderOptions& options)
    : options_(options), selector_(options.selector) {
  options_.validate();
  // Enough for the levels of the frame being made and of one released before it.
  level_buffers_ =
      std::make_shared<FloatBufferPool>(2 * static_cast<std::size_t>(options_.image_levels));
}

LabeledCloud DepthCloudBuilder::build(const cv::Mat& image, const cv::Mat& depth,
                                      const PinholeIntrinsics& intrinsics,
                                      const cv::Mat& semantics_image, FrontendStats* stats,
                                      FrameImages* images, const LabelTiming* timing) {
  const auto start = std::chrono::steady_clock::now();
  if (image.empty()) throw std::invalid_argument("colour image is empty");
  if (depth.empty()) throw std::invalid_argument("depth image is empty");
  if (depth.type() != CV_32FC1) throw std::invalid_argument("metric depth must be 32FC1");
  if (image.size() != depth.size()) {
    throw std::invalid_argument("colour image is " + sizeText(image) + " but depth is " +
                                sizeText(depth));
  }
  intrinsics.validate();
  if (intrinsics.width != image.cols || intrinsics.height != image.rows) {
    throw std::invalid_argument("camera info is for " + std::to_string(intrinsics.width) + "x" +
                                std::to_string(intrinsics.height) + " images but the image is " +
                                sizeText(image));
  }
  std::unique_ptr<SemanticImage> semantics;
  if (options_.semantic_classes > 0) {
    if (semantics_image.empty()) throw std::invalid_argument("segmentation image missing");
    if (semantics_image.size() != image.size()) {
      throw std::invalid_argument("segmentation is " + sizeText(semantics_image) +
                                  " but the image is " + sizeText(image));
    }
    semantics = std::make_unique<SemanticImage>(semantics_image, options_.semantic_classes,
                                                options_.ignore_classes);
  }
  // Pixels of ignored classes, grown by the border (and their motion): no stage uses them.
  cv::Mat excluded;
  int motion_px = 0;
  if (semantics) {
    excluded = semantics->excludedMask();
    if (cv::countNonZero(excluded) == 0) excluded.release();
    if (timing) {
      // Each region that moved further than the border reaches, also where the depth shows it.
      const cv::Mat at_depth_instant =
          labelsAtDepthInstant(excluded, image.size(), *timing, &motion_px);
      if (!at_depth_instant.empty()) {
        excluded = excluded.empty() ? at_depth_instant : (excluded | at_depth_instant);
      }
    }
    if (!excluded.empty() && options_.ignore_border_px > 0) {
      // A square: separable, and at least the border in every direction.
      const int side = 2 * options_.ignore_border_px + 1;
      cv::dilate(excluded, excluded,
                 cv::getStructuringElement(cv::MORPH_RECT, cv::Size(side, side)));
    }
  }
  cv::Mat valid;  // NaN is outside every range
  const auto [lo, hi] = floatDepthRange(options_.min_depth, options_.max_depth);
  cv::inRange(depth, lo, hi, valid);
  const int cropped = std::min(options_.crop_top_rows, depth.rows);
  valid.rowRange(0, cropped).setTo(0);
  const bool any_in_range = cv::countNonZero(valid) > 0;
  if (!excluded.empty()) valid.setTo(0, excluded);
  const std::size_t valid_count = static_cast<std::size_t>(cv::countNonZero(valid));
  if (valid_count == 0 && any_in_range) {
    throw EmptyFrameError("every pixel with depth belongs to an ignored class (ignore_classes, " +
                          std::to_string(options_.ignore_border_px) + " px border)");
  }
  if (valid_count == 0) {
    // Named by what emptied it: no depth at all, the crop, or the range (RGB-D depths nearer
    // than min_depth are already NaN here: the converter drops them).
    if (cropped == depth.rows) {
      throw EmptyFrameError("crop_top_rows (" + std::to_string(options_.crop_top_rows) +
                            ") leaves none of the image's " + std::to_string(depth.rows) + " rows");
    }
    const std::string where =
        cropped > 0 ? "below the top " + std::to_string(cropped) + " rows (crop_top_rows) " : "";
    const cv::Mat kept_rows = depth.rowRange(cropped, depth.rows);
    if (cv::countNonZero(kept_rows == kept_rows) == 0) {
      throw EmptyFrameError("no pixel " + where + "has valid depth");
    }
    throw EmptyFrameError("no pixel " + where + "has depth in [" +
                          std::to_string(options_.min_depth) + ", " +
                          std::to_string(options_.max_depth) + "] m");
  }
  const cv::Mat grey = toGrey(image);
  FrontendStats local;
  const auto pixels = selector_.select(grey, valid, &local.selection);

  const auto rays = rays_.rays(pixels, intrinsics);
  LabeledCloud cloud(true, options_.semantic_classes);
  cloud.reserve(pixels.size());
  std::vector<float> probabilities(
      static_cast<std::size_t>(std::max(options_.semantic_classes, 1)));
  PointSpacing spacing(options_.min_point_spacing, pixels.size());
  for (std::size_t k = 0; k < pixels.size(); ++k) {
    const cv::Point& p = pixels[k];
    if (semantics && !semantics->probabilities(p.x, p.y, probabilities.data())) continue;
    const float z = depth.at<float>(p);
    const Eigen::Vector3f position(rays[k].x * z, rays[k].y * z, z);
    if (!spacing.admit(position)) {
      ++local.spaced_out;
      continue;
    }
    float features[5];
    colorFeaturesAt(image, grey, p.x, p.y, features);
    cloud.add(position, features, semantics ? probabilities.data() : nullptr);
  }
  if (cloud.size() == 0) {
    throw EmptyFrameError("every selected pixel belongs to an ignored class");
  }
  cloud.setImage(intensityImage(grey, intrinsics, options_.image_levels, level_buffers_, excluded));
  if (images) *images = FrameImages{grey, depth, excluded};
  local.valid_depth_pixels = valid_count;
  local.label_motion_px = motion_px;
  local.time_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  if (stats) {
    local.matching_ms = stats->matching_ms;
    *stats = local;
  }
  return cloud;
}

}  // namespace cvo
