#include "cvo_odometry/frontend/depth_cloud_builder.hpp"

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
                                      FrameImages* images) {
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
  // Pixels of ignored classes, grown by the border: no stage uses them.
  cv::Mat excluded;
  if (semantics) {
    excluded = semantics->excludedMask();
    if (cv::countNonZero(excluded) == 0) {
      excluded.release();
    } else if (options_.ignore_border_px > 0) {
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
  local.time_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  if (stats) {
    local.matching_ms = stats->matching_ms;
    *stats = local;
  }
  return cloud;
}

}  // namespace cvo
