#include "cvo_odometry/core/labeled_cloud.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <stdexcept>

#include <Eigen/Geometry>

namespace cvo {

LabeledCloud::LabeledCloud(bool has_color, int semantic_classes)
    : has_color_(has_color), semantic_classes_(semantic_classes) {
  if (semantic_classes < 0) throw std::invalid_argument("semantic class count must be >= 0");
}

void LabeledCloud::reserve(std::size_t n) {
  positions_.reserve(3 * n);
  if (has_color_) colors_.reserve(kColorDim * n);
  semantics_.reserve(static_cast<std::size_t>(semantic_classes_) * n);
}

void LabeledCloud::add(const Eigen::Vector3f& position, const float* color,
                       const float* semantics) {
  if (has_color_ && color == nullptr)
    throw std::invalid_argument("cloud has colour: colour needed");
  if (semantic_classes_ > 0 && semantics == nullptr) {
    throw std::invalid_argument("cloud has semantics: class probabilities needed");
  }
  positions_.insert(positions_.end(), position.data(), position.data() + 3);
  if (has_color_) colors_.insert(colors_.end(), color, color + kColorDim);
  if (semantic_classes_ > 0)
    semantics_.insert(semantics_.end(), semantics, semantics + semantic_classes_);
}

LabeledCloud LabeledCloud::transformed(const Eigen::Isometry3f& T) const {
  LabeledCloud out = *this;
  out.image_.reset();
  for (std::size_t i = 0; i < size(); ++i) {
    Eigen::Map<Eigen::Vector3f>(&out.positions_[3 * i]) = T * position(i);
  }
  return out;
}

float rayScale(float depth, const std::function<float(float)>& new_depth) {
  if (!(depth > 0.0f) || !std::isfinite(depth)) return NAN;
  const float moved = new_depth(depth);
  return moved > 0.0f && std::isfinite(moved) ? moved / depth : NAN;
}

LabeledCloud LabeledCloud::withDepths(const std::function<float(float)>& new_depth) const {
  LabeledCloud out(has_color_, semantic_classes_);
  out.reserve(size());
  for (std::size_t i = 0; i < size(); ++i) {
    const float scale = rayScale(position(i).z(), new_depth);
    if (std::isnan(scale)) continue;
    out.add(position(i) * scale, has_color_ ? color(i) : nullptr,
            semantic_classes_ ? semantics(i) : nullptr);
  }
  out.image_ = image_;  // each point stays on its pixel's ray
  out.left_out_ = left_out_;
  return out;
}

LabeledCloud LabeledCloud::without(const std::function<bool(const Eigen::Vector3f&)>& leave_out,
                                   std::shared_ptr<const PixelRegion> region) const {
  LabeledCloud out(has_color_, semantic_classes_);
  out.reserve(size());
  for (std::size_t i = 0; i < size(); ++i) {
    if (leave_out(position(i))) continue;
    out.add(position(i), has_color_ ? color(i) : nullptr,
            semantic_classes_ ? semantics(i) : nullptr);
  }
  out.image_ = image_;
  out.left_out_ = std::move(region);
  return out;
}

template <class Index>
void LabeledCloud::pickInto(std::size_t count, Index index, LabeledCloud& out) const {
  const auto sem = static_cast<std::size_t>(semantic_classes_);
  out.has_color_ = has_color_;
  out.semantic_classes_ = semantic_classes_;
  out.image_.reset();
  // resize() keeps the capacity: no allocation (or page faults) once the sizes have been seen.
  out.positions_.resize(3 * count);
  out.colors_.resize(has_color_ ? kColorDim * count : 0);
  out.semantics_.resize(sem * count);
  for (std::size_t k = 0; k < count; ++k) {
    const std::size_t i = index(k);
    std::copy_n(&positions_[3 * i], 3, &out.positions_[3 * k]);
    if (has_color_) std::copy_n(&colors_[kColorDim * i], kColorDim, &out.colors_[kColorDim * k]);
    if (sem > 0) std::copy_n(&semantics_[sem * i], sem, &out.semantics_[sem * k]);
  }
}

void LabeledCloud::stridedInto(std::size_t stride, LabeledCloud& out) const {
  stride = std::max<std::size_t>(stride, 1);
  pickInto((size() + stride - 1) / stride, [&](std::size_t k) { return k * stride; }, out);
}

LabeledCloud LabeledCloud::strided(std::size_t stride) const {
  LabeledCloud out;
  stridedInto(stride, out);
  return out;
}

void LabeledCloud::thinnedInto(std::size_t count, LabeledCloud& out) const {
  count = std::min(count, size());
  pickInto(
      count, [&](std::size_t k) { return k * size() / count; }, out);
}

LabeledCloud LabeledCloud::thinned(std::size_t count) const {
  if (count >= size()) return *this;
  LabeledCloud out;
  thinnedInto(count, out);
  return out;
}

namespace {

// True when no value is NaN or infinite: the exponent bits of each, in a loop without an early
// exit that the compiler vectorises (the scan by point costs 0.25 ms at 15k points).
bool allFinite(const std::vector<float>& values) {
  std::uint32_t non_finite = 0;
  for (const float value : values) {
    std::uint32_t bits;
    std::memcpy(&bits, &value, sizeof bits);
    non_finite |= (bits & 0x7f800000u) == 0x7f800000u;
  }
  return non_finite == 0;
}

}  // namespace

long LabeledCloud::firstNonFinite() const {
  if (allFinite(positions_) && allFinite(colors_) && allFinite(semantics_)) return -1;
  const std::size_t sem = static_cast<std::size_t>(semantic_classes_);
  for (std::size_t i = 0; i < size(); ++i) {
    bool finite = std::isfinite(positions_[3 * i]) && std::isfinite(positions_[3 * i + 1]) &&
                  std::isfinite(positions_[3 * i + 2]);
    for (int k = 0; finite && has_color_ && k < kColorDim; ++k) {
      finite = std::isfinite(colors_[kColorDim * i + k]);
    }
    for (std::size_t k = 0; finite && k < sem; ++k)
      finite = std::isfinite(semantics_[sem * i + k]);
    if (!finite) return static_cast<long>(i);
  }
  return -1;
}

}  // namespace cvo
