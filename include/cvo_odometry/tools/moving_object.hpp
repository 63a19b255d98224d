// A moving object composited into recorded frames, with its exact labels: the dynamic-scene cases
// of bench/dynamic_table.sh and the moving-object tests. The object is a textured planar board
// (a rectangle or an ellipse) that starts facing the first camera at a given image position and
// depth, and moves at a constant velocity, either in the world (a person walking past: the
// dataset's ground truth places it in each frame) or with the camera (a car driving along: its
// image motion is only its drift). It is rendered by casting each pixel's ray (undistorted with
// the camera's model) onto the board, so a stereo pair's two images, and an RGB-D frame's colour
// and depth at their own stamps, show it consistently. Given the scene's depth (an RGB-D frame's),
// the scene hides it where the scene is nearer, as a real camera would see it; without (a stereo
// pair), it is painted over the scene: choose a depth nearer than what it should hide.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "cvo_odometry/frontend/pinhole_intrinsics.hpp"

namespace cvo {

enum class ObjectTexture {
  kPlain,    // one colour, softly shaded: no corners inside
  kStripes,  // vertical stripes: edges, few corners
  kChecker,  // a checkerboard: a corner every square
  kBlocks,   // random rectangles of random shades: corner-rich, irregular
  kScene     // a mirrored crop of a frame of the same sequence: looks like the background
};
ObjectTexture parseObjectTexture(const std::string& name);  // throws std::invalid_argument
std::string toString(ObjectTexture texture);

struct MovingObjectSpec {
  double area = 0.3;     // fraction of the image the board covers in the first frame
  double aspect = 0.75;  // width / height
  double depth = 0.6;    // m from the first camera
  double start_u = 0.25, start_v = 0.5;  // its centre in the first image, fractions of its size
  Eigen::Vector3d velocity = Eigen::Vector3d(0.25, 0.0, 0.0);  // m/s, first camera's axes
  bool with_camera = false;  // the velocity is relative to the moving camera, not the world
  bool ellipse = false;      // an elliptic board instead of a rectangle
  ObjectTexture texture = ObjectTexture::kBlocks;
  unsigned seed = 1;
  int label = 1;  // class id of its pixels (the rest: 0)
  // The label image's error at the object's outline (px): > 0 the labels miss that much of it
  // (eroded), < 0 they spill over (dilated); 0 exact.
  int label_error_px = 0;

  void validate() const;  // throws std::invalid_argument naming the bad field
};

class MovingObject {
 public:
  // `intrinsics` of the images it is drawn into (distortion included); `world_from_first` and
  // `first_stamp`: the first frame's camera pose and time; `scene` (8-bit BGR or grey, may be
  // empty but for kScene) the source of a kScene texture.
  MovingObject(const MovingObjectSpec& spec, const PinholeIntrinsics& intrinsics,
               const Eigen::Isometry3d& world_from_first, double first_stamp,
               const cv::Mat& scene = cv::Mat());

  // camera <- object at `stamp`, the camera then at `world_from_camera`.
  Eigen::Isometry3d cameraFromObject(double stamp,
                                     const Eigen::Isometry3d& world_from_camera) const;

  // Paints the board seen from `camera_from_object` into `image` (8-bit BGR or grey), writes its
  // depth (m) into `depth` (CV_32FC1, may be null) and its mask into `mask` (CV_8UC1 255 where
  // it is, may be null). `shift_x`: a camera displaced by that much along its x axis (a stereo
  // rig's right camera: +baseline). `scene_depth` (CV_32FC1, m; 0 or not finite where unknown,
  // may be null): the board is left out where the scene is nearer. Returns the pixels it covers.
  int render(const Eigen::Isometry3d& camera_from_object, cv::Mat* image, cv::Mat* depth,
             cv::Mat* mask, double shift_x = 0.0, const cv::Mat* scene_depth = nullptr) const;

  // The labels of a frame whose object mask is `mask`: spec.label where the (eroded or dilated)
  // mask is, 0 elsewhere, 8-bit.
  cv::Mat labels(const cv::Mat& mask) const;

  double width() const { return width_; }
  double height() const { return height_; }

 private:
  MovingObjectSpec spec_;
  PinholeIntrinsics intrinsics_;
  std::vector<cv::Point2f> rays_;  // every pixel's normalised ray, row-major
  Eigen::Isometry3d world_from_first_;
  double first_stamp_;
  double width_ = 0.0, height_ = 0.0;  // m
  Eigen::Vector3d start_;              // the centre in the first camera's frame
  cv::Mat texture_;                    // 8-bit BGR
};

}  // namespace cvo
