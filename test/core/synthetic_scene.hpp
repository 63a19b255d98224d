// Structured synthetic scenes for the core tests: a room corner (floor, two walls) with a box,
// colour textured by position, sampled at random so that two samplings never share points.
#pragma once

#include <cmath>
#include <random>

#include "cvo_odometry/core/labeled_cloud.hpp"

namespace cvo_test {

// Texture: smooth stripes in B, G, R; the gradient channels at their neutral 0.5.
inline void textureAt(const Eigen::Vector3f& p, float* color) {
  color[0] = 0.5f + 0.4f * std::sin(9.0f * p.x() + 2.0f * p.z());
  color[1] = 0.5f + 0.4f * std::sin(7.0f * p.y() - 3.0f * p.x());
  color[2] = 0.5f + 0.4f * std::cos(8.0f * p.z() + 5.0f * p.y());
  color[3] = 0.5f;
  color[4] = 0.5f;
}

// Semantic class by stripe along x (3 classes), one-hot.
inline void labelAt(const Eigen::Vector3f& p, float* probabilities) {
  const int cls = static_cast<int>(std::floor(p.x() / 0.1f)) % 3;
  for (int k = 0; k < 3; ++k)
    probabilities[k] = (k == (cls + 3) % 3) ? 1.0f : 0.0f;
}

inline void addPoint(cvo::LabeledCloud& cloud, const Eigen::Vector3f& p) {
  float color[5], labels[3];
  textureAt(p, color);
  labelAt(p, labels);
  cloud.add(p, cloud.hasColor() ? color : nullptr, cloud.semanticClasses() ? labels : nullptr);
}

// Room corner: floor z = 0 over [0, 1.2] x [0, 1.2], walls x = 0 and y = 0 up to 0.9 m, and a
// 0.3 m box on the floor; dense enough (3000 points: ~3 cm apart) for kernels of 5 cm.
inline cvo::LabeledCloud roomScene(int count, unsigned seed, bool color = true, int classes = 0) {
  cvo::LabeledCloud cloud(color, classes);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (int n = 0; n < count; ++n) {
    const float a = u(rng), b = u(rng);
    switch (n % 4) {
      case 0:
        addPoint(cloud, {1.2f * a, 1.2f * b, 0.0f});
        break;
      case 1:
        addPoint(cloud, {0.0f, 1.2f * a, 0.9f * b});
        break;
      case 2:
        addPoint(cloud, {1.2f * a, 0.0f, 0.9f * b});
        break;
      default: {
        // Box [0.5, 0.8] x [0.5, 0.8] x [0, 0.3]: top and two sides.
        const int face = static_cast<int>(3.0f * u(rng));
        if (face == 0) addPoint(cloud, {0.5f + 0.3f * a, 0.5f + 0.3f * b, 0.3f});
        if (face == 1) addPoint(cloud, {0.8f, 0.5f + 0.3f * a, 0.3f * b});
        if (face == 2) addPoint(cloud, {0.5f + 0.3f * a, 0.8f, 0.3f * b});
      }
    }
  }
  return cloud;
}

// A flat textured plane z = 0 over [lo, hi]^2. A patch inside a larger plane has no edge that
// geometry could lock onto.
inline cvo::LabeledCloud texturedPlane(int count, unsigned seed, float lo, float hi,
                                       bool color = true, int classes = 0) {
  cvo::LabeledCloud cloud(color, classes);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(lo, hi);
  for (int n = 0; n < count; ++n)
    addPoint(cloud, {u(rng), u(rng), 0.0f});
  return cloud;
}

}  // namespace cvo_test
