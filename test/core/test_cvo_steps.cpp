#include <gtest/gtest.h>

#include <random>

#include "cvo_odometry/core/cvo_steps.hpp"

using cvo::kernels::MomentSums;

TEST(CvoSteps, CubicRootsAreFoundAndPolished) {
  // (t - 0.5)(t - 2)(t + 1) = t^3 - 1.5 t^2 - 1.5 t + 1
  EXPECT_NEAR(cvo::smallestPositiveCubicRoot(1, -1.5, -1.5, 1), 0.5, 1e-12);
  // 2 (t - 0.3)(t^2 + 1): one real root
  EXPECT_NEAR(cvo::smallestPositiveCubicRoot(2, -0.6, 2, -0.6), 0.3, 1e-12);
  // Degenerate to quadratic and linear.
  EXPECT_NEAR(cvo::smallestPositiveCubicRoot(0, 1, -3, 2), 1.0, 1e-12);
  EXPECT_NEAR(cvo::smallestPositiveCubicRoot(0, 0, 2, -1), 0.5, 1e-12);
  EXPECT_LT(cvo::smallestPositiveCubicRoot(1, 3, 3, 1), 0.0);  // (t + 1)^3
}

TEST(CvoSteps, TaylorStepClampsAndHandlesNoRoot) {
  // F' = B + 2 C t with B = 1, C = -1: maximum at 0.5.
  EXPECT_NEAR(cvo::taylorStepLength({1.0, -1.0, 0.0, 0.0}, 1e-5, 0.8), 0.5, 1e-12);
  EXPECT_NEAR(cvo::taylorStepLength({1.0, -1.0, 0.0, 0.0}, 1e-5, 0.1), 0.1, 1e-12);
  EXPECT_NEAR(cvo::taylorStepLength({1.0, 1.0, 0.0, 0.0}, 1e-5, 0.8), 0.8, 1e-12);
}

TEST(CvoSteps, WeightedProcrustesRecoversAnExactTransform) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const Eigen::Isometry3d truth =
      cvo::lie::expSE3((cvo::Vector6d() << 0.2, -0.1, 0.3, 0.5, -0.2, 0.1).finished());
  MomentSums m;
  cvo::kernels::clear(m);
  for (int n = 0; n < 50; ++n) {
    const Eigen::Vector3d z(u(rng), u(rng), u(rng));
    const Eigen::Vector3d x = truth * z;
    const double a = 0.5 + 0.5 * u(rng);
    m.weight += a;
    for (int r = 0; r < 3; ++r) {
      m.target[r] += a * x[r];
      m.source[r] += a * z[r];
      for (int c = 0; c < 3; ++c)
        m.cross[3 * r + c] += a * x[r] * z[c];
    }
    ++m.pairs;
  }
  const Eigen::Isometry3d D = cvo::weightedProcrustes(m);
  EXPECT_LT((D.matrix() - truth.matrix()).norm(), 1e-12);
  m.pairs = 2;
  EXPECT_TRUE(cvo::weightedProcrustes(m).matrix().isIdentity());
}
