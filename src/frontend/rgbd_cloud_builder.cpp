#include "cvo_odometry/frontend/rgbd_cloud_builder.hpp"

#include <chrono>
#include <cmath>
#include <memory>
#include <stdexcept>

#include <opencv2/calib3d.hpp>

#include "cvo_odometry/frontend/color_features.hpp"
#include "cvo_odometry/frontend/depth_conversion.hpp"
#include "cvo_odometry/frontend/semantic_image.hpp"

namespace cvo {

namespace {

std::string sizeText(const cv::Mat& m) {
  return std::to_string(m.cols) + "x" + std::to_string(m.rows);
}

}  // namespace

std::vector<cv::Point2f> normalisedRays(const std::vector<cv::Point>& pixels,
                                        const PinholeIntrinsics& K) {
  std::vector<cv::Point2f> rays(pixels.size());
  if (K.distortion.empty()) {
    for (std::size_t k = 0; k < pixels.size(); ++k) {
      rays[k] = cv::Point2f(static_cast<float>((pixels[k].x - K.cx) / K.fx),
                            static_cast<float>((pixels[k].y - K.cy) / K.fy));
    }
    return rays;
  }
  if (pixels.empty()) return rays;
  std::vector<cv::Point2f> in(pixels.begin(), pixels.end());
  const cv::Matx33d camera(K.fx, 0, K.cx, 0, K.fy, K.cy, 0, 0, 1);
  cv::undistortPoints(in, rays, camera, K.distortion);
  return rays;
}

RgbdCloudBuilder::RgbdCloudBuilder(const RgbdFrontendOptions& options)
    : options_(options), selector_(options.selector) {
  if (!(options.min_depth >= 0.0) || !(options.max_depth > options.min_depth)) {
    throw std::invalid_argument("depth range [" + std::to_string(options.min_depth) + ", " +
                                std::to_string(options.max_depth) + "] makes no sense");
  }
}

LabeledCloud RgbdCloudBuilder::build(const RgbdFrame& frame, FrontendStats* stats) {
  const auto start = std::chrono::steady_clock::now();
  if (frame.image.empty()) throw std::invalid_argument("colour image is empty");
  if (frame.depth.empty()) throw std::invalid_argument("depth image is empty");
  if (frame.image.size() != frame.depth.size()) {
    throw std::invalid_argument("colour image is " + sizeText(frame.image) + " but depth is " +
                                sizeText(frame.depth));
  }
  frame.intrinsics.validate();
  if (frame.intrinsics.width != frame.image.cols || frame.intrinsics.height != frame.image.rows) {
    throw std::invalid_argument("camera info is for " + std::to_string(frame.intrinsics.width) +
                                "x" + std::to_string(frame.intrinsics.height) +
                                " images but the image is " + sizeText(frame.image));
  }
  std::unique_ptr<SemanticImage> semantics;
  if (options_.semantic_classes > 0) {
    if (frame.semantics.empty()) throw std::invalid_argument("segmentation image missing");
    if (frame.semantics.size() != frame.image.size()) {
      throw std::invalid_argument("segmentation is " + sizeText(frame.semantics) +
                                  " but the image is " + sizeText(frame.image));
    }
    semantics = std::make_unique<SemanticImage>(frame.semantics, options_.semantic_classes,
                                                options_.ignore_classes);
  }
  const cv::Mat depth = depthToMetres(frame.depth, options_.depth_units_per_metre,
                                      options_.min_depth, options_.max_depth);
  const cv::Mat valid = (depth == depth);  // false for NaN
  const std::size_t valid_count = static_cast<std::size_t>(cv::countNonZero(valid));
  if (valid_count == 0) throw std::invalid_argument("no pixel has valid depth");
  const cv::Mat grey = toGrey(frame.image);
  const cv::Mat features = colorFeatures(frame.image);
  FrontendStats local;
  const auto pixels = selector_.select(grey, valid, &local.selection);

  const auto rays = normalisedRays(pixels, frame.intrinsics);
  LabeledCloud cloud(true, options_.semantic_classes);
  cloud.reserve(pixels.size());
  std::vector<float> probabilities(
      static_cast<std::size_t>(std::max(options_.semantic_classes, 1)));
  for (std::size_t k = 0; k < pixels.size(); ++k) {
    const cv::Point& p = pixels[k];
    if (semantics && !semantics->probabilities(p.x, p.y, probabilities.data())) continue;
    const float z = depth.at<float>(p);
    const Eigen::Vector3f position(rays[k].x * z, rays[k].y * z, z);
    cloud.add(position, features.ptr<float>(p.y) + 5 * p.x,
              semantics ? probabilities.data() : nullptr);
  }
  local.valid_depth_pixels = valid_count;
  local.time_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  if (stats) *stats = local;
  return cloud;
}

}  // namespace cvo
