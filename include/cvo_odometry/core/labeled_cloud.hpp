// A point cloud with appearance features: positions, an optional colour feature per point
// (5-D: B, G, R in [0,1] and the two image gradients, see cvo-method notes) and an optional
// semantic class-probability vector (number of classes chosen at run time).
// Memory: one contiguous float array per attribute, point-major, so a kernel reads one point's
// position or feature vector with a single strided load on the CPU and the GPU alike.
#pragma once

#include <cstddef>
#include <functional>
#include <memory>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "cvo_odometry/core/intensity_image.hpp"
#include "cvo_odometry/core/pair_kernels.hpp"
#include "cvo_odometry/core/pixel_region.hpp"

namespace cvo {

// The factor that moves a point at depth (z) `depth` along its ray to depth new_depth(depth); NaN
// when either depth is not positive and finite (the point is dropped).
float rayScale(float depth, const std::function<float(float)>& new_depth);

class LabeledCloud {
 public:
  static constexpr int kColorDim = kernels::kColorDim;

  LabeledCloud() = default;
  // `semantic_classes` = 0 for a cloud without semantics.
  explicit LabeledCloud(bool has_color, int semantic_classes = 0);

  void reserve(std::size_t n);
  // `color` must point to kColorDim floats when the cloud has colour, `semantics` to
  // semanticClasses() floats when it has semantics; either may be null otherwise.
  void add(const Eigen::Vector3f& position, const float* color = nullptr,
           const float* semantics = nullptr);

  std::size_t size() const { return positions_.size() / 3; }
  bool empty() const { return positions_.empty(); }
  bool hasColor() const { return has_color_; }
  int semanticClasses() const { return semantic_classes_; }

  Eigen::Map<const Eigen::Vector3f> position(std::size_t i) const {
    return Eigen::Map<const Eigen::Vector3f>(&positions_[3 * i]);
  }
  const float* color(std::size_t i) const { return &colors_[kColorDim * i]; }
  const float* semantics(std::size_t i) const {
    return &semantics_[static_cast<std::size_t>(semantic_classes_) * i];
  }

  const std::vector<float>& positionData() const { return positions_; }
  const std::vector<float>& colorData() const { return colors_; }
  const std::vector<float>& semanticData() const { return semantics_; }

  // The grey image the points were selected from (for the photometric rotation stage), or null.
  // Shared: copies of a cloud refer to the same image.
  const IntensityImage* image() const { return image_.get(); }
  void setImage(std::shared_ptr<const IntensityImage> image) { image_ = std::move(image); }

  // The image region whose points were left out of this cloud (a moving object's), or null.
  // Shared like the image; copies that keep the image keep it.
  const PixelRegion* leftOutRegion() const { return left_out_.get(); }
  // A copy without the points `leave_out` is true for, the image kept, and `region` as the region
  // they were left out of.
  LabeledCloud without(const std::function<bool(const Eigen::Vector3f&)>& leave_out,
                       std::shared_ptr<const PixelRegion> region) const;

  // A copy with every position moved by `T` (features unchanged, no image: the image no longer
  // matches the positions).
  LabeledCloud transformed(const Eigen::Isometry3f& T) const;
  // A copy with each point moved along its ray to the depth (z) `new_depth` gives its depth; the
  // image is kept (every point stays on its pixel). Points given no positive finite depth, or
  // without one, are dropped.
  LabeledCloud withDepths(const std::function<float(float)>& new_depth) const;
  // Every `stride`-th point, starting with the first.
  LabeledCloud strided(std::size_t stride) const;
  // The same into `out`, reusing its storage (a registration's coarse levels, every frame).
  void stridedInto(std::size_t stride, LabeledCloud& out) const;
  // `count` points spread evenly over the cloud's order (point floor(k size / count), the first
  // among them); the whole cloud when it has no more.
  LabeledCloud thinned(std::size_t count) const;
  void thinnedInto(std::size_t count, LabeledCloud& out) const;
  // Index of the first point with a non-finite position or feature, or -1.
  long firstNonFinite() const;

 private:
  // The `count` points index(0), index(1), ... (features too; no image) into `out`, whose
  // storage is reused.
  template <class Index>
  void pickInto(std::size_t count, Index index, LabeledCloud& out) const;

  bool has_color_ = false;
  int semantic_classes_ = 0;
  std::vector<float> positions_;
  std::vector<float> colors_;
  std::vector<float> semantics_;
  std::shared_ptr<const IntensityImage> image_;
  std::shared_ptr<const PixelRegion> left_out_;
};

}  // namespace cvo
