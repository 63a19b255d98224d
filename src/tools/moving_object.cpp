#include "cvo_odometry/tools/moving_object.hpp"

#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

#include "cvo_odometry/frontend/depth_cloud_builder.hpp"

namespace cvo {

namespace {

constexpr int kTextureSize = 512;

cv::Mat makeTexture(ObjectTexture kind, unsigned seed, const cv::Mat& scene) {
  std::mt19937 random(seed);
  std::uniform_int_distribution<int> shade(20, 235);
  cv::Mat texture(kTextureSize, kTextureSize, CV_8UC3);
  switch (kind) {
    case ObjectTexture::kPlain:
      // A soft left-to-right shading: a real surface, but no corner anywhere inside it.
      for (int r = 0; r < texture.rows; ++r) {
        for (int c = 0; c < texture.cols; ++c) {
          const double s = 0.85 + 0.15 * c / static_cast<double>(texture.cols);
          texture.at<cv::Vec3b>(r, c) =
              cv::Vec3b(cv::saturate_cast<uchar>(70 * s), cv::saturate_cast<uchar>(110 * s),
                        cv::saturate_cast<uchar>(170 * s));
        }
      }
      break;
    case ObjectTexture::kStripes:
      for (int c = 0; c < texture.cols; ++c) {
        const bool dark = (c / 32) % 2 == 0;
        texture.col(c).setTo(dark ? cv::Scalar(40, 50, 60) : cv::Scalar(200, 210, 190));
      }
      break;
    case ObjectTexture::kChecker:
      for (int r = 0; r < texture.rows; ++r) {
        for (int c = 0; c < texture.cols; ++c) {
          const bool dark = ((r / 64) + (c / 64)) % 2 == 0;
          texture.at<cv::Vec3b>(r, c) = dark ? cv::Vec3b(30, 40, 50) : cv::Vec3b(220, 215, 200);
        }
      }
      break;
    case ObjectTexture::kBlocks: {
      texture.setTo(cv::Scalar(shade(random), shade(random), shade(random)));
      std::uniform_int_distribution<int> at(-40, kTextureSize), size(12, 90);
      for (int k = 0; k < 260; ++k) {
        const cv::Rect block(at(random), at(random), size(random), size(random));
        cv::rectangle(texture, block, cv::Scalar(shade(random), shade(random), shade(random)),
                      cv::FILLED);
      }
      break;
    }
    case ObjectTexture::kScene: {
      if (scene.empty()) throw std::invalid_argument("the scene texture needs a scene image");
      cv::Mat colour;
      if (scene.channels() == 1) {
        cv::cvtColor(scene, colour, cv::COLOR_GRAY2BGR);
      } else {
        colour = scene;
      }
      // The middle of the frame, mirrored: the background's own kind of texture.
      const int side = std::min(colour.cols, colour.rows);
      const cv::Rect middle((colour.cols - side) / 2, (colour.rows - side) / 2, side, side);
      cv::Mat crop;
      cv::flip(colour(middle), crop, 1);
      cv::resize(crop, texture, texture.size(), 0, 0, cv::INTER_AREA);
      break;
    }
  }
  return texture;
}

}  // namespace

ObjectTexture parseObjectTexture(const std::string& name) {
  if (name == "plain") return ObjectTexture::kPlain;
  if (name == "stripes") return ObjectTexture::kStripes;
  if (name == "checker") return ObjectTexture::kChecker;
  if (name == "blocks") return ObjectTexture::kBlocks;
  if (name == "scene") return ObjectTexture::kScene;
  throw std::invalid_argument("texture '" + name +
                              "': expected plain, stripes, checker, blocks or scene");
}

std::string toString(ObjectTexture texture) {
  switch (texture) {
    case ObjectTexture::kPlain:
      return "plain";
    case ObjectTexture::kStripes:
      return "stripes";
    case ObjectTexture::kChecker:
      return "checker";
    case ObjectTexture::kBlocks:
      return "blocks";
    default:
      return "scene";
  }
}

void MovingObjectSpec::validate() const {
  if (!(area > 0.0 && area <= 4.0)) throw std::invalid_argument("object area must be in (0, 4]");
  if (!(aspect > 0.05 && aspect < 20.0))
    throw std::invalid_argument("aspect must be in (0.05, 20)");
  if (!(depth > 0.05 && depth < 1e4)) throw std::invalid_argument("object depth must be > 0.05 m");
  if (!std::isfinite(start_u) || !std::isfinite(start_v)) {
    throw std::invalid_argument("the object's start must be finite");
  }
  if (!velocity.allFinite()) throw std::invalid_argument("the object's velocity must be finite");
  if (label < 0 || label > 255) throw std::invalid_argument("label must be in [0, 255]");
  if (std::abs(label_error_px) > 50) throw std::invalid_argument("label error must be <= 50 px");
}

MovingObject::MovingObject(const MovingObjectSpec& spec, const PinholeIntrinsics& intrinsics,
                           const Eigen::Isometry3d& world_from_first, double first_stamp,
                           const cv::Mat& scene)
    : spec_(spec),
      intrinsics_(intrinsics),
      world_from_first_(world_from_first),
      first_stamp_(first_stamp) {
  spec_.validate();
  intrinsics_.validate();
  std::vector<cv::Point2f> pixels;
  pixels.reserve(static_cast<std::size_t>(intrinsics_.width) * intrinsics_.height);
  for (int v = 0; v < intrinsics_.height; ++v) {
    for (int u = 0; u < intrinsics_.width; ++u)
      pixels.emplace_back(static_cast<float>(u), static_cast<float>(v));
  }
  rays_ = normalisedRays(pixels, intrinsics_);
  // The board's size from the share of the image it covers at its depth.
  const double z = spec_.depth;
  const double view_area =
      (intrinsics_.width * z / intrinsics_.fx) * (intrinsics_.height * z / intrinsics_.fy);
  const double shape_area = spec_.ellipse ? M_PI / 4.0 : 1.0;
  width_ = std::sqrt(spec_.area * view_area * spec_.aspect / shape_area);
  height_ = width_ / spec_.aspect;
  const double u = spec_.start_u * intrinsics_.width, v = spec_.start_v * intrinsics_.height;
  const std::vector<cv::Point2f> centre = normalisedRays(
      std::vector<cv::Point2f>{cv::Point2f(static_cast<float>(u), static_cast<float>(v))},
      intrinsics_);
  start_ = Eigen::Vector3d(centre[0].x * z, centre[0].y * z, z);
  texture_ = makeTexture(spec_.texture, spec_.seed, scene);
}

Eigen::Isometry3d MovingObject::cameraFromObject(double stamp,
                                                 const Eigen::Isometry3d& world_from_camera) const {
  Eigen::Isometry3d moved = Eigen::Isometry3d::Identity();
  moved.translation() = start_ + spec_.velocity * (stamp - first_stamp_);
  if (spec_.with_camera) return moved;
  return world_from_camera.inverse() * world_from_first_ * moved;
}

int MovingObject::render(const Eigen::Isometry3d& camera_from_object, cv::Mat* image,
                         cv::Mat* depth, cv::Mat* mask, double shift_x,
                         const cv::Mat* scene_depth) const {
  if (image == nullptr || image->rows != intrinsics_.height || image->cols != intrinsics_.width ||
      image->depth() != CV_8U || (image->channels() != 1 && image->channels() != 3)) {
    throw std::invalid_argument("the image must be 8-bit BGR or grey of the intrinsics' size");
  }
  if (depth) {
    if (depth->empty()) {
      depth->create(image->size(), CV_32FC1);
      depth->setTo(std::numeric_limits<float>::quiet_NaN());
    }
    if (depth->size() != image->size() || depth->type() != CV_32FC1) {
      throw std::invalid_argument("the depth must be CV_32FC1 of the image's size");
    }
  }
  if (scene_depth && (scene_depth->size() != image->size() || scene_depth->type() != CV_32FC1)) {
    throw std::invalid_argument("the scene depth must be CV_32FC1 of the image's size");
  }
  if (mask) *mask = cv::Mat::zeros(image->size(), CV_8UC1);
  // The ray x = s * (r, 1) from the camera at (shift_x, 0, 0), in the board's frame.
  const Eigen::Isometry3d object_from_camera = camera_from_object.inverse();
  const Eigen::Vector3d origin = object_from_camera * Eigen::Vector3d(shift_x, 0.0, 0.0);
  const Eigen::Matrix3d R = object_from_camera.linear();
  const bool grey = image->channels() == 1;
  int covered = 0;
  for (int v = 0; v < image->rows; ++v) {
    for (int u = 0; u < image->cols; ++u) {
      const cv::Point2f& r = rays_[static_cast<std::size_t>(v) * image->cols + u];
      const Eigen::Vector3d direction = R * Eigen::Vector3d(r.x, r.y, 1.0);
      if (std::abs(direction.z()) < 1e-9) continue;
      const double s = -origin.z() / direction.z();  // the camera's depth of the hit
      if (!(s > 1e-3)) continue;
      if (scene_depth) {
        const float z = scene_depth->at<float>(v, u);
        if (std::isfinite(z) && z > 0.0f && z < s) continue;  // the scene is in front
      }
      const Eigen::Vector3d hit = origin + s * direction;
      const double a = hit.x() / width_ + 0.5, b = hit.y() / height_ + 0.5;
      if (spec_.ellipse) {
        if ((a - 0.5) * (a - 0.5) + (b - 0.5) * (b - 0.5) > 0.25) continue;
      } else if (a < 0.0 || a >= 1.0 || b < 0.0 || b >= 1.0) {
        continue;
      }
      const int tc = std::min(kTextureSize - 1, static_cast<int>(a * kTextureSize));
      const int tr = std::min(kTextureSize - 1, static_cast<int>(b * kTextureSize));
      const cv::Vec3b colour = texture_.at<cv::Vec3b>(tr, tc);
      if (grey) {
        image->at<uchar>(v, u) =
            cv::saturate_cast<uchar>(0.114 * colour[0] + 0.587 * colour[1] + 0.299 * colour[2]);
      } else {
        image->at<cv::Vec3b>(v, u) = colour;
      }
      if (depth) depth->at<float>(v, u) = static_cast<float>(s);
      if (mask) mask->at<uchar>(v, u) = 255;
      ++covered;
    }
  }
  return covered;
}

cv::Mat MovingObject::labels(const cv::Mat& mask) const {
  cv::Mat changed = mask;
  if (spec_.label_error_px != 0) {
    changed = cv::Mat();  // a new image: the caller's mask stays the object's
    const int n = std::abs(spec_.label_error_px);
    const cv::Mat disc =
        cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * n + 1, 2 * n + 1));
    if (spec_.label_error_px > 0) {
      cv::erode(mask, changed, disc);
    } else {
      cv::dilate(mask, changed, disc);
    }
  }
  cv::Mat out = cv::Mat::zeros(mask.size(), CV_8UC1);
  out.setTo(spec_.label, changed);
  return out;
}

}  // namespace cvo
